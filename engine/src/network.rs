//! A network of independent sPLLs sharing one input train, and batches of samples, run in
//! parallel with rayon (over sPLLs within one sample, over samples within a batch).

use rayon::prelude::*;

use crate::cancel::Cancel;
use crate::error::{bail, EngineError};
use crate::gate::GateTable;
use crate::params::SpllParams;
use crate::spll::{run_interleaved, Facilitation, Recorder, SpllState, Stepper};
use crate::threads;

/// sPLLs run together on one thread with their events interleaved ([`run_interleaved`]): the
/// processor overlaps their independent chains of exponentials, ~10 % faster than one after
/// the other on the reference workload (`benchmarks/bench_engine.py`; groups of 2 to 8 were
/// tried, 2 was fastest).
const INTERLEAVE: usize = 2;

/// What to keep and how far to go, shared by every sPLL and sample of a call.
#[derive(Clone, Copy, Debug)]
pub struct RunConfig<'a> {
    /// Keep spike times (otherwise only count them).
    pub keep_spikes: bool,
    /// More events than this in one sPLL is an error.
    pub max_events: u64,
    /// Raised to stop the call early (it then returns an error).
    pub cancel: &'a Cancel,
    /// The standard-neuron sPLL's K-level gate in place of the product `g_trg * I_fac`
    /// ([`crate::gate`]); `None` is the golden model.
    pub gate: Option<&'a GateTable>,
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
    config: RunConfig<'_>,
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
        Some(s) => {
            for (i, (state, p)) in s.iter().zip(params).enumerate() {
                state.check(p, i)?;
            }
            s
        }
        None => params.iter().map(SpllState::new).collect(),
    };
    let start = states.first().map_or(0.0, |s| s.t);
    if states.iter().any(|s| s.t != start) {
        bail!("saved state mixes sPLLs stopped at different times");
    }
    validate_end(t_end, start)?;
    validate_inputs(inputs, start, fresh, "input")?;
    if let Some(gate) = config.gate {
        gate.check(params)?;
    }
    if probes.iter().any(|&t| t.is_nan() || t < start || t > t_end) {
        bail!("probe times must lie within the run ({start} s to {t_end} s)");
    }
    if let Some(i) = probes.windows(2).position(|w| w[0] > w[1]) {
        bail!(
            "probe times must be sorted; probe {} comes after probe {i}",
            i + 1
        );
    }
    // The facilitatory currents, one per distinct synapse and saved current (`facs[uses[i]]`
    // is sPLL i's).
    let mut facs: Vec<Facilitation> = Vec::new();
    let uses: Vec<usize> = params
        .iter()
        .zip(&states)
        .map(|(p, s)| match facs.iter().position(|f| f.serves(p, s)) {
            Some(k) => k,
            None => {
                facs.push(Facilitation::new(p, s, inputs, t_end));
                facs.len() - 1
            }
        })
        .collect();
    // One group of sPLLs (number `g`) on one thread, its events interleaved.
    let group = |(g_index, (p, st)): (usize, (&[SpllParams], &mut [SpllState]))| {
        let mut recs: Vec<Recorder> = p
            .iter()
            .map(|_| Recorder {
                keep_spikes: config.keep_spikes,
                ..Recorder::default()
            })
            .collect();
        let name = |k: usize, e: EngineError| {
            EngineError(format!("sPLL {}: {e}", g_index * INTERLEAVE + k))
        };
        let runs = p
            .iter()
            .zip(st.iter_mut())
            .zip(recs.iter_mut())
            .zip(&uses[g_index * INTERLEAVE..])
            .enumerate()
            .map(|(j, (((p, s), r), &k))| {
                let gate = config.gate.map(|g| g.staircase(g_index * INTERLEAVE + j));
                Stepper::new(p, s, &facs[k], t_end, probes, &config, r).map(|s| s.gated(gate))
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| name(0, e))?;
        run_interleaved(runs).map_err(|(k, e)| name(k, e))?;
        Ok(recs)
    };
    let groups: Result<Vec<Vec<Recorder>>, EngineError> = if parallel {
        params
            .par_chunks(INTERLEAVE)
            .zip(states.par_chunks_mut(INTERLEAVE))
            .enumerate()
            .map(group)
            .collect()
    } else {
        params
            .chunks(INTERLEAVE)
            .zip(states.chunks_mut(INTERLEAVE))
            .enumerate()
            .map(group)
            .collect()
    };
    let recorders = groups.map(|g| g.into_iter().flatten().collect());
    config.cancel.check()?;
    Ok(SampleResult {
        recorders: recorders?,
        states,
    })
}

