//! The time-step loop of the fixed-point reference over a block of sPLLs, one per lane.
//!
//! The sPLLs of a network only share their input, so a block of `N` of them steps as `N`
//! independent lanes ([`Lanes`]). The per-step work every lane needs (decays, membranes,
//! spike tests) is branch-free; what only some steps need runs behind one test per step for
//! the whole block:
//!
//! * input spikes (shared by every lane) add to `f`, and only then can `f` saturate;
//! * a CCO spike of the previous step opens the trigger gate, and only then can `g` saturate;
//! * a TDE spike of the previous step kicks `u`, and only then can `u` saturate;
//! * a membrane saturates only when its sum exceeds the largest state value, which is above
//!   its threshold, so only on steps when it spikes (it is reset to 0 then, so the clip itself
//!   changes nothing but the counter).
//!
//! (`decay(x) <= x`, so a variable with no increment never saturates.) A refractory counter is
//! kept as the last step it holds the membrane, `last = k_spike + refr`: the membrane steps
//! at `k` iff `k > last`, and `refr_left = max(0, last − k)` after step `k`. When every sPLL of
//! a block has the same facilitatory constants (as in a quantized network), their `f`, driven
//! by the shared input alone, is one scalar.
//!
//! The step loop ([`advance`]) makes no calls, so its state stays in registers: it writes the
//! steps with spikes to a small buffer and returns when it is full, and [`run_block`] counts
//! and records them. A block is sixteen sPLLs on AVX-512 (two registers, two dependency chains
//! for the CPU to overlap; eight for the last block when no more are left), eight on AVX2 (two
//! registers of four) and one on the scalar fallback; [`dispatch`] picks the implementation
//! and holds the copies of the loop compiled for each instruction set.

use super::lanes::{Lanes, Scalar};
use super::{FixedFormat, FixedRecord, FixedSpll, FixedState};
use crate::cancel::Cancel;

mod dispatch;

pub(super) use dispatch::Kernel;

/// Lanes of the widest implementation.
pub(super) const MAX_LANES: usize = 16;

/// Input spikes arriving at one step: `count` of them at step `step`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Arrival {
    pub step: u64,
    pub count: u64,
}

/// Group sorted arrival steps (repeats are several spikes in one step).
pub(super) fn group_arrivals(steps: &[u64]) -> Vec<Arrival> {
    let mut out: Vec<Arrival> = Vec::new();
    for &step in steps {
        match out.last_mut() {
            Some(a) if a.step == step => a.count += 1,
            _ => out.push(Arrival { step, count: 1 }),
        }
    }
    out
}

/// What every block of one sample shares.
#[derive(Clone, Copy, Debug)]
pub(super) struct BlockRun<'a> {
    pub format: &'a FixedFormat,
    /// Input spikes, by step, sorted, every step in `start_step + 1 ..= n_steps`.
    pub arrivals: &'a [Arrival],
    /// The step the start states were saved after (0: from rest).
    pub start_step: u64,
    pub n_steps: u64,
    /// Time step [s].
    pub dt: f64,
    pub keep_spikes: bool,
    /// Polled every [`CANCEL_POLL`] steps: once raised, the block stops where it is.
    pub cancel: &'a Cancel,
}

/// Steps between two polls of the cancel flag (well under a millisecond for a block).
pub(super) const CANCEL_POLL: u64 = 1 << 16;

/// One value of every item of `items` (the sPLLs of a block, or their start states) in lanes
/// (0 in lanes past its end).
#[inline(always)]
fn column<V: Lanes, T>(items: &[T], get: impl Fn(&T) -> i64) -> V {
    let mut a = [0u64; MAX_LANES];
    for (slot, item) in a.iter_mut().zip(items) {
        // Validated parameters and states are non-negative.
        *slot = get(item) as u64;
    }
    V::load(&a)
}

/// Constants of one membrane.
#[derive(Clone, Copy)]
struct Membrane<V: Lanes> {
    /// `2^D − δ`.
    keep: V::Keep,
    threshold: V,
    refr: V,
}

