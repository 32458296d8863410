//! Discrete-time fixed-point reference of the sPLL network: the integer arithmetic a digital
//! neuromorphic chip performs, bit for bit.
//!
//! The golden model ([`crate::spll`]) is exact in continuous time. A digital chip instead steps
//! time in units of `dt` and keeps every state variable as a saturating integer. This module is
//! that chip's behaviour, specified precisely enough for another implementation (the Lava
//! fixed-point process models of `mappings/lava`, the pure-Python check in
//! `tests/test_fixed_point.py`) to reproduce it spike for spike. `quantize.core.quantize` (Python)
//! turns a continuous network into the integer parameters below and reports what was lost.
//!
//! # Formats
//!
//! * State words are signed `state_bits`-bit integers (`2 <= state_bits <= 32`), saturating at
//!   `S = 2^(state_bits-1) - 1`. Every parameter is non-negative, so every state stays in `[0, S]`
//!   and only the upper bound can be hit; each time a value is clipped to `S` a per-variable
//!   saturation counter is incremented.
//! * A decay constant `δ` is a `decay_bits`-bit unsigned integer, `0 <= δ <= 2^D` with
//!   `D = decay_bits <= 30`. One step of decay is `x ← (x · (2^D − δ)) >> D`: multiply, then
//!   shift right (truncation, which for `x >= 0` is truncation toward zero as on Loihi). A
//!   continuous time constant `τ` corresponds to `δ ≈ 2^D (1 − e^{−dt/τ})`.
//! * Products are formed in 64 bits; the bounds above keep them below `2^62`.
//!
//! # Parameters of one sPLL (one row, [`FIXED_PARAM_NAMES`] order)
//!
//! CCO: `cco_syn_decay`, `cco_decay` (δ of its synapse current `u` and potential `v`),
//! `cco_weight` (added to `u` per TDE spike), `cco_current_shift` (`c`: currents carry `c`
//! fractional bits), `cco_bias` (the offset current, with the same fractional bits),
//! `cco_refr` (refractory period [steps]), `cco_threshold` (`θ`).
//! TDE: `fac_decay`, `trg_decay`, `tde_decay` (δ of the facilitatory current `f`, the trigger
//! current `g` and the potential `v`), `fac_weight` (added to `f` per input spike),
//! `trg_mantissa`, `trg_shift` (the trigger weight `m · 2^−s`), `tde_current_shift` (`g`'s
//! fractional bits), `tde_refr`, `tde_threshold`.
//!
//! # One time step `k = 1, 2, …, K` (state at step 0: everything 0)
//!
//! Inputs: `n_k` input spikes arrive at step `k` (a spike at time `t` arrives at step
//! `max(1, ⌈t/dt⌉)`: during the step it happened in). Every spike a neuron emits at step `k` is
//! received at step `k + 1`, Loihi's one-step synaptic delay. In this order:
//!
//! 1. TDE synapses. If the CCO fired at `k − 1`, the trigger increment is the integer product of
//!    the facilitatory current *as it stood when the CCO fired* with the trigger weight,
//!    `Δg = (f_{k−1} · trg_mantissa) >> trg_shift` (else 0). Then
//!    `f_k = sat(decay(f_{k−1}) + n_k · fac_weight)` and `g_k = sat(decay(g_{k−1}) + Δg)`.
//! 2. TDE membrane (see *membrane* below) driven by `g_k >> tde_current_shift`.
//! 3. CCO synapse: `u_k = sat(decay(u_{k−1}) + [TDE fired at k − 1] · cco_weight)`.
//! 4. CCO membrane driven by `(u_k + cco_bias) >> cco_current_shift`.
//!
//! *Membrane* with drive `d`: while the refractory counter is positive it is decremented and `v`
//! stays at 0 (the currents keep evolving); otherwise `v_k = sat(decay(v_{k−1}) + d)`, and if
//! `v_k > θ` (strictly, as Loihi) the neuron spikes, `v` is reset to 0 and the counter is set
//! to the refractory period. A spike at step `k` is reported at time `k · dt`.
//!
//! Currents are in "potential LSBs per step" with `c` extra fractional bits: `v += u >> c`
//! integrates the current over one step, so a continuous current `I` into a membrane of
//! capacitance `C` and time constant `τ` is the integer `2^c · I · τ (1 − e^{−dt/τ}) / (C · q_v)`
//! with `q_v = V_thr / θ` the potential's LSB; this factor makes a constant current (the CCO
//! offset) charge the membrane exactly as in continuous time at every step. The fractional bits matter as `dt` shrinks: a current of `u` LSBs decays by
//! `u δ / 2^D ∝ u dt` LSBs a step and truncation removes up to one more, so without them small
//! currents die out linearly instead of exponentially, and the bias (`∝ dt`) loses resolution.
//! With `c = 0` (Loihi) the membrane adds `u + bias` itself.
//!
//! # Implementation
//!
//! [`simulate_fixed`] steps blocks of sPLLs in lanes (module `kernel`): sixteen per pair of
//! AVX-512 registers when the CPU has AVX-512F (detected at run time; decays by AVX-512 IFMA
//! multiply-adds when it has that too), one at a time otherwise. Every implementation is the
//! same integer arithmetic, bit for bit: the tests check each one the CPU can run against a
//! plain per-sPLL, per-step transcription of the steps above (module `reference`).
//!
//! # Mapping to a chip
//!
//! With `cco_current_shift = 0` the CCO is a standard current-based LIF neuron with bias and
//! refractory period (Loihi's compartment: `u` and `v` decayed by 12-bit `du`, `dv`; `bias = mantissa << exponent`;
//! threshold `vth << 6`), fed by a dense synapse of weight `cco_weight` from the TDE. The TDE's
//! trigger gating multiplies two quantities at run time, the facilitatory *state* and a weight,
//! which a fixed synapse cannot express. On a programmable-neuron chip (Loihi 2's neuron
//! microcode) it is one neuron with three state words `f`, `g`, `v` and two input ports: the
//! input spikes (weighted sum into `f`) and the CCO spike (a 1-bit event). Its program, per step,
//! runs steps 1–2 above: one 24 × 8-bit multiply and a barrel shift by `trg_shift` when the
//! trigger event is present. Without a multiplier the same product is obtained with graded
//! spikes: a compartment holding `f` sends `f` as the payload of a graded spike when the trigger
//! arrives, and a synapse of weight `trg_mantissa` with exponent `−trg_shift` delivers it to `g`.