/// Simulate many samples from rest, in parallel over samples on `threads` threads
/// (rayon's global pool when `None`, at most [`threads::max_threads`]). Every sample is
/// validated before any runs.
pub fn simulate_batch(
    params: &[SpllParams],
    inputs: &[&[f64]],
    t_end: f64,
    config: RunConfig<'_>,
    threads: Option<usize>,
) -> Result<Vec<SampleResult>, EngineError> {
    validate_end(t_end, 0.0)?;
    if let Some(gate) = config.gate {
        gate.check(params)?;
    }
    for (i, x) in inputs.iter().enumerate() {
        validate_inputs(x, 0.0, true, &format!("sample {i}"))?;
    }
    let work = || {
        inputs
            .par_iter()
            .enumerate()
            .map(|(i, x)| {
                simulate(params, x, t_end, None, &[], config, false)
                    .map_err(|e| EngineError(format!("sample {i}: {e}")))
            })
            .collect::<Result<Vec<_>, _>>()
    };
    let results = threads::install(threads, work)?;
    config.cancel.check()?;
    results
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::cancel::{Cancel, CANCELLED, NEVER};
    use crate::spll::MAX_EVENTS;

    /// Table 6's "VibTac vary offset LIF" sPLL, its CCO free-running at `frequency` [Hz].
    pub(crate) fn vibtac(frequency: f64) -> SpllParams {
        let (tau_cco, t_refr) = (0.314, 1e-3);
        let offset = 1.0 / (tau_cco * -(-(1.0 / frequency - t_refr) / tau_cco).exp_m1());
        let row = [
            7.50e-3, tau_cco, 1.0, 9.84, offset, t_refr, 1.0, 9.59e-3, 1.25e-3, 4.52e-3, 1.0,
            6.15e2, 0.271, t_refr, 1.0,
        ];
        SpllParams::from_row(&row, 0).unwrap()
    }

    /// Periodic input at `rate` [Hz] over `[0, duration)`.
    pub(crate) fn periodic(rate: f64, duration: f64) -> Vec<f64> {
        (0..(rate * duration) as usize)
            .map(|k| k as f64 / rate)
            .collect()
    }

    /// Bursts of three input spikes 0.5 ms apart at `rate` [Hz] over `[0, duration)`: enough
    /// facilitation for [`vibtac`]'s TDE to fire.
    pub(crate) fn bursts(rate: f64, duration: f64) -> Vec<f64> {
        periodic(rate, duration)
            .into_iter()
            .flat_map(|t| [t, t + 5e-4, t + 1e-3])
            .filter(|&t| t < duration)
            .collect()
    }

    fn config(cancel: &Cancel) -> RunConfig<'_> {
        RunConfig {
            keep_spikes: false,
            max_events: MAX_EVENTS,
            cancel,
            gate: None,
        }
    }

    #[test]
    fn a_raised_cancel_stops_a_run_within_milliseconds() {
        let params: Vec<SpllParams> = (0..4).map(|k| vibtac(100.0 + 50.0 * k as f64)).collect();
        // Hours of simulated time: seconds of work (minutes unoptimised).
        let inputs = periodic(300.0, 5_000.0);
        let cancel = Cancel::new();
        let start = std::time::Instant::now();
        let (one, batch) = std::thread::scope(|scope| {
            scope.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(50));
                cancel.request();
            });
            let one = simulate(&params, &inputs, 5_000.0, None, &[], config(&cancel), true);
            let batch = simulate_batch(&params, &[&inputs], 5_000.0, config(&cancel), Some(1));
            (one, batch)
        });
        assert_eq!(one.unwrap_err().0, CANCELLED);
        assert_eq!(batch.unwrap_err().0, CANCELLED);
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
    }

    #[test]
    fn a_run_resumed_from_its_state_equals_the_whole_run() {
        let params = [vibtac(150.0), vibtac(400.0)];
        let inputs = bursts(310.0, 1.0);
        let cut = inputs.partition_point(|&t| t <= 0.4);
        let whole = simulate(&params, &inputs, 1.0, None, &[], config(&NEVER), true).unwrap();
        let first = simulate(
            &params,
            &inputs[..cut],
            0.4,
            None,
            &[],
            config(&NEVER),
            true,
        );
        let first = first.unwrap();
        let loaded: Vec<SpllState> = first
            .states
            .iter()
            .enumerate()
            .map(|(i, s)| SpllState::from_array(&s.to_array(), i).unwrap())
            .collect();
        let rest = simulate(
            &params,
            &inputs[cut..],
            1.0,
            Some(loaded),
            &[],
            config(&NEVER),
            true,
        );
        let rest = rest.unwrap();
        assert_eq!(rest.states, whole.states);
        let parts = first.recorders.iter().zip(&rest.recorders);
        for ((a, b), w) in parts.zip(&whole.recorders) {
            assert!(w.tde_count > 0);
            assert_eq!(a.tde_count + b.tde_count, w.tde_count);
            assert_eq!(a.cco_count + b.cco_count, w.cco_count);
        }
    }

    /// A gate row belongs to its own sPLL whatever group it runs in, and a gate changes what
    /// the TDE sees: levels above every facilitatory current silence it.
    #[test]
    fn each_gated_spll_runs_with_its_own_levels() {
        let params: Vec<SpllParams> = (0..5).map(|k| vibtac(110.0 + 70.0 * k as f64)).collect();
        let inputs = bursts(290.0, 0.8);
        let levels = |i: usize| {
            let scale = 2500.0 * (1.0 + 0.3 * i as f64);
            (
                vec![0.2 * scale, 0.9 * scale, 1.6 * scale],
                vec![1.0 * scale, 1.4 * scale, 0.8 * scale],
            )
        };
        let (t, d): (Vec<_>, Vec<_>) = (0..5).map(levels).unzip();
        let gate = GateTable::new(t.concat(), d.concat(), 3).unwrap();
        fn keep(gate: Option<&GateTable>) -> RunConfig<'_> {
            RunConfig {
                keep_spikes: true,
                gate,
                ..config(&NEVER)
            }
        }
        let all = simulate(&params, &inputs, 0.8, None, &[], keep(Some(&gate)), true).unwrap();
        let golden = simulate(&params, &inputs, 0.8, None, &[], keep(None), true).unwrap();
        for (i, p) in params.iter().enumerate() {
            let (t, d) = levels(i);
            let own = GateTable::new(t, d, 3).unwrap();
            let alone = simulate(&[*p], &inputs, 0.8, None, &[], keep(Some(&own)), false).unwrap();
            let (a, b) = (&all.recorders[i], &alone.recorders[0]);
            assert!(
                b.tde_count > 0,
                "sPLL {i} is silent: the test shows nothing"
            );
            assert_eq!(a.tde_spikes, b.tde_spikes, "sPLL {i}");
            assert_ne!(a.tde_spikes, golden.recorders[i].tde_spikes, "sPLL {i}");
        }
        let high = GateTable::new(vec![1e9; 5], vec![1.0; 5], 1).unwrap();
        let silent = simulate(&params, &inputs, 0.8, None, &[], keep(Some(&high)), true).unwrap();
        assert!(silent.recorders.iter().all(|r| r.tde_count == 0));
        let wrong = GateTable::new(vec![1.0; 4], vec![1.0; 4], 1).unwrap();
        let message = simulate(&params, &inputs, 0.8, None, &[], keep(Some(&wrong)), true);
        assert_eq!(
            message.unwrap_err().0,
            "the gate has levels for 4 sPLLs but the network has 5"
        );
    }

    /// sPLLs of one sample run interleaved in groups and share facilitatory currents: each
    /// must still get exactly what it gets alone, and an error must name its own sPLL.
    #[test]
    fn interleaved_and_shared_runs_equal_each_spll_alone() {
        let mut slow_fac = vibtac(333.0);
        slow_fac.inv_tau_fac *= 0.5; // a facilitatory synapse of its own
        let params = [
            vibtac(120.0),
            slow_fac,
            vibtac(250.0),
            vibtac(410.0),
            vibtac(90.0),
        ];
        let inputs = bursts(290.0, 0.8);
        let probes = [0.1, 0.35, 0.35, 0.79];
        let keep = RunConfig {
            keep_spikes: true,
            ..config(&NEVER)
        };
        for parallel in [false, true] {
            let all = simulate(&params, &inputs, 0.8, None, &probes, keep, parallel).unwrap();
            for (i, p) in params.iter().enumerate() {
                let alone = simulate(&[*p], &inputs, 0.8, None, &probes, keep, false).unwrap();
                let (a, b) = (&all.recorders[i], &alone.recorders[0]);
                assert!(
                    b.tde_count > 0,
                    "sPLL {i} is silent: the test shows nothing"
                );
                assert_eq!(a.tde_spikes, b.tde_spikes, "sPLL {i}");
                assert_eq!(a.cco_spikes, b.cco_spikes, "sPLL {i}");
                assert_eq!(a.trace, b.trace, "sPLL {i}");
                assert_eq!(all.states[i], alone.states[0], "sPLL {i}");
            }
        }
        // An event limit hit by the fourth sPLL only (the fastest CCO) names it.
        let counts = simulate(&params, &inputs, 0.8, None, &[], config(&NEVER), false).unwrap();
        let events = |r: &Recorder| r.tde_count + r.cco_count;
        let most = counts.recorders.iter().map(events).max().unwrap();
        let second = counts
            .recorders
            .iter()
            .map(events)
            .filter(|&e| e < most)
            .max()
            .unwrap();
        assert_eq!(events(&counts.recorders[3]), most);
        let limited = RunConfig {
            max_events: second + 1,
            ..config(&NEVER)
        };
        let message = simulate(&params, &inputs, 0.8, None, &[], limited, false)
            .unwrap_err()
            .0;
        assert!(message.starts_with("sPLL 3: more than"), "{message}");
    }
}