/// One membrane step in every lane (module docs of `fixed_point`): lanes past their
/// refractory period (`k > last`) set `v ← decay(v) + drive` and spike if `v > θ`, which
/// resets `v` to 0. Returns the unclipped sum (0 in refractory lanes) and the spiking lanes;
/// the caller counts saturations (`sum > max`, always a spiking lane) and restarts `last`.
#[inline(always)]
fn membrane_step<V: Lanes>(m: &Membrane<V>, v: &mut V, last: V, k: V, drive: V) -> (V, V::Mask) {
    let sum = v.decay_add_or_zero(m.keep, drive, k.gt(last));
    let spike = sum.gt(m.threshold);
    *v = sum.zero_if(spike);
    (sum, spike)
}

/// First step at which a CCO fires from rest with a constant drive `bias >> cco_current_shift`
/// (no synaptic current), through the same [`membrane_step`] as the full run; `None` if it
/// does not fire within `max_steps` steps, or once `cancel` is raised.
pub(super) fn first_free_spike(
    p: &FixedSpll,
    format: &FixedFormat,
    max_steps: u64,
    cancel: &Cancel,
) -> Option<u64> {
    let block = std::slice::from_ref(p);
    let m = Membrane::<Scalar> {
        keep: Scalar::keep(
            column(block, |p| format.decay_unity() - p.cco_decay),
            format.decay_bits,
        ),
        threshold: column(block, |p| p.cco_threshold),
        refr: column(block, |p| p.cco_refr),
    };
    let drive =
        column::<Scalar, _>(block, |p| p.cco_bias).shr(column(block, |p| p.cco_current_shift));
    let last = Scalar::splat(0);
    let (mut v, mut previous) = (Scalar::splat(0), [0u64]);
    for k in 1..=max_steps {
        let (_, spike) = membrane_step(&m, &mut v, last, Scalar::splat(k), drive);
        if spike {
            return Some(k);
        }
        // From rest the potential never falls (the step is monotone in v and v_1 >= v_0), so
        // once it stops rising below the threshold it never fires.
        let mut now = [0u64];
        v.store(&mut now);
        if now == previous {
            return None;
        }
        previous = now;
        if k.is_multiple_of(CANCEL_POLL) && cancel.requested() {
            return None;
        }
    }
    None
}

/// Constants of a block, in lanes.
#[derive(Clone, Copy)]
struct Constants<V: Lanes> {
    max: V,
    /// The facilitatory constants, when every sPLL of the block has the same: then `f`,
    /// driven by the shared input alone, is the same in every lane and steps as one scalar.
    shared_fac: Option<SharedFac>,
    keep_f: V::Keep,
    keep_g: V::Keep,
    keep_u: V::Keep,
    fac_weight: V,
    trg_mantissa: V,
    trg_shift: V,
    tde_shift: V,
    /// Some `tde_current_shift` is non-zero (otherwise the shift is skipped).
    tde_shifted: bool,
    cco_weight: V,
    cco_bias: V,
    cco_shift: V,
    /// Some `cco_current_shift` is non-zero.
    cco_shifted: bool,
    tde: Membrane<V>,
    cco: Membrane<V>,
}