use rayon::prelude::*;

use crate::cancel::{Cancel, NEVER};
use crate::error::{bail, EngineError};
use crate::network::validate_inputs;
use crate::threads;

mod kernel;
mod lanes;
#[cfg(test)]
mod reference;

use kernel::{first_free_spike, group_arrivals, Arrival, BlockRun, Kernel};

/// Number of integer parameters per sPLL (columns of the fixed-point parameter matrix).
pub const N_FIXED_PARAMS: usize = 16;

/// Column names of the fixed-point parameter matrix, identical to
/// `quantize.fixed_point.FIXED_PARAM_NAMES` on the Python side.
pub const FIXED_PARAM_NAMES: [&str; N_FIXED_PARAMS] = [
    "cco_syn_decay",
    "cco_decay",
    "cco_weight",
    "cco_current_shift",
    "cco_bias",
    "cco_refr",
    "cco_threshold",
    "fac_decay",
    "trg_decay",
    "tde_decay",
    "fac_weight",
    "trg_mantissa",
    "trg_shift",
    "tde_current_shift",
    "tde_refr",
    "tde_threshold",
];

/// Saturation counters per sPLL, in this order: `f`, `g`, TDE `v`, CCO `u`, CCO `v`.
pub const N_SATURATION: usize = 5;

