//! A network of independent sPLLs sharing one input train, and batches of samples, run in
//! parallel with rayon (over sPLLs within one sample, over samples within a batch).

use rayon::prelude::*;

use crate::error::{bail, EngineError};
use crate::params::SpllParams;
use crate::spll::{run, Recorder, SpllState};

/// What to keep and how far to go, shared by every sPLL and sample of a call.
#[derive(Clone, Copy, Debug)]
pub struct RunConfig {
    /// Keep spike times (otherwise only count them).
    pub keep_spikes: bool,
    /// More events than this in one sPLL is an error.
    pub max_events: u64,
}

/// Output of one sample: one [`Recorder`] and final state per sPLL.
#[derive(Clone, Debug)]
pub struct SampleResult {
    pub recorders: Vec<Recorder>,
    pub states: Vec<SpllState>,
}

/// Check that input spike times are finite, sorted and inside `(start, t_end]` (or `[0, t_end]`
/// for a run from rest). `what` names the sample in messages.
pub fn validate_inputs(
    inputs: &[f64],
    start: f64,
    fresh: bool,
    what: &str,
) -> Result<(), EngineError> {
    let mut previous = f64::NEG_INFINITY;
    for (i, &t) in inputs.iter().enumerate() {
        if !t.is_finite() {
            bail!("{what}: input spike {i} is not a finite time ({t})");
        }
        if t < 0.0 {
            bail!("{what}: input spike {i} has negative time {t} s");
        }
        if t < previous {
            bail!("{what}: input spike times must be sorted; spike {i} ({t} s) comes after {previous} s");
        }
        if !fresh && t <= start {
            bail!(
                "{what}: input spike {i} at {t} s is not after the resumed state's time {start} s \
                 (pass only the spikes that follow the saved state)"
            );
        }
        previous = t;
    }
    Ok(())
}

/// Check the end time against the start time.
pub fn validate_end(t_end: f64, start: f64) -> Result<(), EngineError> {
    if !(t_end.is_finite() && t_end > start) {
        bail!("duration must be finite and the run must end after it starts (start {start} s, end {t_end} s)");
    }
    Ok(())
}

/// Simulate one sample on every sPLL. `states` resumes a saved run (one per sPLL); `probes` are
/// sorted sample times for state traces. With `parallel`, sPLLs are spread over rayon's pool.
pub fn simulate(
    params: &[SpllParams],
    inputs: &[f64],
    t_end: f64,
    states: Option<Vec<SpllState>>,
    probes: &[f64],
    config: RunConfig,
    parallel: bool,
) -> Result<SampleResult, EngineError> {
    let fresh = states.is_none();
    let mut states = match states {
        Some(s) if s.len() != params.len() => {
            bail!(
                "saved state has {} sPLLs but the network has {}",
                s.len(),
                params.len()
            )
        }
        Some(s) => s,
        None => params.iter().map(SpllState::new).collect(),
    };
    let start = states.first().map_or(0.0, |s| s.t);
    if states.iter().any(|s| s.t != start) {
        bail!("saved state mixes sPLLs stopped at different times");
    }
    validate_end(t_end, start)?;
    validate_inputs(inputs, start, fresh, "input")?;
    if probes.iter().any(|&t| t.is_nan() || t < start || t > t_end) {
        bail!("probe times must lie within the run ({start} s to {t_end} s)");
    }
    if let Some(i) = probes.windows(2).position(|w| w[0] > w[1]) {
        bail!(
            "probe times must be sorted; probe {} comes after probe {i}",
            i + 1
        );
    }
    let one = |(p, state): (&SpllParams, &mut SpllState)| {
        let mut rec = Recorder {
            keep_spikes: config.keep_spikes,
            ..Recorder::default()
        };
        run(p, state, inputs, t_end, probes, config.max_events, &mut rec).map(|()| rec)
    };
    let recorders: Result<Vec<Recorder>, EngineError> = if parallel {
        params
            .par_iter()
            .zip(states.par_iter_mut())
            .map(one)
            .collect()
    } else {
        params.iter().zip(states.iter_mut()).map(one).collect()
    };
    Ok(SampleResult {
        recorders: recorders?,
        states,
    })
}

/// Simulate many samples from rest, in parallel over samples on `threads` threads
/// (rayon's global pool when `None`). Every sample is validated before any runs.
pub fn simulate_batch(
    params: &[SpllParams],
    inputs: &[&[f64]],
    t_end: f64,
    config: RunConfig,
    threads: Option<usize>,
) -> Result<Vec<SampleResult>, EngineError> {
    validate_end(t_end, 0.0)?;
    for (i, x) in inputs.iter().enumerate() {
        validate_inputs(x, 0.0, true, &format!("sample {i}"))?;
    }
    let work = || {
        inputs
            .par_iter()
            .map(|x| simulate(params, x, t_end, None, &[], config, false))
            .collect::<Result<Vec<_>, _>>()
    };
    match threads {
        None => work(),
        Some(0) => bail!("threads must be >= 1"),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| EngineError(format!("cannot start {n} threads: {e}")))?
            .install(work),
    }
}