impl<V: Lanes> Constants<V> {
    /// The constants of `block`; `f_shared` says whether its lanes start with one `f` (always
    /// so from rest), which sharing the facilitatory constants needs as well.
    #[inline(always)]
    fn new(block: &[FixedSpll], format: &FixedFormat, f_shared: bool) -> Self {
        let unity = format.decay_unity();
        let keep = |get: fn(&FixedSpll) -> i64| {
            V::keep(column(block, |p| unity - get(p)), format.decay_bits)
        };
        let first = &block[0];
        let shared = f_shared
            && block
                .iter()
                .all(|p| (p.fac_decay, p.fac_weight) == (first.fac_decay, first.fac_weight));
        Constants {
            max: V::splat(format.state_max() as u64),
            shared_fac: shared.then_some(SharedFac {
                keep: (unity - first.fac_decay) as u64,
                bits: format.decay_bits,
                weight: first.fac_weight as u64,
                max: format.state_max() as u64,
            }),
            keep_f: keep(|p| p.fac_decay),
            keep_g: keep(|p| p.trg_decay),
            keep_u: keep(|p| p.cco_syn_decay),
            fac_weight: column(block, |p| p.fac_weight),
            trg_mantissa: column(block, |p| p.trg_mantissa),
            trg_shift: column(block, |p| p.trg_shift),
            tde_shift: column(block, |p| p.tde_current_shift),
            tde_shifted: block.iter().any(|p| p.tde_current_shift > 0),
            cco_weight: column(block, |p| p.cco_weight),
            cco_bias: column(block, |p| p.cco_bias),
            cco_shift: column(block, |p| p.cco_current_shift),
            cco_shifted: block.iter().any(|p| p.cco_current_shift > 0),
            tde: Membrane {
                keep: keep(|p| p.tde_decay),
                threshold: column(block, |p| p.tde_threshold),
                refr: column(block, |p| p.tde_refr),
            },
            cco: Membrane {
                keep: keep(|p| p.cco_decay),
                threshold: column(block, |p| p.cco_threshold),
                refr: column(block, |p| p.cco_refr),
            },
        }
    }
}

/// Facilitatory constants shared by a block: `keep = 2^D − fac_decay`, `D`, `fac_weight`, and
/// the largest state value.
#[derive(Clone, Copy)]
struct SharedFac {
    keep: u64,
    bits: u32,
    weight: u64,
    max: u64,
}

/// State of a block after a step (`last_*`: last refractory step, module docs).
#[derive(Clone, Copy)]
struct State<V: Lanes> {
    f: V,
    g: V,
    v_tde: V,
    last_tde: V,
    u: V,
    v_cco: V,
    last_cco: V,
    tde_fired: V::Mask,
    cco_fired: V::Mask,
}

/// Saturation counters of each lane ([`super::N_SATURATION`] order). They change on few steps,
/// so they live in memory rather than in registers the step loop needs.
type Saturations = [[u64; MAX_LANES]; super::N_SATURATION];

/// Count one saturation of `counter` in every lane set in `bits`.
#[inline(always)]
fn bump(counter: &mut [u64; MAX_LANES], mut bits: u32) {
    while bits != 0 {
        counter[bits.trailing_zeros() as usize] += 1;
        bits &= bits - 1;
    }
}

/// The lanes that spiked at one step.
#[derive(Clone, Copy, Debug, Default)]
struct Spikes {
    step: u64,
    tde: u32,
    cco: u32,
}

/// Steps the inner loop runs at most between two visits of the caller's bookkeeping.
pub(super) const SPIKE_BUFFER: usize = 64;

/// Where the run of a block stands between two calls of [`advance`].
struct Progress<V: Lanes> {
    state: State<V>,
    sat: Saturations,
    /// The next step to run.
    k: u64,
    /// Index of the next input arrival in [`BlockRun::arrivals`].
    next: usize,
}

