//! Event-driven simulation of one sPLL: input → facilitatory synapse, CCO → trigger synapse (gated
//! by the facilitatory current), TDE → CCO synapse (thesis section 2.4, Algorithm 1).
//!
//! State is kept local: each neuron holds its potential and synapse current at the time of its
//! last update and is decayed from there in closed form, so precision does not depend on how long
//! the run has been going. Input spikes only change the facilitatory current, which no membrane
//! sees directly: it is computed once per run from the input train, and the event loop visits
//! only TDE and CCO spikes.

use crate::error::{approx, bail, EngineError};
use crate::membrane::Neuron;
use crate::network::RunConfig;
use crate::params::SpllParams;

/// Values per sPLL in a flattened [`SpllState`] (see [`SpllState::to_array`]).
pub const STATE_LEN: usize = 13;

/// Default limit on events per sPLL and call, so parameters that make a neuron fire absurdly
/// fast (say, no refractory period and a huge gain) end in an error instead of a hang.
pub const MAX_EVENTS: u64 = 200_000_000;

/// Events between two polls of the cancel flag (a fraction of a millisecond of work).
const CANCEL_POLL: u64 = 4096;

/// Shortest interval [s] between two spikes of one neuron that the event-limit message counts
/// as resolvable when the neuron has no (or a shorter) refractory period (as the recording
/// estimate of `spll_hw.simulate`).
pub const MIN_INTERVAL: f64 = 1e-5;

/// A neuron's state at time `t0`, plus its planned next spike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeuronState {
    /// Time [s] at which `v0` and `i0` hold.
    pub t0: f64,
    /// Membrane potential at `t0` [V].
    pub v0: f64,
    /// Synapse current at `t0` [A].
    pub i0: f64,
    /// End of the current refractory period [s] (`-inf` if none yet).
    pub refr_end: f64,
    /// Planned next spike time [s] (`inf` if the neuron will not fire without new input).
    pub next_spike: f64,
}

impl NeuronState {
    fn at_rest(n: &Neuron) -> Self {
        let mut s = NeuronState {
            t0: 0.0,
            v0: 0.0,
            i0: 0.0,
            refr_end: f64::NEG_INFINITY,
            next_spike: f64::INFINITY,
        };
        s.plan(n);
        s
    }

    /// `(V, I)` at time `t >= t0`; `V` is held at 0 until the refractory period ends.
    #[inline]
    pub fn at(&self, n: &Neuron, t: f64) -> (f64, f64) {
        if t == self.t0 {
            return (if t < self.refr_end { 0.0 } else { self.v0 }, self.i0);
        }
        if t <= self.refr_end {
            (0.0, n.current(self.i0, t - self.t0))
        } else if self.t0 < self.refr_end {
            let i_free = n.current(self.i0, self.refr_end - self.t0);
            n.evolve(0.0, i_free, t - self.refr_end)
        } else {
            n.evolve(self.v0, self.i0, t - self.t0)
        }
    }

    #[inline]
    fn advance(&mut self, n: &Neuron, t: f64) {
        let (v, i) = self.at(n, t);
        self.t0 = t;
        self.v0 = v;
        self.i0 = i;
    }

    /// Spike at `t`: reset to 0 and start the refractory period.
    #[inline]
    fn fire(&mut self, n: &Neuron, t: f64) {
        self.i0 = n.current(self.i0, t - self.t0);
        self.t0 = t;
        self.v0 = 0.0;
        self.refr_end = t + n.t_refr;
    }

    /// Re-plan the next spike from the current state (a pure function of the state).
    #[inline]
    fn plan(&mut self, n: &Neuron) {
        let free_from = self.t0.max(self.refr_end);
        let (v, i) = if self.t0 + n.t_refr == self.refr_end && self.t0 < self.refr_end {
            // Just fired: V is 0 at the end of the refractory period and the synapse current
            // has decayed by the neuron's constant factor for one refractory period.
            (0.0, self.i0 * n.refr_syn_decay)
        } else {
            self.at(n, free_from)
        };
        self.next_spike = match n.time_to_threshold(v, i) {
            Some(s) => free_from + s,
            None => f64::INFINITY,
        };
    }
}