/// Values per sPLL in a flattened [`FixedState`] (see [`FixedState::to_array`]).
pub const FIXED_STATE_LEN: usize = 9;

/// Widest state word: 32 bits keep every product below `2^62`.
pub const MAX_STATE_BITS: u32 = 32;

/// Widest decay constant.
pub const MAX_DECAY_BITS: u32 = 30;

/// Largest trigger shift.
pub const MAX_TRIGGER_SHIFT: i64 = 62;

/// Largest fractional-bit shift of a current.
pub const MAX_CURRENT_SHIFT: u32 = 30;

/// Block-steps (time steps × blocks of sPLLs) below which one sample runs its blocks one
/// after the other: a block-step takes nanoseconds, waking the pool's threads up to a
/// millisecond (short resumed pieces, as the USB emulator runs one per packet).
const PARALLEL_BLOCK_STEPS: u64 = 1 << 16;

/// Default limit on time steps per call (guards against a `dt` far too small for the run).
pub const MAX_STEPS: u64 = 1_000_000_000;

/// Word widths shared by every sPLL of a network.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FixedFormat {
    /// Width of a state word in bits, sign included.
    pub state_bits: u32,
    /// Width of a decay constant in bits (the shift after the decay multiply).
    pub decay_bits: u32,
}

impl FixedFormat {
    /// Validate the widths.
    pub fn new(state_bits: u32, decay_bits: u32) -> Result<Self, EngineError> {
        if !(2..=MAX_STATE_BITS).contains(&state_bits) {
            bail!("state_bits must be between 2 and {MAX_STATE_BITS}, got {state_bits}");
        }
        if !(1..=MAX_DECAY_BITS).contains(&decay_bits) {
            bail!("decay_bits must be between 1 and {MAX_DECAY_BITS}, got {decay_bits}");
        }
        Ok(FixedFormat {
            state_bits,
            decay_bits,
        })
    }

    /// Largest state value, `2^(state_bits-1) - 1`.
    pub fn state_max(&self) -> i64 {
        (1i64 << (self.state_bits - 1)) - 1
    }

    /// `2^decay_bits`: a decay constant of this value clears a variable in one step.
    pub fn decay_unity(&self) -> i64 {
        1i64 << self.decay_bits
    }
}

/// Integer parameters of one sPLL (module docs), validated against a [`FixedFormat`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FixedSpll {
    pub cco_syn_decay: i64,
    pub cco_decay: i64,
    pub cco_weight: i64,
    pub cco_current_shift: i64,
    pub cco_bias: i64,
    pub cco_refr: i64,
    pub cco_threshold: i64,
    pub fac_decay: i64,
    pub trg_decay: i64,
    pub tde_decay: i64,
    pub fac_weight: i64,
    pub trg_mantissa: i64,
    pub trg_shift: i64,
    pub tde_current_shift: i64,
    pub tde_refr: i64,
    pub tde_threshold: i64,
}