/// Run steps `p.k, p.k + 1, …` up to `run.n_steps`, at most [`CANCEL_POLL`] of them, or until
/// `spikes` is full; the steps with a spike are written to `spikes`. Returns how many were
/// written. No calls: the state stays in registers.
#[inline(always)]
fn advance<V: Lanes>(
    c: &Constants<V>,
    p: &mut Progress<V>,
    run: &BlockRun<'_>,
    spikes: &mut [Spikes; SPIKE_BUFFER],
) -> usize {
    let (arrivals, n_steps, sat) = (run.arrivals, run.n_steps, &mut p.sat);
    let (mut k, mut next) = (p.k, p.next);
    let Constants {
        max,
        shared_fac,
        keep_f,
        keep_g,
        keep_u,
        fac_weight,
        trg_mantissa,
        trg_shift,
        tde_shift,
        tde_shifted,
        cco_weight,
        cco_bias,
        cco_shift,
        cco_shifted,
        tde,
        cco,
    } = *c;
    let State {
        mut f,
        mut g,
        mut v_tde,
        mut last_tde,
        mut u,
        mut v_cco,
        mut last_cco,
        mut tde_fired,
        mut cco_fired,
    } = p.state;
    // With shared facilitatory constants `f` is `f_shared` in every lane (and `f` is only
    // brought up to date when the loop ends).
    let mut f_shared = {
        let mut lanes = [0; MAX_LANES];
        f.store(&mut lanes);
        lanes[0]
    };
    let mut written = 0;
    let mut next_input = arrivals.get(next).map_or(u64::MAX, |a| a.step);
    let last = n_steps.min(k + (CANCEL_POLL - 1));
    while k <= last {
        let kv = V::splat(k);
        // 1. TDE synapses; the trigger reads the facilitatory current before this step.
        g = g.decay(keep_g);
        if V::bits(cco_fired) != 0 {
            let f_now = if shared_fac.is_some() {
                V::splat(f_shared)
            } else {
                f
            };
            let gate = f_now.mul32(trg_mantissa).shr(trg_shift);
            g = g.add(gate.zero_unless(cco_fired));
            bump(&mut sat[1], V::bits(g.gt(max)));
            g = g.min(max);
        }
        let mut input = 0;
        if k == next_input {
            // More than 2^31 spikes fill any word as surely as their exact number would.
            input = arrivals[next].count.min(1 << 31);
            next += 1;
            next_input = arrivals.get(next).map_or(u64::MAX, |a| a.step);
        }
        if let Some(fac) = shared_fac {
            f_shared = (f_shared * fac.keep) >> fac.bits;
            if input > 0 {
                f_shared += input * fac.weight;
                if f_shared > fac.max {
                    bump(&mut sat[0], (1 << V::N) - 1);
                    f_shared = fac.max;
                }
            }
        } else {
            f = f.decay(keep_f);
            if input > 0 {
                f = f.add(V::splat(input).mul32(fac_weight));
                bump(&mut sat[0], V::bits(f.gt(max)));
                f = f.min(max);
            }
        }
        // 2. TDE membrane.
        let mut drive = g;
        if tde_shifted {
            drive = drive.shr(tde_shift);
        }
        let (sum_tde, tde_spike) = membrane_step(&tde, &mut v_tde, last_tde, kv, drive);
        // 3. CCO synapse, fed by the TDE spike of the previous step.
        u = u.decay(keep_u);
        if V::bits(tde_fired) != 0 {
            u = u.add(cco_weight.zero_unless(tde_fired));
            bump(&mut sat[3], V::bits(u.gt(max)));
            u = u.min(max);
        }
        // 4. CCO membrane.
        let mut drive = u.add(cco_bias);
        if cco_shifted {
            drive = drive.shr(cco_shift);
        }
        let (sum_cco, cco_spike) = membrane_step(&cco, &mut v_cco, last_cco, kv, drive);
        (tde_fired, cco_fired) = (tde_spike, cco_spike);
        k += 1;
        if V::bits(tde_spike) | V::bits(cco_spike) != 0 {
            bump(&mut sat[2], V::bits(sum_tde.gt(max)));
            bump(&mut sat[4], V::bits(sum_cco.gt(max)));
            last_tde = last_tde.replace(tde_spike, kv.add(tde.refr));
            last_cco = last_cco.replace(cco_spike, kv.add(cco.refr));
            spikes[written] = Spikes {
                step: k - 1,
                tde: V::bits(tde_spike),
                cco: V::bits(cco_spike),
            };
            written += 1;
            if written == SPIKE_BUFFER {
                break;
            }
        }
    }
    if shared_fac.is_some() {
        f = V::splat(f_shared);
    }
    p.state = State {
        f,
        g,
        v_tde,
        last_tde,
        u,
        v_cco,
        last_cco,
        tde_fired,
        cco_fired,
    };
    (p.k, p.next) = (k, next);
    written
}

