//! Event-driven simulation of one sPLL: input → facilitatory synapse, CCO → trigger synapse (gated
//! by the facilitatory current), TDE → CCO synapse (thesis section 2.4, Algorithm 1).
//!
//! State is kept local: each neuron holds its potential and synapse current at the time of its
//! last update and is decayed from there in closed form, so precision does not depend on how long
//! the run has been going. Only the neuron whose state an event changes is re-planned: an input
//! spike only changes the facilitatory current, which no membrane sees directly, so input spikes
//! cost one exponential each.

use crate::error::{bail, EngineError};
use crate::membrane::Neuron;
use crate::params::SpllParams;

/// Values per sPLL in a flattened [`SpllState`] (see [`SpllState::to_array`]).
pub const STATE_LEN: usize = 13;

/// Default limit on events per sPLL and call, so parameters that make a neuron fire absurdly
/// fast (say, no refractory period and a huge gain) end in an error instead of a hang.
pub const MAX_EVENTS: u64 = 200_000_000;

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
        let i = n.current(self.i0, t - self.t0);
        if t <= self.refr_end {
            (0.0, i)
        } else if self.t0 < self.refr_end {
            let i_free = n.current(self.i0, self.refr_end - self.t0);
            (n.potential(0.0, i_free, t - self.refr_end), i)
        } else {
            (n.potential(self.v0, self.i0, t - self.t0), i)
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
        self.advance(n, t);
        self.v0 = 0.0;
        self.refr_end = t + n.t_refr;
    }

    /// Re-plan the next spike from the current state (a pure function of the state).
    #[inline]
    fn plan(&mut self, n: &Neuron) {
        let free_from = self.t0.max(self.refr_end);
        let (v, i) = self.at(n, free_from);
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

/// Run one sPLL from `state` up to and including `t_end`, delivering the sorted `inputs`
/// (all later than the state's time, already validated), and recording into `rec`.
/// `probes` are sorted times at which the five state variables are sampled (right-continuous).
/// More than `max_events` events is an error.
pub fn run(
    p: &SpllParams,
    state: &mut SpllState,
    inputs: &[f64],
    t_end: f64,
    probes: &[f64],
    max_events: u64,
    rec: &mut Recorder,
) -> Result<(), EngineError> {
    let SpllState {
        fac_i,
        fac_t,
        tde,
        cco,
        ..
    } = state;
    let (n_tde, n_cco) = (&p.tde, &p.cco);
    let mut k = 0;
    let mut next_probe = 0;
    let mut events: u64 = 0;
    loop {
        let t_in = inputs.get(k).copied().unwrap_or(f64::INFINITY);
        let t = t_in.min(tde.next_spike).min(cco.next_spike);
        if !(t <= t_end) {
            break;
        }
        events += 1;
        if events > max_events {
            bail!(
                "more than {max_events} events before t = {t} s: a neuron fires faster than the \
                 simulation can resolve (raise its refractory period or lower its gains)"
            );
        }
        while next_probe < probes.len() && probes[next_probe] < t {
            rec.trace
                .push(sample(p, *fac_i, *fac_t, tde, cco, probes[next_probe]));
            next_probe += 1;
        }
        let input_spike = t_in == t;
        let tde_spike = tde.next_spike == t;
        let cco_spike = cco.next_spike == t;
        // Facilitatory current just before this instant's deliveries (the trigger gate).
        let fac_before = if input_spike || cco_spike {
            *fac_i * (-(t - *fac_t) / p.tau_fac).exp()
        } else {
            0.0
        };
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
        }
        // ... then every spike is delivered.
        if input_spike {
            let mut arrivals = 0.0;
            while k < inputs.len() && inputs[k] == t {
                arrivals += 1.0;
                k += 1;
            }
            *fac_i = fac_before + arrivals * p.g_fac;
            *fac_t = t;
        }
        let trigger = p.g_trg * fac_before;
        if cco_spike && trigger != 0.0 {
            tde.advance(n_tde, t);
            tde.i0 += trigger;
        }
        if tde_spike && p.g_cco != 0.0 {
            cco.advance(n_cco, t);
            cco.i0 += p.g_cco;
        }
        if tde_spike || cco_spike {
            tde.plan(n_tde);
            cco.plan(n_cco);
        }
    }
    for &probe in &probes[next_probe..] {
        rec.trace.push(sample(p, *fac_i, *fac_t, tde, cco, probe));
    }
    state.t = t_end;
    Ok(())
}

#[inline]
fn sample(
    p: &SpllParams,
    fac_i: f64,
    fac_t: f64,
    tde: &NeuronState,
    cco: &NeuronState,
    t: f64,
) -> [f64; 5] {
    let (v_tde, i_trg) = tde.at(&p.tde, t);
    let (v_cco, i_cco) = cco.at(&p.cco, t);
    [
        fac_i * (-(t - fac_t) / p.tau_fac).exp(),
        i_trg,
        v_tde,
        i_cco,
        v_cco,
    ]
}