impl FixedSpll {
    /// Validate one row of the fixed-point parameter matrix (`index` names it in messages).
    pub fn from_row(row: &[i64], index: usize, format: &FixedFormat) -> Result<Self, EngineError> {
        if row.len() != N_FIXED_PARAMS {
            bail!(
                "sPLL {index}: expected {N_FIXED_PARAMS} fixed-point parameters, got {}",
                row.len()
            );
        }
        let unity = format.decay_unity();
        let max = format.state_max();
        for (&value, name) in row.iter().zip(FIXED_PARAM_NAMES) {
            let (low, high, what) = match name {
                "cco_syn_decay" | "cco_decay" | "fac_decay" | "trg_decay" | "tde_decay" => {
                    (0, unity, "a decay constant of decay_bits bits")
                }
                "cco_weight" | "cco_bias" | "fac_weight" => (0, max, "a state-word value"),
                "cco_threshold" | "tde_threshold" => (0, max - 1, "below the largest state value"),
                "trg_mantissa" => (0, i64::from(i32::MAX), "a 31-bit magnitude"),
                "trg_shift" => (0, MAX_TRIGGER_SHIFT, "a shift of at most 62 bits"),
                "cco_current_shift" | "tde_current_shift" => (
                    0,
                    i64::from(MAX_CURRENT_SHIFT),
                    "a shift of at most 30 bits",
                ),
                _ => (0, i64::from(u32::MAX), "a 32-bit step count"),
            };
            if !(low..=high).contains(&value) {
                bail!(
                    "sPLL {index}: fixed-point parameter {name} = {value} is out of range \
                     [{low}, {high}] ({what}; state_bits {}, decay_bits {})",
                    format.state_bits,
                    format.decay_bits
                );
            }
        }
        Ok(FixedSpll {
            cco_syn_decay: row[0],
            cco_decay: row[1],
            cco_weight: row[2],
            cco_current_shift: row[3],
            cco_bias: row[4],
            cco_refr: row[5],
            cco_threshold: row[6],
            fac_decay: row[7],
            trg_decay: row[8],
            tde_decay: row[9],
            fac_weight: row[10],
            trg_mantissa: row[11],
            trg_shift: row[12],
            tde_current_shift: row[13],
            tde_refr: row[14],
            tde_threshold: row[15],
        })
    }

    /// Validate a row-major `(n, 14)` fixed-point parameter matrix.
    pub fn from_matrix(flat: &[i64], format: &FixedFormat) -> Result<Vec<Self>, EngineError> {
        if flat.is_empty() || !flat.len().is_multiple_of(N_FIXED_PARAMS) {
            bail!(
                "fixed-point parameter matrix must have shape (n_spll >= 1, {N_FIXED_PARAMS}); \
                 got {} values",
                flat.len()
            );
        }
        flat.chunks_exact(N_FIXED_PARAMS)
            .enumerate()
            .map(|(i, row)| Self::from_row(row, i, format))
            .collect()
    }
}

/// Integer state of one sPLL after a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FixedState {
    /// Facilitatory current `f`.
    pub fac: i64,
    /// Trigger current `g`.
    pub trg: i64,
    /// TDE potential.
    pub v_tde: i64,
    /// Refractory steps the TDE has still to wait.
    pub tde_refr_left: i64,
    /// CCO synapse current.
    pub u_cco: i64,
    /// CCO potential.
    pub v_cco: i64,
    /// Refractory steps the CCO has still to wait.
    pub cco_refr_left: i64,
    /// The TDE fired at this step (its spike reaches the CCO at the next).
    pub tde_fired: bool,
    /// The CCO fired at this step (its spike reaches the TDE at the next).
    pub cco_fired: bool,
}

/// Names of the values of [`FixedState::to_array`], in its order.
pub const FIXED_STATE_NAMES: [&str; FIXED_STATE_LEN] = [
    "fac",
    "trg",
    "v_tde",
    "tde_refr_left",
    "u_cco",
    "v_cco",
    "cco_refr_left",
    "tde_fired",
    "cco_fired",
];

impl FixedState {
    /// Inverse of [`FixedState::to_array`], refusing a state a run of `p` cannot have left:
    /// every current in `[0, S]`, every potential in `[0, threshold]`, every refractory count
    /// in `[0, refractory period]`, the spike flags 0 or 1. `what` names the state in messages.
    pub fn from_array(
        row: &[i64],
        p: &FixedSpll,
        format: &FixedFormat,
        what: &str,
    ) -> Result<Self, EngineError> {
        if row.len() != FIXED_STATE_LEN {
            bail!(
                "{what}: expected {FIXED_STATE_LEN} state values, got {}",
                row.len()
            );
        }
        let max = format.state_max();
        let highs = [
            max,
            max,
            p.tde_threshold,
            p.tde_refr,
            max,
            p.cco_threshold,
            p.cco_refr,
            1,
            1,
        ];
        for ((&value, high), name) in row.iter().zip(highs).zip(FIXED_STATE_NAMES) {
            if !(0..=high).contains(&value) {
                bail!("{what}: {name} = {value} is out of range [0, {high}]");
            }
        }
        Ok(FixedState {
            fac: row[0],
            trg: row[1],
            v_tde: row[2],
            tde_refr_left: row[3],
            u_cco: row[4],
            v_cco: row[5],
            cco_refr_left: row[6],
            tde_fired: row[7] == 1,
            cco_fired: row[8] == 1,
        })
    }

