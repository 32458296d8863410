//! Event-driven simulation of one sPLL: input → facilitatory synapse, CCO → trigger synapse (gated
//! by the facilitatory current), TDE → CCO synapse (thesis section 2.4, Algorithm 1).
//!
//! State is kept local: each neuron holds its potential and synapse current at the time of its
//! last update and is decayed from there in closed form, so precision does not depend on how long
//! the run has been going. Input spikes only change the facilitatory current, which no membrane
//! sees directly: it is computed once per run from the input train, and the event loop visits
//! only TDE and CCO spikes.

use crate::error::{approx, bail, EngineError};
use crate::gate::Staircase;
use crate::membrane::Neuron;
use crate::network::RunConfig;
use crate::params::SpllParams;

/// Values per sPLL in a flattened [`SpllState`] (see [`SpllState::to_array`]).
pub const STATE_LEN: usize = 13;

/// Names of the values of a flattened [`SpllState`], in [`SpllState::to_array`] order.
pub const STATE_NAMES: [&str; STATE_LEN] = [
    "t",
    "fac_i",
    "fac_t",
    "tde_t0",
    "tde_v0",
    "tde_i0",
    "tde_refr_end",
    "tde_next_spike",
    "cco_t0",
    "cco_v0",
    "cco_i0",
    "cco_refr_end",
    "cco_next_spike",
];

/// Largest current [A] a saved state may hold: far above what parameters within
/// [`crate::params::LARGEST`] build up, far below where its products with them overflow.
pub const LARGEST_STATE_CURRENT: f64 = 1e150;