/// The block's state in lanes from the states `start` saved after step `start_step` (lanes
/// past its end, and every lane when `start` is empty, at rest).
#[inline(always)]
fn start_state<V: Lanes>(start: &[FixedState], start_step: u64) -> State<V> {
    let lanes = |get: fn(&FixedState) -> i64| -> V { column(start, get) };
    let zero = V::splat(0);
    let step = V::splat(start_step);
    State {
        f: lanes(|s| s.fac),
        g: lanes(|s| s.trg),
        v_tde: lanes(|s| s.v_tde),
        last_tde: step.add(lanes(|s| s.tde_refr_left)),
        u: lanes(|s| s.u_cco),
        v_cco: lanes(|s| s.v_cco),
        last_cco: step.add(lanes(|s| s.cco_refr_left)),
        tde_fired: lanes(|s| i64::from(s.tde_fired)).gt(zero),
        cco_fired: lanes(|s| i64::from(s.cco_fired)).gt(zero),
    }
}

/// Run `block` (at most `V::N` sPLLs) from `start`; see [`Kernel::run`].
#[inline(always)]
fn run_block<V: Lanes>(
    block: &[FixedSpll],
    start: &[FixedState],
    run: &BlockRun<'_>,
    mut advance: impl FnMut(&Constants<V>, &mut Progress<V>, &mut [Spikes; SPIKE_BUFFER]) -> usize,
) -> Vec<FixedRecord> {
    assert!(!block.is_empty() && block.len() <= V::N);
    assert!(start.is_empty() || start.len() == block.len());
    let f_shared = start.iter().all(|s| s.fac == start[0].fac);
    let c = Constants::<V>::new(block, run.format, f_shared);
    let mut p = Progress {
        state: start_state(start, run.start_step),
        sat: [[0; MAX_LANES]; super::N_SATURATION],
        k: run.start_step + 1,
        next: 0,
    };
    let mut records = vec![FixedRecord::default(); block.len()];
    let mut spikes = [Spikes::default(); SPIKE_BUFFER];
    while p.k <= run.n_steps && !run.cancel.requested() {
        let written = advance(&c, &mut p, &mut spikes);
        for s in &spikes[..written] {
            let time = s.step as f64 * run.dt;
            record(&mut records, s.tde, time, run.keep_spikes, |r| {
                (&mut r.tde_count, &mut r.tde_spikes)
            });
            record(&mut records, s.cco, time, run.keep_spikes, |r| {
                (&mut r.cco_count, &mut r.cco_spikes)
            });
        }
    }
    let lanes = |x: V| {
        let mut a = [0u64; MAX_LANES];
        x.store(&mut a);
        a
    };
    let s = p.state;
    let [f, g, v_tde, last_tde, u, v_cco, last_cco] =
        [s.f, s.g, s.v_tde, s.last_tde, s.u, s.v_cco, s.last_cco].map(lanes);
    let (tde_fired, cco_fired) = (V::bits(s.tde_fired), V::bits(s.cco_fired));
    for (l, r) in records.iter_mut().enumerate() {
        r.saturations = p.sat.map(|s| s[l]);
        // Every state value is at most the largest state word (< 2^31).
        r.state = FixedState {
            fac: f[l] as i64,
            trg: g[l] as i64,
            v_tde: v_tde[l] as i64,
            tde_refr_left: last_tde[l].saturating_sub(run.n_steps) as i64,
            u_cco: u[l] as i64,
            v_cco: v_cco[l] as i64,
            cco_refr_left: last_cco[l].saturating_sub(run.n_steps) as i64,
            tde_fired: tde_fired >> l & 1 == 1,
            cco_fired: cco_fired >> l & 1 == 1,
        };
    }
    records
}

/// Count a spike at `time` [s] (and keep it, with `keep`) in the spike counter and list that
/// `which` picks of every record whose lane is set in `lanes`.
#[inline(always)]
fn record(
    records: &mut [FixedRecord],
    mut lanes: u32,
    time: f64,
    keep: bool,
    which: impl Fn(&mut FixedRecord) -> (&mut u64, &mut Vec<f64>),
) {
    while lanes != 0 {
        let l = lanes.trailing_zeros() as usize;
        lanes &= lanes - 1;
        // Lanes past the block's sPLLs never spike (all their parameters are 0).
        if let Some(r) = records.get_mut(l) {
            let (count, times) = which(r);
            *count += 1;
            if keep {
                times.push(time);
            }
        }
    }
}
