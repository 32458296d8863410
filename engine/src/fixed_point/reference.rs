//! The plain scalar implementation of the fixed-point reference, one sPLL and one step at a
//! time, as it was before the step loop was vectorised ([`super::kernel`]). Tests only: the
//! kernel must equal it bit for bit.

use super::{FixedFormat, FixedRecord, FixedSpll, FixedState};

/// One step of decay: `(x · keep) >> bits`, `keep = 2^bits − δ` (`x >= 0`).
#[inline]
pub fn decay(x: i64, keep: i64, bits: u32) -> i64 {
    (x * keep) >> bits
}

/// Clip `x` (>= 0) at `max`, counting the clip.
#[inline]
fn saturate(x: i64, max: i64, count: &mut u64) -> i64 {
    if x > max {
        *count += 1;
        max
    } else {
        x
    }
}

/// A membrane's constants for [`Membrane::step`].
struct Membrane {
    keep: i64,
    threshold: i64,
    refr: i64,
}

impl Membrane {
    /// One step of a membrane driven by `drive`; true if it spikes.
    #[inline]
    fn step(
        &self,
        v: &mut i64,
        refr_left: &mut i64,
        drive: i64,
        bits: u32,
        max: i64,
        saturations: &mut u64,
    ) -> bool {
        if *refr_left > 0 {
            *refr_left -= 1;
            return false;
        }
        *v = saturate(decay(*v, self.keep, bits) + drive, max, saturations);
        if *v > self.threshold {
            *v = 0;
            *refr_left = self.refr;
            true
        } else {
            false
        }
    }
}

/// Run one sPLL from rest for steps `1..=n_steps`, with inputs arriving at the sorted steps
/// `arrivals` (each in `1..=n_steps`; repeats are several spikes in one step): the module docs
/// of `fixed_point` followed literally, one sPLL and one step at a time.
pub fn reference_run(
    p: &FixedSpll,
    format: &FixedFormat,
    arrivals: &[u64],
    n_steps: u64,
    dt: f64,
    keep_spikes: bool,
) -> FixedRecord {
    let bits = format.decay_bits;
    let max = format.state_max();
    let unity = format.decay_unity();
    let (keep_fac, keep_trg, keep_cco_syn) = (
        unity - p.fac_decay,
        unity - p.trg_decay,
        unity - p.cco_syn_decay,
    );
    let tde = Membrane {
        keep: unity - p.tde_decay,
        threshold: p.tde_threshold,
        refr: p.tde_refr,
    };
    let cco = Membrane {
        keep: unity - p.cco_decay,
        threshold: p.cco_threshold,
        refr: p.cco_refr,
    };
    let mut s = FixedState::default();
    let mut rec = FixedRecord::default();
    let sat = &mut rec.saturations;
    let mut cursor = 0;
    for k in 1..=n_steps {
        let start = cursor;
        while cursor < arrivals.len() && arrivals[cursor] == k {
            cursor += 1;
        }
        let n_in = (cursor - start) as i64;
        // 1. TDE synapses; the trigger reads the facilitatory current before this step.
        let gate = if s.cco_fired {
            (s.fac * p.trg_mantissa) >> p.trg_shift
        } else {
            0
        };
        let fac_in = n_in.saturating_mul(p.fac_weight);
        s.fac = saturate(
            decay(s.fac, keep_fac, bits).saturating_add(fac_in),
            max,
            &mut sat[0],
        );
        s.trg = saturate(decay(s.trg, keep_trg, bits) + gate, max, &mut sat[1]);
        // 2. TDE membrane.
        let drive = s.trg >> p.tde_current_shift;
        let tde_spike = tde.step(
            &mut s.v_tde,
            &mut s.tde_refr_left,
            drive,
            bits,
            max,
            &mut sat[2],
        );
        // 3. CCO synapse, fed by the TDE spike of the previous step.
        let feedback = if s.tde_fired { p.cco_weight } else { 0 };
        s.u_cco = saturate(
            decay(s.u_cco, keep_cco_syn, bits) + feedback,
            max,
            &mut sat[3],
        );
        // 4. CCO membrane.
        let drive = (s.u_cco + p.cco_bias) >> p.cco_current_shift;
        let cco_spike = cco.step(
            &mut s.v_cco,
            &mut s.cco_refr_left,
            drive,
            bits,
            max,
            &mut sat[4],
        );
        s.tde_fired = tde_spike;
        s.cco_fired = cco_spike;
        if tde_spike {
            rec.tde_count += 1;
            if keep_spikes {
                rec.tde_spikes.push(k as f64 * dt);
            }
        }
        if cco_spike {
            rec.cco_count += 1;
            if keep_spikes {
                rec.cco_spikes.push(k as f64 * dt);
            }
        }
    }
    rec.state = s;
    rec
}