/// Relative difference a saved next spike time may have from the one its state plans (the
/// same engine plans it bit for bit; another build's exponentials may differ in the last bits).
const PLAN_TOLERANCE: f64 = 1e-9;

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
        let (free_from, v, i) = self.free_start(n);
        self.plan_from(n, free_from, v, i);
    }

    /// The first time `free_from` at which the neuron can move (the state's time or the end of
    /// its refractory period) and `(V, I)` there.
    #[inline]
    fn free_start(&self, n: &Neuron) -> (f64, f64, f64) {
        let free_from = self.t0.max(self.refr_end);
        let (v, i) = if self.t0 + n.t_refr == self.refr_end && self.t0 < self.refr_end {
            // Just fired: V is 0 at the end of the refractory period and the synapse current
            // has decayed by the neuron's constant factor for one refractory period.
            (0.0, self.i0 * n.refr_syn_decay)
        } else {
            self.at(n, free_from)
        };
        (free_from, v, i)
    }

    /// [`plan`](Self::plan) from its [`free_start`](Self::free_start).
    #[inline]
    fn plan_from(&mut self, n: &Neuron, free_from: f64, v: f64, i: f64) {
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

    /// Inverse of [`to_array`](Self::to_array) (only the length is checked here; [`check`](
    /// Self::check) checks the values against the parameters).
    pub fn from_array(a: &[f64], index: usize) -> Result<Self, EngineError> {
        if a.len() != STATE_LEN {
            bail!(
                "state of sPLL {index}: expected {STATE_LEN} values, got {}",
                a.len()
            );
        }
        let t = a[0];
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

    /// Check that a loaded state is one this engine could have made for `p` (sPLL number
    /// `index`): times finite with `0 <= fac_t, t0 <= t`, currents in
    /// `[0, LARGEST_STATE_CURRENT]`, potentials in `[0, V_thr)` and 0 while refractory, each
    /// refractory end `-inf` (never fired) or within one refractory period after a spike no
    /// later than `t0`, and each next spike the one its neuron's state plans, after `t` (`inf`
    /// if none). The error names the first bad value ([`STATE_NAMES`]) and the sPLL.
    pub fn check(&self, p: &SpllParams, index: usize) -> Result<(), EngineError> {
        let t = self.t;
        let fail = |k: usize, why: String| {
            let value = self.to_array()[k];
            EngineError(format!(
                "saved state of sPLL {index}: {} = {value:?} {why}",
                STATE_NAMES[k]
            ))
        };
        if !(t.is_finite() && t >= 0.0) {
            return Err(fail(0, "must be a finite time >= 0 s".into()));
        }
        if !(0.0..=t).contains(&self.fac_t) {
            return Err(fail(2, format!("must be a time in [0, t = {t:?}] s")));
        }
        if !(0.0..=LARGEST_STATE_CURRENT).contains(&self.fac_i) {
            return Err(fail(
                1,
                format!("must be a current in [0, {LARGEST_STATE_CURRENT:e}] A"),
            ));
        }
        check_neuron(&self.tde, &p.tde, t).map_err(|(k, why)| fail(3 + k, why))?;
        check_neuron(&self.cco, &p.cco, t).map_err(|(k, why)| fail(8 + k, why))
    }
}

/// [`SpllState::check`] for one neuron `s` of a state at time `t`; the error is the index of
/// the bad value in the neuron's five (`t0, v0, i0, refr_end, next_spike`) and why.
fn check_neuron(s: &NeuronState, n: &Neuron, t: f64) -> Result<(), (usize, String)> {
    if !(0.0..=t).contains(&s.t0) {
        return Err((0, format!("must be a time in [0, t = {t:?}] s")));
    }
    if !(0.0..=LARGEST_STATE_CURRENT).contains(&s.i0) {
        return Err((
            2,
            format!("must be a current in [0, {LARGEST_STATE_CURRENT:e}] A"),
        ));
    }
    let never_fired = s.refr_end == f64::NEG_INFINITY;
    if !(never_fired || (n.t_refr..=s.t0 + n.t_refr).contains(&s.refr_end)) {
        return Err((
            3,
            format!(
                "must be -inf (never fired) or end one refractory period ({:?} s) after a \
                 spike at a time in [0, t0]",
                n.t_refr
            ),
        ));
    }
    if !(0.0..n.v_thr).contains(&s.v0) || (s.v0 != 0.0 && s.t0 < s.refr_end) {
        return Err((
            1,
            format!(
                "must be a potential in [0, V_thr = {:?}) V, and 0 while refractory",
                n.v_thr
            ),
        ));
    }
    let mut planned = *s;
    planned.plan(n);
    let planned = planned.next_spike;
    let agrees = s.next_spike == planned
        || (planned.is_finite()
            && (s.next_spike - planned).abs() <= PLAN_TOLERANCE * planned.abs());
    if !agrees {
        return Err((
            4,
            format!("is not the spike its state plans ({planned:?} s)"),
        ));
    }
    if s.next_spike <= t {
        return Err((4, format!("must be after the state's time t = {t:?} s")));
    }
    Ok(())
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
/// sPLLs with the same facilitatory synapse and saved current share one ([`serves`](
/// Self::serves)): every sPLL of a vary-offset or grouped network run from rest.
pub struct Facilitation {
    /// Distinct input times [s], ascending.
    times: Vec<f64>,
    /// Facilitatory current [A] just after each of `times` (all arrivals at that time added).
    after: Vec<f64>,
    /// Current [A] and time [s] before the first input of this run (from the saved state).
    start: (f64, f64),
    inv_tau: f64,
    gain: f64,
}

impl Facilitation {
    /// The current of `p`'s facilitatory synapse from `state`'s saved current through the
    /// sorted `inputs` up to `t_end` (later ones are ignored).
    pub fn new(p: &SpllParams, state: &SpllState, inputs: &[f64], t_end: f64) -> Self {
        let inputs = &inputs[..inputs.partition_point(|&t| t <= t_end)];
        let start = (state.fac_i, state.fac_t);
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
            gain: p.g_fac,
        }
    }

    /// Whether this is also the current of `p`'s synapse from `state` (same time constant,
    /// gain and saved current: then the same inputs give the same values bit for bit).
    pub fn serves(&self, p: &SpllParams, state: &SpllState) -> bool {
        self.inv_tau == p.inv_tau_fac
            && self.gain == p.g_fac
            && self.start == (state.fac_i, state.fac_t)
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
    ///
    /// Between two CCO spikes none, one or a few inputs arrive at random, so a loop that stops
    /// at the first later time mispredicts its exit on most calls. Counting the earlier times among
    /// the next four (sorted, so they are a prefix) has no branch to mispredict until a window
    /// is full: 8 % faster on the reference workload, 4 % on the demo's network.
    #[inline]
    fn seek(&self, k: &mut usize, t: f64, inclusive: bool) {
        let before = |x: f64| x < t || (inclusive && x == t);
        while let Some(window) = self.times.get(*k..*k + 4) {
            let earlier = window.iter().map(|&x| before(x) as usize).sum::<usize>();
            *k += earlier;
            if earlier < 4 {
                return;
            }
        }
        while *k < self.times.len() && before(self.times[*k]) {
            *k += 1;
        }
    }
}

/// One sPLL's run in progress ([`run`] drives it to the end with [`step`](Self::step)).
/// Keeping the run's state in one value lets a caller interleave the runs of independent sPLLs
/// ([`run_interleaved`]).
pub struct Stepper<'a> {
    p: &'a SpllParams,
    state: &'a mut SpllState,
    fac: &'a Facilitation,
    probes: &'a [f64],
    config: &'a RunConfig<'a>,
    rec: &'a mut Recorder,
    /// The K-level gate in place of the product (`None`: the golden model).
    gate: Option<Staircase<'a>>,
    t_end: f64,
    start: f64,
    gate_cursor: usize,
    probe_cursor: usize,
    next_probe: usize,
    events: u64,
    /// The CCO's next spike is not planned (`next_spike` is `inf`): it fired, and the TDE
    /// fires before it can reach threshold again; that TDE spike plans it (see [`step`](
    /// Self::step)).
    cco_unplanned: bool,
}

impl<'a> Stepper<'a> {
    /// Start a run of one sPLL from `state` up to and including `t_end` (see [`run`]), its
    /// input given as the facilitatory current `fac` it makes (one that [`serves`](
    /// Facilitation::serves) this sPLL and state, built with the same `t_end`).
    pub fn new(
        p: &'a SpllParams,
        state: &'a mut SpllState,
        fac: &'a Facilitation,
        t_end: f64,
        probes: &'a [f64],
        config: &'a RunConfig<'a>,
        rec: &'a mut Recorder,
    ) -> Result<Self, EngineError> {
        debug_assert!(fac.serves(p, state));
        config.cancel.check()?;
        Ok(Stepper {
            p,
            start: state.t,
            state,
            fac,
            probes,
            config,
            rec,
            gate: None,
            t_end,
            gate_cursor: 0,
            probe_cursor: 0,
            next_probe: 0,
            events: 0,
            cco_unplanned: false,
        })
    }

    /// Gate the trigger with a K-level staircase (the standard-neuron sPLL, [`crate::gate`])
    /// instead of the product `g_trg * I_fac`; `None` keeps the golden product.
    pub fn gated(mut self, gate: Option<Staircase<'a>>) -> Self {
        self.gate = gate;
        self
    }

    /// Handle the next event (a TDE spike, a CCO spike or both at once); `false` once the next
    /// one would come after the end (call [`finish`](Self::finish) then).
    #[inline]
    pub fn step(&mut self) -> Result<bool, EngineError> {
        let p = self.p;
        let (n_tde, n_cco) = (&p.tde, &p.cco);
        let SpllState { tde, cco, .. } = &mut *self.state;
        let t = tde.next_spike.min(cco.next_spike);
        if t > self.t_end || t.is_nan() {
            return Ok(false);
        }
        self.events += 1;
        if self.events > self.config.max_events {
            return Err(event_limit(
                p,
                self.config.max_events,
                self.start,
                t,
                self.t_end,
            ));
        }
        if self.events.is_multiple_of(CANCEL_POLL) {
            self.config.cancel.check()?;
        }
        let rec = &mut *self.rec;
        while self.next_probe < self.probes.len() && self.probes[self.next_probe] < t {
            let at = self.probes[self.next_probe];
            self.fac.seek(&mut self.probe_cursor, at, true);
            let i_fac = self.fac.current(self.probe_cursor, at);
            rec.trace.push(sample(p, i_fac, tde, cco, at));
            self.next_probe += 1;
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
            self.fac.seek(&mut self.gate_cursor, t, false);
            let i_fac = self.fac.current(self.gate_cursor, t);
            let trigger = p.g_trg * self.gate.map_or(i_fac, |g| g.level(i_fac));
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
        // A CCO that just fired charges from reset. If the TDE fires before the CCO can reach
        // threshold, that TDE spike is the next event and plans the CCO again from its state
        // then, so the crossing planned now would never be used: it is left unplanned (on the
        // README demo's networks nearly every TDE spike came before the CCO's next crossing).
        let (from, v, i) = cco.free_start(n_cco);
        self.cco_unplanned =
            cco_spike && v == 0.0 && tde.next_spike < from + n_cco.no_crossing_before(i);
        if self.cco_unplanned {
            cco.next_spike = f64::INFINITY;
        } else {
            cco.plan_from(n_cco, from, v, i);
        }
        Ok(true)
    }

    /// Sample the probes after the last event and leave the state at the end time.
    pub fn finish(self) {
        let Stepper {
            p,
            state,
            fac,
            probes,
            rec,
            t_end,
            mut probe_cursor,
            next_probe,
            cco_unplanned,
            ..
        } = self;
        if cco_unplanned {
            // The run ends before the TDE spike that would have planned it.
            state.cco.plan(&p.cco);
        }
        for &at in &probes[next_probe..] {
            fac.seek(&mut probe_cursor, at, true);
            rec.trace.push(sample(
                p,
                fac.current(probe_cursor, at),
                &state.tde,
                &state.cco,
                at,
            ));
        }
        if let (Some(&t), Some(&i)) = (fac.times.last(), fac.after.last()) {
            (state.fac_i, state.fac_t) = (i, t);
        }
        state.t = t_end;
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
    let fac = Facilitation::new(p, state, inputs, t_end);
    let run = Stepper::new(p, state, &fac, t_end, probes, config, rec)?;
    run_interleaved(vec![run]).map_err(|(_, e)| e)
}

/// Independent runs with their events interleaved one for one until all end. Each event is a
/// chain of dependent exponentials and roots, so the processor overlaps one run's chain with
/// the others'; the results are those of running them one after the other. An error names the
/// run (its position in `runs`).
pub fn run_interleaved(runs: Vec<Stepper<'_>>) -> Result<(), (usize, EngineError)> {
    let mut active: Vec<(usize, Stepper<'_>)> = runs.into_iter().enumerate().collect();
    while !active.is_empty() {
        let mut k = 0;
        while k < active.len() {
            let (index, run) = &mut active[k];
            match run.step() {
                Ok(true) => k += 1,
                Ok(false) => active.swap_remove(k).1.finish(),
                Err(e) => return Err((*index, e)),
            }
        }
    }
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
mod tests;