    /// `[fac, trg, v_tde, tde_refr_left, u_cco, v_cco, cco_refr_left, tde_fired, cco_fired]`.
    pub fn to_array(&self) -> [i64; FIXED_STATE_LEN] {
        [
            self.fac,
            self.trg,
            self.v_tde,
            self.tde_refr_left,
            self.u_cco,
            self.v_cco,
            self.cco_refr_left,
            i64::from(self.tde_fired),
            i64::from(self.cco_fired),
        ]
    }
}

/// Output of one sPLL on one sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FixedRecord {
    /// TDE spike times [s] (`k · dt`), when spikes are kept.
    pub tde_spikes: Vec<f64>,
    /// CCO spike times [s], when spikes are kept.
    pub cco_spikes: Vec<f64>,
    pub tde_count: u64,
    pub cco_count: u64,
    /// How often each variable was clipped at the largest state value ([`N_SATURATION`] order).
    pub saturations: [u64; N_SATURATION],
    /// State after the last step.
    pub state: FixedState,
}

/// Time step, length and recording options shared by every sPLL and sample of a call.
#[derive(Clone, Copy, Debug)]
pub struct StepConfig<'a> {
    /// Time step [s].
    pub dt: f64,
    /// Length of the run [s]; it runs `round(duration / dt)` steps.
    pub duration: f64,
    /// Step the run resumes after (0: a run from rest); it then runs steps `start_step + 1 ..=
    /// round(duration / dt)`.
    pub start_step: u64,
    /// The state each sample resumes from, one per sPLL ([`FixedRecord::state`] of a run that
    /// ended at step `start_step`); empty: every sample from rest. Inputs must then arrive
    /// after `start_step`. A run split into pieces this way is the whole run bit for bit.
    pub starts: &'a [Vec<FixedState>],
    /// Keep spike times (otherwise only count them).
    pub keep_spikes: bool,
    /// More steps than this is an error.
    pub max_steps: u64,
    /// Raised to stop the call early (it then returns an error).
    pub cancel: &'a Cancel,
}

impl StepConfig<'_> {
    /// Number of steps `K = round(duration / dt)`, validated.
    pub fn n_steps(&self) -> Result<u64, EngineError> {
        let (dt, duration) = (self.dt, self.duration);
        if !(dt.is_finite() && dt > 0.0) {
            bail!("time step dt must be finite and > 0 s, got {dt}");
        }
        if !(duration.is_finite() && duration > 0.0) {
            bail!("duration must be finite and > 0 s, got {duration}");
        }
        let steps = (duration / dt).round();
        if steps < 1.0 {
            bail!("duration {duration} s is shorter than half a time step (dt = {dt} s)");
        }
        // Steps beyond 2^53 are not even distinct as f64 (and keep `k + refr` far from 2^63).
        let limit = self.max_steps.min(1 << 53);
        if steps > limit as f64 {
            bail!(
                "duration {duration} s at dt = {dt} s is {steps} time steps, more than the limit \
                 of {limit} (raise dt or shorten the run)"
            );
        }
        if steps as u64 <= self.start_step {
            bail!(
                "duration {duration} s at dt = {dt} s ends at step {steps}, not after the \
                 resumed state's step {}",
                self.start_step
            );
        }
        Ok(steps as u64)
    }
}