/// Complete state of one sPLL at time `t`, enough to resume a run bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpllState {
    /// Time [s] up to which the sPLL has been simulated.
    pub t: f64,
    /// Facilitatory current [A] at time `fac_t`.
    pub fac_i: f64,
    /// Time [s] of the last input spike (when `fac_i` holds).
    pub fac_t: f64,
    /// TDE neuron; its synapse is the trigger synapse.
    pub tde: NeuronState,
    /// CCO neuron; its synapse receives the TDE spikes.
    pub cco: NeuronState,
}

impl SpllState {
    /// Everything at rest at time 0.
    pub fn new(p: &SpllParams) -> Self {
        SpllState {
            t: 0.0,
            fac_i: 0.0,
            fac_t: 0.0,
            tde: NeuronState::at_rest(&p.tde),
            cco: NeuronState::at_rest(&p.cco),
        }
    }

    /// Flatten to `[t, fac_i, fac_t, tde(t0, v0, i0, refr_end, next), cco(...)]`.
    pub fn to_array(&self) -> [f64; STATE_LEN] {
        let n = |s: &NeuronState| [s.t0, s.v0, s.i0, s.refr_end, s.next_spike];
        let (a, b) = (n(&self.tde), n(&self.cco));
        [
            self.t, self.fac_i, self.fac_t, a[0], a[1], a[2], a[3], a[4], b[0], b[1], b[2], b[3],
            b[4],
        ]
    }

    /// Inverse of [`to_array`](Self::to_array); checks the values are a state this engine made.
    pub fn from_array(a: &[f64], index: usize) -> Result<Self, EngineError> {
        if a.len() != STATE_LEN {
            bail!(
                "state of sPLL {index}: expected {STATE_LEN} values, got {}",
                a.len()
            );
        }
        let t = a[0];
        if !t.is_finite()
            || t < 0.0
            || a[1..3]
                .iter()
                .chain(&a[3..6])
                .chain(&a[8..11])
                .any(|x| !x.is_finite())
        {
            bail!(
                "state of sPLL {index} is not a saved engine state (non-finite or negative time)"
            );
        }
        let n = |k: usize| NeuronState {
            t0: a[k],
            v0: a[k + 1],
            i0: a[k + 2],
            refr_end: a[k + 3],
            next_spike: a[k + 4],
        };
        Ok(SpllState {
            t,
            fac_i: a[1],
            fac_t: a[2],
            tde: n(3),
            cco: n(8),
        })
    }
}

/// Where spikes and probed state values go during a run.
#[derive(Clone, Debug, Default)]
pub struct Recorder {
    /// Keep spike times (otherwise only count them).
    pub keep_spikes: bool,
    pub tde_spikes: Vec<f64>,
    pub cco_spikes: Vec<f64>,
    pub tde_count: u64,
    pub cco_count: u64,
    /// `[I_fac, I_trg, V_tde, I_cco, V_cco]` at each probe time.
    pub trace: Vec<[f64; 5]>,
}

/// The facilitatory current over one run. It depends on the input train alone, never on the
/// neurons, so it is computed once up front (one exponential per distinct input time) and the
/// event loop only visits TDE and CCO spikes, looking the gate value up where a CCO fires.
struct Facilitation {
    /// Distinct input times [s], ascending.
    times: Vec<f64>,
    /// Facilitatory current [A] just after each of `times` (all arrivals at that time added).
    after: Vec<f64>,
    /// Current [A] and time [s] before the first input of this run (from the saved state).
    start: (f64, f64),
    inv_tau: f64,
}

