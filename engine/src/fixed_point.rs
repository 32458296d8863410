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
mod tests {
    use super::reference::{decay, reference_run};
    use super::*;

    const DT: f64 = 1e-4;

    fn format() -> FixedFormat {
        FixedFormat::new(24, 12).unwrap()
    }

    /// A row with no decays, no refractory periods, silent TDE (threshold at the maximum),
    /// with the named parameters changed.
    fn row(changes: &[(&str, i64)]) -> [i64; N_FIXED_PARAMS] {
        let mut r = [0; N_FIXED_PARAMS];
        let mut set = |name: &str, value: i64| {
            let k = FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap();
            r[k] = value;
        };
        set("cco_threshold", 1000);
        set("tde_threshold", format().state_max() - 1);
        for &(name, value) in changes {
            set(name, value);
        }
        r
    }

    fn spll(row: [i64; N_FIXED_PARAMS]) -> FixedSpll {
        FixedSpll::from_row(&row, 0, &format()).unwrap()
    }

    fn config(duration: f64) -> StepConfig<'static> {
        StepConfig {
            dt: DT,
            duration,
            start_step: 0,
            starts: &[],
            keep_spikes: true,
            max_steps: MAX_STEPS,
            cancel: &NEVER,
        }
    }

    fn run(row: [i64; N_FIXED_PARAMS], inputs: &[f64], steps: u64) -> FixedRecord {
        let out = simulate_fixed(
            &[spll(row)],
            &format(),
            &[inputs],
            config(steps as f64 * DT),
            Some(1),
        )
        .unwrap();
        out.into_iter().next().unwrap().into_iter().next().unwrap()
    }

    #[test]
    fn a_spike_on_a_step_end_arrives_in_that_step() {
        // 0.49 ms / 10 us = 49.00000000000001 in floating point: still step 49.
        let dt = 1e-5;
        for k in 1..20_000u64 {
            let t = k as f64 * dt;
            assert_eq!(spike_step(t, dt), k, "t = {t:e}");
            assert_eq!(spike_step(f64::from_bits(t.to_bits() + 1), dt), k);
            assert_eq!(spike_step((k as f64 - 0.5) * dt, dt), k);
            assert_eq!(spike_step((k as f64 + 1e-6) * dt, dt), k + 1);
        }
        assert_eq!(spike_step(0.0, dt), 1);
    }

    #[test]
    fn decay_is_multiply_and_truncating_shift() {
        assert_eq!(decay(1000, 4096 - 2048, 12), 500);
        assert_eq!(decay(1001, 4096 - 2048, 12), 500);
        assert_eq!(decay(7, 4095, 12), 6, "(7 * 4095) >> 12 = 6.998 truncated");
        assert_eq!(decay(5, 4096, 12), 5, "delta 0: no decay");
        assert_eq!(decay(5, 0, 12), 0, "delta 2^D: cleared in one step");
    }

    #[test]
    fn free_running_cco_without_leak_has_the_closed_form_period() {
        // v_j = j * bias exceeds the threshold first at j = floor(theta / bias) + 1, then the
        // refractory period holds it R steps: period R + floor(theta/bias) + 1 steps.
        let r = row(&[("cco_bias", 70), ("cco_refr", 9), ("cco_threshold", 1000)]);
        let rec = run(r, &[], 500);
        let first = 1000 / 70 + 1;
        let period = 9 + first;
        let expected: Vec<f64> = (0..)
            .map(|j| (first + j * period) as f64 * DT)
            .take_while(|&t| t <= 500.0 * DT + 1e-12)
            .collect();
        assert_eq!(rec.cco_spikes.len(), expected.len());
        for (got, want) in rec.cco_spikes.iter().zip(&expected) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        assert_eq!(rec.tde_count, 0);
        assert_eq!(rec.state.fac, 0);
    }

    #[test]
    fn threshold_is_strict() {
        // v reaches exactly 1000 at step 10 (no spike), 1100 at step 11 (spike).
        let rec = run(row(&[("cco_bias", 100)]), &[], 11);
        assert_eq!(rec.cco_spikes, vec![11.0 * DT]);
    }

    /// The CCO fires at step 1 (bias above threshold) and then stays refractory; the TDE's
    /// facilitatory weight is 1000 and its trigger weight 3 >> 1.
    fn gated(changes: &[(&str, i64)]) -> [i64; N_FIXED_PARAMS] {
        let mut r = row(&[
            ("cco_bias", 2000),
            ("cco_refr", 1000),
            ("fac_weight", 1000),
            ("trg_mantissa", 3),
            ("trg_shift", 1),
        ]);
        for &(name, value) in changes {
            r[FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap()] = value;
        }
        r
    }

    #[test]
    fn trigger_gates_with_the_facilitatory_current_of_the_previous_step() {
        // One input during step 1. Step 1: f = 1000, CCO fires. Step 2: g += (1000*3)>>1 = 1500,
        // v_tde = 1500. Step 3: v_tde = 3000 (no decays anywhere).
        let rec = run(gated(&[]), &[0.5 * DT], 3);
        assert_eq!(rec.cco_count, 1);
        assert_eq!(
            (rec.state.fac, rec.state.trg, rec.state.v_tde),
            (1000, 1500, 3000)
        );
        // Without the input the gate is closed.
        let rec = run(gated(&[]), &[], 3);
        assert_eq!((rec.state.trg, rec.state.v_tde), (0, 0));
    }

    #[test]
    fn current_shift_gives_the_membrane_the_integer_part() {
        // g = 1500 with 4 fractional bits: the membrane adds 1500 >> 4 = 93 per step.
        let rec = run(gated(&[("tde_current_shift", 4)]), &[0.5 * DT], 3);
        assert_eq!((rec.state.trg, rec.state.v_tde), (1500, 186));
    }

    #[test]
    fn spikes_are_delivered_one_step_later() {
        // The TDE fires as soon as the trigger current arrives (step 2); its spike reaches the
        // CCO synapse at step 3.
        let r = gated(&[
            ("cco_weight", 77),
            ("trg_shift", 0),
            ("trg_mantissa", 1),
            ("tde_threshold", 10),
            ("tde_refr", 1000),
        ]);
        let at2 = run(r, &[0.5 * DT], 2);
        assert_eq!(at2.tde_spikes, vec![2.0 * DT]);
        assert_eq!(
            at2.state.u_cco, 0,
            "the TDE spike has not reached the CCO yet"
        );
        assert!(at2.state.tde_fired);
        let at3 = run(r, &[0.5 * DT], 3);
        assert_eq!(at3.state.u_cco, 77);
    }

    #[test]
    fn refractory_holds_the_potential_while_currents_evolve() {
        let r = row(&[("cco_syn_decay", 2048), ("cco_bias", 2000), ("cco_refr", 3)]);
        let rec = run(r, &[], 3);
        // Spike at step 1, refractory for steps 2..4.
        assert_eq!(rec.cco_spikes, vec![DT]);
        assert_eq!((rec.state.v_cco, rec.state.cco_refr_left), (0, 1));
        let rec = run(r, &[], 5);
        assert_eq!(rec.cco_spikes, vec![DT, 5.0 * DT]);
    }

    #[test]
    fn saturation_clips_and_counts() {
        let max = format().state_max();
        // One input fills the facilitatory current.
        let rec = run(
            row(&[("fac_weight", max)]),
            &[0.1 * DT, 0.2 * DT, 1.5 * DT],
            2,
        );
        assert_eq!(rec.state.fac, max);
        assert_eq!(rec.saturations, [2, 0, 0, 0, 0]);
    }

    #[test]
    fn inputs_arrive_in_the_step_they_happen_in() {
        let steps =
            input_steps(&[0.0, 0.5 * DT, DT, 1.5 * DT, 2.0 * DT, 9.0], DT, 0, 3, "x").unwrap();
        assert_eq!(steps, vec![1, 1, 1, 2, 2]);
    }

    #[test]
    fn batch_equals_one_by_one_and_does_not_depend_on_threads() {
        let params = lively_network();
        let trains: Vec<Vec<f64>> = (0..4)
            .map(|s| {
                (0..300)
                    .map(|j| (j as f64 * 0.0031 + s as f64 * 1e-4) % 1.0)
                    .collect()
            })
            .map(|mut v: Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v
            })
            .collect();
        let views: Vec<&[f64]> = trains.iter().map(Vec::as_slice).collect();
        let cfg = config(1.0);
        let batch = simulate_fixed(&params, &format(), &views, cfg, Some(2)).unwrap();
        let serial = simulate_fixed(&params, &format(), &views, cfg, Some(1)).unwrap();
        assert_eq!(batch, serial);
        for (i, v) in views.iter().enumerate() {
            let alone = simulate_fixed(&params, &format(), &[v], cfg, None).unwrap();
            assert_eq!(alone[0], batch[i]);
        }
        assert!(batch[0].iter().all(|r| r.tde_count > 0 && r.cco_count > 0));
    }

    /// The batch test's network: both neurons of both sPLLs spike, and their currents decay.
    fn lively_network() -> Vec<FixedSpll> {
        let base = [
            ("cco_syn_decay", 300),
            ("cco_decay", 5),
            ("cco_weight", 400),
            ("cco_current_shift", 1),
            ("cco_bias", 180),
            ("cco_refr", 10),
            ("cco_threshold", 20_000),
            ("fac_decay", 40),
            ("trg_decay", 200),
            ("tde_decay", 90),
            ("fac_weight", 1 << 17),
            ("trg_mantissa", 107),
            ("trg_shift", 10),
            ("tde_current_shift", 1),
            ("tde_refr", 10),
            ("tde_threshold", 50_000),
        ];
        let mut other = base;
        other[4].1 = 260;
        vec![spll(row(&base)), spll(row(&other))]
    }

    #[test]
    fn runs_over_several_cancel_polls_equal_the_reference() {
        // The step loop stops every CANCEL_POLL steps to poll the cancel flag; with a high CCO
        // threshold a block spikes on fewer steps than fill the spike buffer between two polls,
        // so it stops at the polls.
        let n_steps = 3 * kernel::CANCEL_POLL + 17;
        let params = [FixedSpll {
            cco_threshold: 70_000,
            ..lively_network()[0]
        }];
        let inputs: Vec<f64> = (0..400).map(|j| j as f64 * 0.049).collect();
        let cfg = config(n_steps as f64 * DT);
        let arrivals = input_steps(&inputs, DT, 0, n_steps, "x").unwrap();
        let expected: Vec<FixedRecord> = params
            .iter()
            .map(|p| reference_run(p, &format(), &arrivals, n_steps, DT, true))
            .collect();
        assert!(expected.iter().all(|r| r.tde_count > 0));
        let spikes: u64 = expected.iter().map(|r| r.tde_count + r.cco_count).sum();
        assert!(spikes < 3 * kernel::SPIKE_BUFFER as u64, "{spikes} spikes");
        for kernel in Kernel::available() {
            let got = simulate_with(kernel, &params, &format(), &[&inputs], cfg, Some(1));
            assert_eq!(got.unwrap()[0], expected, "{kernel:?}");
        }
    }

    #[test]
    fn a_raised_cancel_stops_a_run_within_milliseconds() {
        let params = lively_network();
        let cancel = Cancel::new();
        // A billion steps: minutes of work.
        let cfg = StepConfig {
            cancel: &cancel,
            ..config(MAX_STEPS as f64 * DT)
        };
        let start = std::time::Instant::now();
        let result = std::thread::scope(|scope| {
            scope.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(50));
                cancel.request();
            });
            simulate_fixed(&params, &format(), &[&[0.1]], cfg, Some(1))
        });
        assert_eq!(result.unwrap_err().0, crate::cancel::CANCELLED);
        assert!(start.elapsed().as_secs_f64() < 1.0, "{:?}", start.elapsed());
        let periods = cco_free_periods(&params, &format(), MAX_STEPS, &cancel);
        assert_eq!(periods.unwrap_err().0, crate::cancel::CANCELLED);
    }

    #[test]
    fn bad_input_is_an_error_naming_the_problem() {
        fn err<T>(r: Result<T, EngineError>) -> String {
            r.map(|_| ()).unwrap_err().0
        }
        let f = format();
        let bad = |name: &str, value: i64| err(FixedSpll::from_row(&row(&[(name, value)]), 3, &f));
        assert!(FixedFormat::new(33, 12)
            .unwrap_err()
            .0
            .contains("state_bits"));
        assert!(FixedFormat::new(24, 0)
            .unwrap_err()
            .0
            .contains("decay_bits"));
        assert!(bad("cco_decay", 4097).contains("sPLL 3: fixed-point parameter cco_decay"));
        assert!(bad("fac_weight", -1).contains("fac_weight"));
        assert!(bad("tde_threshold", f.state_max()).contains("tde_threshold"));
        assert!(bad("trg_shift", 63).contains("trg_shift"));
        assert!(bad("tde_current_shift", 31).contains("tde_current_shift"));
        assert!(bad("cco_refr", -2).contains("cco_refr"));
        assert!(err(FixedSpll::from_row(&row(&[])[..5], 0, &f)).contains("expected 16"));
        assert!(err(FixedSpll::from_matrix(&[], &f)).contains("shape"));
        let p = [spll(row(&[]))];
        let run_with =
            |inputs: &[f64], cfg: StepConfig| err(simulate_fixed(&p, &f, &[inputs], cfg, None));
        assert!(run_with(&[f64::NAN], config(1.0)).contains("not a finite time"));
        assert!(run_with(&[0.2, 0.1], config(1.0)).contains("sorted"));
        assert!(run_with(&[-0.1], config(1.0)).contains("negative"));
        assert!(run_with(&[], config(0.4 * DT)).contains("shorter than half a time step"));
        assert!(run_with(&[], config(f64::INFINITY)).contains("duration"));
        let mut cfg = config(1.0);
        cfg.dt = 0.0;
        assert!(run_with(&[], cfg).contains("dt"));
        cfg.dt = 1e-10;
        assert!(run_with(&[], cfg).contains("more than the limit"));
        assert!(err(simulate_fixed(&p, &f, &[&[]], config(1.0), Some(0))).contains("threads"));
        assert!(err(simulate_fixed(&[], &f, &[&[]], config(1.0), None)).contains("at least one"));
    }
    /// splitmix64: a small deterministic generator for the random cases below.
    fn next(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A uniform integer in `[low, high]`.
    fn between(state: &mut u64, low: i64, high: i64) -> i64 {
        low + (next(state) % (high - low + 1) as u64) as i64
    }

    /// A random valid row for `format`, drawn to spike, saturate and hit the edge values
    /// (decay constants 0, if `zero_decays`, and `2^D`, zero refractory periods, large shifts)
    /// often.
    fn random_row(
        state: &mut u64,
        format: &FixedFormat,
        zero_decays: bool,
    ) -> [i64; N_FIXED_PARAMS] {
        let max = format.state_max();
        let unity = format.decay_unity();
        let mut r = [0; N_FIXED_PARAMS];
        for (value, name) in r.iter_mut().zip(FIXED_PARAM_NAMES) {
            let scale = between(state, 0, 8) as u32;
            *value = match name {
                "cco_syn_decay" | "cco_decay" | "fac_decay" | "trg_decay" | "tde_decay" => {
                    match between(state, 0, 9) {
                        0 if zero_decays => 0,
                        1 => unity,
                        _ => (between(state, 0, unity) >> scale.min(format.decay_bits)).max(1),
                    }
                }
                "cco_weight" | "cco_bias" | "fac_weight" => between(state, 0, max) >> scale,
                "cco_threshold" | "tde_threshold" => between(state, 0, max - 1) >> scale,
                "trg_mantissa" => between(state, 0, i64::from(i32::MAX)) >> (4 * scale),
                "trg_shift" => between(state, 0, MAX_TRIGGER_SHIFT) >> (scale / 2),
                "cco_current_shift" | "tde_current_shift" => {
                    between(state, 0, i64::from(MAX_CURRENT_SHIFT)) >> (scale / 2)
                }
                _ => between(state, 0, 12),
            };
        }
        r
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        /// Every step-loop implementation this CPU can run (the scalar fallback, AVX-512, AVX-512
        /// with IFMA decays, which only blocks without zero decay constants use) equals the
        /// plain scalar reference on random networks (with or without facilitatory constants
        /// shared by every sPLL, which step as one scalar), formats and inputs, one sample over
        /// sPLLs and a batch over samples.
        #[test]
        fn kernels_equal_the_plain_reference(
            state_bits in 2u32..=MAX_STATE_BITS,
            decay_bits in 1u32..=MAX_DECAY_BITS,
            n_spll in 1usize..=19,
            n_steps in 1u64..=400,
            zero_decays: bool,
            shared_fac: bool,
            seed: u64,
        ) {
            let format = FixedFormat::new(state_bits, decay_bits).unwrap();
            let mut rng = seed;
            let mut rows: Vec<_> =
                (0..n_spll).map(|_| random_row(&mut rng, &format, zero_decays)).collect();
            if shared_fac {
                // Every sPLL with the same facilitatory constants, as in most networks.
                let column = |name| FIXED_PARAM_NAMES.iter().position(|n| *n == name).unwrap();
                for name in ["fac_decay", "fac_weight"] {
                    let k = column(name);
                    let first = rows[0][k];
                    rows.iter_mut().for_each(|r| r[k] = first);
                }
            }
            let params: Vec<FixedSpll> = rows
                .iter()
                .enumerate()
                .map(|(i, row)| FixedSpll::from_row(row, i, &format).unwrap())
                .collect();
            let trains: Vec<Vec<f64>> = (0..2)
                .map(|_| {
                    let n = between(&mut rng, 0, 3 * n_steps as i64);
                    // Few distinct times, so many spikes share a step.
                    let spread = between(&mut rng, 1, n_steps as i64);
                    let mut t: Vec<f64> =
                        (0..n).map(|_| between(&mut rng, 0, spread) as f64 * DT * 0.999).collect();
                    t.sort_by(f64::total_cmp);
                    t
                })
                .collect();
            let views: Vec<&[f64]> = trains.iter().map(Vec::as_slice).collect();
            let cfg = config(n_steps as f64 * DT);
            let expected: Vec<Vec<FixedRecord>> = views
                .iter()
                .map(|x| {
                    let arrivals = input_steps(x, DT, 0, n_steps, "x").unwrap();
                    params
                        .iter()
                        .map(|p| reference_run(p, &format, &arrivals, n_steps, DT, true))
                        .collect()
                })
                .collect();
            for kernel in Kernel::available() {
                let batch =
                    simulate_with(kernel, &params, &format, &views, cfg, Some(2)).unwrap();
                proptest::prop_assert_eq!(&batch, &expected, "{:?}, batch", kernel);
                let one = simulate_with(kernel, &params, &format, &views[..1], cfg, Some(2));
                proptest::prop_assert_eq!(&one.unwrap()[0], &expected[0], "{:?}, one", kernel);
                let pieces = resumed_in_pieces(kernel, &params, &format, &views, n_steps, seed);
                proptest::prop_assert_eq!(&pieces, &expected, "{:?}, resumed", kernel);
            }
        }
    }

    /// The run of `inputs` for `n_steps` steps made of up to four pieces, each resumed from the
    /// last one's final states, with their spikes and saturations joined.
    fn resumed_in_pieces(
        kernel: Kernel,
        params: &[FixedSpll],
        format: &FixedFormat,
        inputs: &[&[f64]],
        n_steps: u64,
        seed: u64,
    ) -> Vec<Vec<FixedRecord>> {
        let mut rng = seed ^ 0x5eed;
        let mut ends: Vec<u64> = (0..3)
            .map(|_| between(&mut rng, 1, n_steps as i64) as u64)
            .collect();
        ends.push(n_steps);
        ends.sort_unstable();
        ends.dedup();
        let mut joined: Vec<Vec<FixedRecord>> =
            vec![vec![FixedRecord::default(); params.len()]; inputs.len()];
        let mut starts: Vec<Vec<FixedState>> = Vec::new();
        let mut begin = 0;
        for end in ends {
            let arrives = |t: &f64| ((t / DT).ceil() as u64).max(1) > begin;
            let pieces: Vec<Vec<f64>> = inputs
                .iter()
                .map(|x| x.iter().copied().filter(arrives).collect())
                .collect();
            let views: Vec<&[f64]> = pieces.iter().map(Vec::as_slice).collect();
            let cfg = StepConfig {
                start_step: begin,
                starts: &starts,
                ..config(end as f64 * DT)
            };
            let out = simulate_with(kernel, params, format, &views, cfg, Some(2)).unwrap();
            for (whole, piece) in joined.iter_mut().zip(&out) {
                for (w, p) in whole.iter_mut().zip(piece) {
                    w.tde_spikes.extend(&p.tde_spikes);
                    w.cco_spikes.extend(&p.cco_spikes);
                    w.tde_count += p.tde_count;
                    w.cco_count += p.cco_count;
                    w.saturations
                        .iter_mut()
                        .zip(p.saturations)
                        .for_each(|(a, b)| *a += b);
                    w.state = p.state;
                }
            }
            starts = out
                .iter()
                .map(|s| s.iter().map(|r| r.state).collect())
                .collect();
            begin = end;
        }
        joined
    }
    #[test]
    fn free_periods_are_the_first_spike_of_an_empty_run_plus_the_refractory_period() {
        let mut rng = 7;
        for case in 0..300 {
            let state_bits = between(&mut rng, 2, i64::from(MAX_STATE_BITS)) as u32;
            let decay_bits = between(&mut rng, 1, i64::from(MAX_DECAY_BITS)) as u32;
            let format = FixedFormat::new(state_bits, decay_bits).unwrap();
            let p = FixedSpll::from_row(&random_row(&mut rng, &format, true), 0, &format).unwrap();
            let max_steps = between(&mut rng, 1, 3000) as u64;
            let empty = reference_run(&p, &format, &[], max_steps, DT, true);
            let expected = empty
                .cco_spikes
                .first()
                .map_or(0, |t| (t / DT).round() as u64 + p.cco_refr as u64);
            let got = cco_free_periods(&[p], &format, max_steps, &NEVER).unwrap();
            assert_eq!(got, vec![expected], "case {case}: {p:?}, {max_steps} steps");
        }
        // A CCO whose potential settles below its threshold never fires.
        let p = spll(row(&[("cco_decay", 2048), ("cco_bias", 400)]));
        assert_eq!(
            cco_free_periods(&[p], &format(), MAX_STEPS, &NEVER).unwrap(),
            vec![0]
        );
        let r = row(&[("cco_bias", 70), ("cco_refr", 9), ("cco_threshold", 1000)]);
        assert_eq!(
            cco_free_periods(&[spll(r)], &format(), 100, &NEVER).unwrap(),
            vec![1000 / 70 + 1 + 9]
        );
        assert_eq!(
            cco_free_periods(&[spll(r)], &format(), 14, &NEVER).unwrap(),
            vec![0]
        );
        assert!(
            cco_free_periods(&[spll(r)], &format(), MAX_STEPS + 1, &NEVER)
                .unwrap_err()
                .0
                .contains("max_steps")
        );
    }
}