/// Relative tolerance within which `t / dt` counts as a whole number of steps: the model's
/// `GRID_RTOL` (`spll_hw/model/grid.py`, which states the grid rule this follows).
pub const GRID_RTOL: f64 = 1e-12;

/// The step at which an input spike at `t` [s] arrives: `max(1, ⌈x - x·GRID_RTOL⌉)` with
/// `x = t / dt`, so a spike on a step's end belongs to that step also when `t / dt` rounds a few
/// ulps above it (the same arithmetic as `spll_hw.model.grid.spike_steps`).
pub fn spike_step(t: f64, dt: f64) -> u64 {
    let x = t / dt;
    ((x - x * GRID_RTOL).ceil() as u64).max(1)
}

/// The step at which each input spike arrives ([`spike_step`]), keeping those up to step
/// `n_steps`. The times are checked (finite, >= 0, sorted, arriving after `start_step`, the
/// step a resumed run starts after); `what` names the sample.
pub fn input_steps(
    times: &[f64],
    dt: f64,
    start_step: u64,
    n_steps: u64,
    what: &str,
) -> Result<Vec<u64>, EngineError> {
    validate_inputs(times, 0.0, true, what)?;
    let steps: Vec<u64> = times
        .iter()
        .map(|&t| spike_step(t, dt))
        .take_while(|&k| k <= n_steps)
        .collect();
    if let Some(&first) = steps.first() {
        if first <= start_step {
            bail!(
                "{what}: input spike 0 at {} s arrives at step {first}, not after the resumed \
                 state's step {start_step} (pass only the spikes that follow the saved state)",
                times[0]
            );
        }
    }
    Ok(steps)
}

/// Run one sPLL from rest for steps `1..=n_steps`, with inputs arriving at the sorted steps
/// `arrivals` (each in `1..=n_steps`; repeats are several spikes in one step); `dt` [s] scales
/// the recorded spike times.
pub fn run_fixed(
    p: &FixedSpll,
    format: &FixedFormat,
    arrivals: &[u64],
    n_steps: u64,
    dt: f64,
    keep_spikes: bool,
) -> FixedRecord {
    let arrivals = group_arrivals(arrivals);
    let run = BlockRun {
        format,
        arrivals: &arrivals,
        start_step: 0,
        n_steps,
        dt,
        keep_spikes,
        cancel: &NEVER,
    };
    let mut records = Kernel::detect().run(std::slice::from_ref(p), &[], &run);
    records.pop().unwrap_or_default()
}

/// Free-running period [steps] of each sPLL's CCO with no input: its synapse current stays 0,
/// so it is driven by `cco_bias >> cco_current_shift` alone. The period is the step `k1` of
/// its first spike from rest plus `cco_refr` (it then repeats from rest every period); 0 if it
/// does not fire within `max_steps` steps. Computed with the same membrane step as
/// [`simulate_fixed`]; equal to what a run with an empty input train shows. A raised `cancel`
/// stops the call with an error.
pub fn cco_free_periods(
    params: &[FixedSpll],
    format: &FixedFormat,
    max_steps: u64,
    cancel: &Cancel,
) -> Result<Vec<u64>, EngineError> {
    if max_steps > MAX_STEPS {
        bail!("max_steps must be at most {MAX_STEPS}, got {max_steps}");
    }
    let periods = params
        .iter()
        .map(|p| {
            first_free_spike(p, format, max_steps, cancel).map_or(0, |k| k + p.cco_refr as u64)
        })
        .collect();
    cancel.check()?;
    Ok(periods)
}