impl Facilitation {
    fn new(p: &SpllParams, start: (f64, f64), inputs: &[f64]) -> Self {
        let mut times: Vec<f64> = Vec::with_capacity(inputs.len());
        let mut after: Vec<f64> = Vec::with_capacity(inputs.len());
        let (mut i, mut t_last) = start;
        for &t in inputs {
            if times.last() == Some(&t) {
                *after.last_mut().expect("times and after grow together") += p.g_fac;
            } else {
                i = i * (-(t - t_last) * p.inv_tau_fac).exp() + p.g_fac;
                times.push(t);
                after.push(i);
            }
            (i, t_last) = (*after.last().expect("just pushed"), t);
        }
        Facilitation {
            times,
            after,
            start,
            inv_tau: p.inv_tau_fac,
        }
    }

    /// Current at time `t` counting the first `k` input times (those at or before `t`).
    #[inline]
    fn current(&self, k: usize, t: f64) -> f64 {
        let (i, t0) = if k == 0 {
            self.start
        } else {
            (self.after[k - 1], self.times[k - 1])
        };
        i * (-(t - t0) * self.inv_tau).exp()
    }

    /// Advance cursor `k` past the input times `< t` (`inclusive`: `<= t`).
    #[inline]
    fn seek(&self, k: &mut usize, t: f64, inclusive: bool) {
        while *k < self.times.len() && (self.times[*k] < t || (inclusive && self.times[*k] == t)) {
            *k += 1;
        }
    }
}

/// Run one sPLL from `state` up to and including `t_end`, delivering the sorted `inputs`
/// (all later than the state's time, already validated; those after `t_end` are ignored), and
/// recording into `rec`. `probes` are sorted times at which the five state variables are
/// sampled (right-continuous). More than `config.max_events` events is an error
/// ([`event_limit`]); a raised `config.cancel` stops the run with an error.
pub fn run(
    p: &SpllParams,
    state: &mut SpllState,
    inputs: &[f64],
    t_end: f64,
    probes: &[f64],
    config: &RunConfig<'_>,
    rec: &mut Recorder,
) -> Result<(), EngineError> {
    config.cancel.check()?;
    let (start, max_events) = (state.t, config.max_events);
    let SpllState { tde, cco, .. } = state;
    let (n_tde, n_cco) = (&p.tde, &p.cco);
    let used = inputs.partition_point(|&t| t <= t_end);
    let fac = Facilitation::new(p, (state.fac_i, state.fac_t), &inputs[..used]);
    let (mut gate_cursor, mut probe_cursor) = (0, 0);
    let mut next_probe = 0;
    let mut events: u64 = 0;
    loop {
        let t = tde.next_spike.min(cco.next_spike);
        if t > t_end || t.is_nan() {
            break;
        }
        events += 1;
        if events > max_events {
            return Err(event_limit(p, max_events, start, t, t_end));
        }
        if events.is_multiple_of(CANCEL_POLL) {
            config.cancel.check()?;
        }
        while next_probe < probes.len() && probes[next_probe] < t {
            let at = probes[next_probe];
            fac.seek(&mut probe_cursor, at, true);
            rec.trace
                .push(sample(p, fac.current(probe_cursor, at), tde, cco, at));
            next_probe += 1;
        }
        let tde_spike = tde.next_spike == t;
        let cco_spike = cco.next_spike == t;
        // Algorithm 1: every block advances (and fires) first ...
        if tde_spike {
            tde.fire(n_tde, t);
            rec.tde_count += 1;
            if rec.keep_spikes {
                rec.tde_spikes.push(t);
            }
        }
        if cco_spike {
            cco.fire(n_cco, t);
            rec.cco_count += 1;
            if rec.keep_spikes {
                rec.cco_spikes.push(t);
            }
            // ... then every spike is delivered: the CCO spike meets the facilitatory current
            // just before this instant (an input arriving at the same time counts after it).
            fac.seek(&mut gate_cursor, t, false);
            let trigger = p.g_trg * fac.current(gate_cursor, t);
            if trigger != 0.0 {
                tde.advance(n_tde, t);
                tde.i0 += trigger;
            }
        }
        if tde_spike && p.g_cco != 0.0 {
            cco.advance(n_cco, t);
            cco.i0 += p.g_cco;
        }
        tde.plan(n_tde);
        cco.plan(n_cco);
    }
    for &at in &probes[next_probe..] {
        fac.seek(&mut probe_cursor, at, true);
        rec.trace
            .push(sample(p, fac.current(probe_cursor, at), tde, cco, at));
    }
    if let (Some(&t), Some(&i)) = (fac.times.last(), fac.after.last()) {
        (state.fac_i, state.fac_t) = (i, t);
    }
    state.t = t_end;
    Ok(())
}