/// Simulate every sample of `inputs` (input spike times [s], each sorted) through every sPLL,
/// from rest, or from `config.starts` after step `config.start_step`. One sample runs its sPLLs
/// in parallel (one after the other when the run is short); several run in parallel over samples, on
/// `threads` threads (rayon's global pool when `None`, at most [`threads::max_threads`]).
/// Returns, per sample, one record per sPLL. Everything is validated before anything runs; a
/// raised `config.cancel` stops the call with an error.
pub fn simulate_fixed(
    params: &[FixedSpll],
    format: &FixedFormat,
    inputs: &[&[f64]],
    config: StepConfig<'_>,
    threads: Option<usize>,
) -> Result<Vec<Vec<FixedRecord>>, EngineError> {
    if params.is_empty() {
        bail!("a fixed-point network needs at least one sPLL");
    }
    let starts = config.starts;
    if !starts.is_empty() && starts.len() != inputs.len() {
        bail!(
            "{} start states for {} samples: give one per sample (or none, from rest)",
            starts.len(),
            inputs.len()
        );
    }
    if let Some((i, s)) = starts
        .iter()
        .enumerate()
        .find(|(_, s)| s.len() != params.len())
    {
        bail!(
            "start state of sample {i} has {} sPLLs but the network has {}",
            s.len(),
            params.len()
        );
    }
    simulate_with(Kernel::detect(), params, format, inputs, config, threads)
}

/// [`simulate_fixed`] with a chosen step-loop implementation.
fn simulate_with(
    kernel: Kernel,
    params: &[FixedSpll],
    format: &FixedFormat,
    inputs: &[&[f64]],
    config: StepConfig<'_>,
    threads: Option<usize>,
) -> Result<Vec<Vec<FixedRecord>>, EngineError> {
    let n_steps = config.n_steps()?;
    let arrivals: Vec<Vec<u64>> = inputs
        .iter()
        .enumerate()
        .map(|(i, x)| {
            input_steps(
                x,
                config.dt,
                config.start_step,
                n_steps,
                &format!("sample {i}"),
            )
        })
        .collect::<Result<_, _>>()?;
    let arrivals: Vec<Vec<Arrival>> = arrivals.iter().map(|a| group_arrivals(a)).collect();
    let lanes = kernel.lanes();
    let blocks: Vec<&[FixedSpll]> = params.chunks(lanes).collect();
    // The start states of sample `i`'s block `b` (empty: from rest).
    let start = |i: usize, b: usize| -> &[FixedState] {
        config
            .starts
            .get(i)
            .map_or(&[], |s| &s[b * lanes..(b * lanes + lanes).min(s.len())])
    };
    let run = |arrivals| BlockRun {
        format,
        arrivals,
        start_step: config.start_step,
        n_steps,
        dt: config.dt,
        keep_spikes: config.keep_spikes,
        cancel: config.cancel,
    };
    let block_steps = (n_steps - config.start_step).saturating_mul(blocks.len() as u64);
    let work = || -> Vec<Vec<FixedRecord>> {
        if arrivals.len() == 1 && block_steps < PARALLEL_BLOCK_STEPS {
            let run = run(arrivals[0].as_slice());
            let parts = blocks.iter().enumerate();
            vec![parts
                .flat_map(|(b, block)| kernel.run(block, start(0, b), &run))
                .collect()]
        } else if arrivals.len() == 1 {
            let run = run(arrivals[0].as_slice());
            let parts: Vec<Vec<FixedRecord>> = blocks
                .par_iter()
                .enumerate()
                .map(|(b, block)| kernel.run(block, start(0, b), &run))
                .collect();
            vec![parts.concat()]
        } else {
            arrivals
                .par_iter()
                .enumerate()
                .map(|(i, a)| {
                    let run = run(a.as_slice());
                    blocks
                        .iter()
                        .enumerate()
                        .flat_map(|(b, block)| kernel.run(block, start(i, b), &run))
                        .collect()
                })
                .collect()
        }
    };
    let records = threads::install(threads, work)?;
    // A cancelled block stops early: its records are incomplete.
    config.cancel.check()?;
    Ok(records)
}

#[cfg(test)]
mod tests;