/// The error of a run that reached `max_events` events at time `t` (it started at `start` and
/// was to end at `t_end`), saying why: either the parameters run away (events come faster than
/// the refractory periods, or [`MIN_INTERVAL`] without one, let the two neurons fire) or the
/// run is long (the rate is one the neurons can keep, and the duration or input needs that many
/// events).
fn event_limit(p: &SpllParams, max_events: u64, start: f64, t: f64, t_end: f64) -> EngineError {
    let rate = max_events as f64 / (t - start);
    let resolvable = 1.0 / p.tde.t_refr.max(MIN_INTERVAL) + 1.0 / p.cco.t_refr.max(MIN_INTERVAL);
    let message = if rate > resolvable {
        format!(
            "more than {max_events} events in {} s of simulated time ({} events/s): a neuron \
             fires faster than the simulation can resolve (its refractory periods allow {} \
             events/s; raise t_tde_refr or t_cco_refr, or lower the gains)",
            approx(t - start),
            approx(rate),
            approx(resolvable)
        )
    } else {
        let needed = rate * (t_end - start);
        format!(
            "more than {max_events} events by t = {} s ({} events/s, which the refractory \
             periods allow): the run is long, and all of it ({} s) needs about {} events; raise \
             max_events, or run shorter pieces (each resumed from the last one's final state) or \
             with less input",
            approx(t),
            approx(rate),
            approx(t_end - start),
            approx(needed)
        )
    };
    EngineError(message)
}

#[inline]
fn sample(p: &SpllParams, i_fac: f64, tde: &NeuronState, cco: &NeuronState, t: f64) -> [f64; 5] {
    let (v_tde, i_trg) = tde.at(&p.tde, t);
    let (v_cco, i_cco) = cco.at(&p.cco, t);
    [i_fac, i_trg, v_tde, i_cco, v_cco]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cancel::NEVER;
    use crate::network::tests::{periodic, vibtac};

    fn config(max_events: u64) -> RunConfig<'static> {
        RunConfig {
            keep_spikes: false,
            max_events,
            cancel: &NEVER,
        }
    }

    #[test]
    fn the_event_limit_says_whether_the_run_is_long_or_the_parameters_run_away() {
        let run_to = |p: &SpllParams, t_end: f64, max_events: u64| {
            let mut state = SpllState::new(p);
            let inputs = periodic(300.0, t_end);
            let mut rec = Recorder::default();
            run(
                p,
                &mut state,
                &inputs,
                t_end,
                &[],
                &config(max_events),
                &mut rec,
            )
            .unwrap_err()
            .0
        };
        let long = run_to(&vibtac(200.0), 100.0, 1000);
        assert!(long.contains("the run is long"), "{long}");
        assert!(long.contains("needs about"), "{long}");
        // No refractory periods, huge gains: the CCO fires without end.
        let fast = [
            1.0, 1.0, 1.0, 1.0, 2000.0, 0.0, 1.0, 10.0, 10.0, 10.0, 1.0, 1e6, 1e6, 0.0, 1.0,
        ];
        let runaway = run_to(&SpllParams::from_row(&fast, 0).unwrap(), 0.01, 100_000);
        assert!(
            runaway.contains("faster than the simulation can resolve"),
            "{runaway}"
        );
        assert!(
            runaway.contains("raise t_tde_refr or t_cco_refr"),
            "{runaway}"
        );
    }
}
