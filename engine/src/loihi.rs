//! Loihi's LIF and Dense arithmetic, step by step: the bit-accurate executor of the standard sPLL
//! on Lava's processes (`mappings.lava.loihi`, whose docstring states the step this follows).
//!
//! Every population is one vector of neurons; every `Dense` between them a sparse matrix held
//! by source column, so a step visits only the neurons that spiked. At step `t` each neuron's
//! `a_in` is the input count of step `t - 1` times its input weight plus the previous step's
//! spikes weighed by the matrices (a matrix with a right shift `s` has its sums shifted by
//! `s`, floor); `u <- decay(u) + (int16(a_in) << 6)`, wrapping at 24 bits;
//! `v <- clip(decay(v) + u + bias, ±(2^23 - 1))`; `v > threshold` is a spike and resets `v`.
//! A graded neuron (a `GradedVec`) sends its whole `a_in` instead of a spike. Samples are
//! independent and run in parallel (rayon).

use rayon::prelude::*;

use crate::cancel::Cancel;
use crate::error::{bail, EngineError};

/// Loihi's `u` and `v` words: 24 bits, `v` clipped to `±(UV_MAX - 1)`.
pub const UV_MAX: i64 = 1 << 23;
/// Fraction bits of a 12-bit decay (`keep / 4096` a step).
pub const DECAY_BITS: u32 = 12;
/// Steps between two polls of the cancel flag.
const POLL_STEPS: usize = 1024;

/// A sparse integer matrix by source column (CSC): the targets and weights of column `j` are
/// `rows[starts[j]..starts[j + 1]]` and `weights[...]`; its sums are shifted right by `shift`.
#[derive(Clone, Debug)]
pub struct Columns {
    pub starts: Vec<usize>,
    pub rows: Vec<usize>,
    pub weights: Vec<i64>,
    pub shift: u32,
}

/// The input `Dense` of a set of neurons whose products are shifted right by `shift`.
#[derive(Clone, Debug)]
pub struct ShiftedInput {
    pub neurons: Vec<usize>,
    pub weights: Vec<i64>,
    pub shift: u32,
}

/// The whole network as one vector of `size` neurons (each vector below has one entry per
/// neuron).
#[derive(Clone, Debug)]
pub struct LoihiNet {
    pub keep_u: Vec<i64>,
    pub keep_v: Vec<i64>,
    pub threshold: Vec<i64>,
    pub bias: Vec<i64>,
    pub graded: Vec<bool>,
    /// Weight of the input count per neuron (the `Dense` from the input with exponent >= 0).
    pub input_weights: Vec<i64>,
    pub input_shifted: Vec<ShiftedInput>,
    pub matrices: Vec<Columns>,
    /// `(neuron, its hold neuron)`: a step both spike counts in `held`.
    pub held_pairs: Vec<(usize, usize)>,
}

/// One sample's run: every neuron's spikes (a graded neuron's steps with a value sent), the
/// steps each held pair spiked together, and with recording each step's spikes (`steps × size`,
/// row-major).
#[derive(Clone, Debug, PartialEq)]
pub struct LoihiRun {
    pub sent: Vec<i64>,
    pub held: Vec<i64>,
    pub raster: Option<Vec<bool>>,
}

impl Columns {
    /// `(target, weight, value sent)` of every synapse from the neurons in `sends`
    /// (`(neuron, value)` pairs).
    fn deliveries<'a>(
        &'a self,
        sends: &'a [(usize, i64)],
    ) -> impl Iterator<Item = (usize, i64, i64)> + 'a {
        sends.iter().flat_map(move |&(j, x)| {
            let span = self.starts[j]..self.starts[j + 1];
            self.rows[span.clone()]
                .iter()
                .zip(&self.weights[span])
                .map(move |(&r, &w)| (r, w, x))
        })
    }
}

impl LoihiNet {
    pub fn size(&self) -> usize {
        self.keep_u.len()
    }

    /// Every index in range and every vector of the network's size, or an error naming what is
    /// not.
    pub fn validate(&self) -> Result<(), EngineError> {
        let size = self.size();
        for (name, len) in [
            ("keep_v", self.keep_v.len()),
            ("threshold", self.threshold.len()),
            ("bias", self.bias.len()),
            ("graded", self.graded.len()),
            ("input_weights", self.input_weights.len()),
        ] {
            if len != size {
                bail!("{name} has {len} entries, the network {size} neurons");
            }
        }
        if let Some(k) = self
            .keep_u
            .iter()
            .chain(&self.keep_v)
            .find(|k| !(0..=1 << DECAY_BITS).contains(*k))
        {
            bail!("a decay keeps {k} / 4096 of a state: outside 0..=4096");
        }
        for (i, m) in self.matrices.iter().enumerate() {
            let nnz = m.rows.len();
            if m.starts.len() != size + 1
                || m.starts.windows(2).any(|w| w[0] > w[1])
                || m.starts.last() != Some(&nnz)
                || m.weights.len() != nnz
            {
                bail!("matrix {i} is not a CSC matrix of {size} columns");
            }
            if m.rows.iter().any(|&r| r >= size) || m.shift > 62 {
                bail!("matrix {i} has a row outside the network's {size} neurons or a shift > 62");
            }
        }
        for (i, s) in self.input_shifted.iter().enumerate() {
            if s.neurons.len() != s.weights.len() || s.neurons.iter().any(|&n| n >= size) {
                bail!("shifted input {i}: neurons and weights differ in length or exceed {size}");
            }
            if s.shift > 62 {
                bail!("shifted input {i}: shift {} > 62", s.shift);
            }
        }
        if self.held_pairs.iter().any(|&(a, b)| a >= size || b >= size) {
            bail!("a held pair names a neuron outside the network's {size}");
        }
        Ok(())
    }
}

/// Loihi's decay: `sgn(x) (|x| keep >> 12)`, truncation toward zero.
#[inline]
fn decay(x: i64, keep: i64) -> i64 {
    let p = x.wrapping_mul(keep);
    (p + ((p >> 63) & ((1 << DECAY_BITS) - 1))) >> DECAY_BITS
}

/// Run every sample: `counts` is the input spike count per step and sample, row-major
/// `(n_steps, batch)` (step `k` is row `k - 1`).
pub fn simulate_loihi(
    net: &LoihiNet,
    counts: &[i64],
    batch: usize,
    record: bool,
    cancel: &Cancel,
) -> Result<Vec<LoihiRun>, EngineError> {
    net.validate()?;
    if batch == 0 {
        return Ok(Vec::new());
    }
    if !counts.len().is_multiple_of(batch) {
        bail!(
            "counts has {} entries, not a whole number of steps of {batch} samples",
            counts.len()
        );
    }
    let n_steps = counts.len() / batch;
    (0..batch)
        .into_par_iter()
        .map(|b| run_sample(net, counts, batch, b, n_steps, record, cancel))
        .collect()
}

fn run_sample(
    net: &LoihiNet,
    counts: &[i64],
    batch: usize,
    b: usize,
    n_steps: usize,
    record: bool,
    cancel: &Cancel,
) -> Result<LoihiRun, EngineError> {
    let size = net.size();
    let (wrap, ceiling) = (UV_MAX - 1, 2 * UV_MAX - 1);
    let (mut u, mut v) = (vec![0i64; size], vec![0i64; size]);
    let mut a_in = vec![0i64; size];
    let mut shifted_sum = vec![0i64; size];
    let mut reached = vec![false; size];
    let mut rows: Vec<usize> = Vec::new();
    let mut sends: Vec<(usize, i64)> = Vec::new(); // the previous step's nonzero sends
    let mut fired = vec![false; size];
    let mut sent = vec![0i64; size];
    let mut held = vec![0i64; net.held_pairs.len()];
    let mut raster = record.then(|| vec![false; n_steps * size]);
    for t in 0..n_steps {
        if t % POLL_STEPS == 0 {
            cancel.check()?;
        }
        let count = if t > 0 {
            counts[(t - 1) * batch + b]
        } else {
            0
        };
        if count != 0 {
            for (a, w) in a_in.iter_mut().zip(&net.input_weights) {
                *a = count.wrapping_mul(*w);
            }
            for s in &net.input_shifted {
                for (&n, &w) in s.neurons.iter().zip(&s.weights) {
                    a_in[n] = a_in[n].wrapping_add(count.wrapping_mul(w) >> s.shift);
                }
            }
        } else {
            a_in.fill(0);
        }
        for m in &net.matrices {
            if m.shift == 0 {
                for (r, w, x) in m.deliveries(&sends) {
                    a_in[r] = a_in[r].wrapping_add(w.wrapping_mul(x));
                }
                continue;
            }
            // A shifted matrix's sums are floored one by one: summed apart on the rows it
            // reaches this step, then shifted into a_in.
            for (r, w, x) in m.deliveries(&sends) {
                if !reached[r] {
                    reached[r] = true;
                    rows.push(r);
                }
                shifted_sum[r] = shifted_sum[r].wrapping_add(w.wrapping_mul(x));
            }
            for r in rows.drain(..) {
                a_in[r] = a_in[r].wrapping_add(shifted_sum[r] >> m.shift);
                shifted_sum[r] = 0;
                reached[r] = false;
            }
        }
        sends.clear();
        for i in 0..size {
            let a = a_in[i] as i16 as i64; // a_in is a 16-bit port
            let ui = (decay(u[i], net.keep_u[i]) + (a << 6) + wrap) & ceiling;
            u[i] = ui - wrap;
            let vi =
                (decay(v[i], net.keep_v[i]) + u[i] + net.bias[i]).clamp(1 - UV_MAX, UV_MAX - 1);
            let spike = vi > net.threshold[i];
            v[i] = if spike { 0 } else { vi };
            if net.graded[i] {
                fired[i] = false;
                if a_in[i] != 0 {
                    sends.push((i, a_in[i]));
                    sent[i] += 1;
                }
            } else {
                fired[i] = spike;
                if spike {
                    sends.push((i, 1));
                    sent[i] += 1;
                }
            }
        }
        for (h, &(n, hold)) in held.iter_mut().zip(&net.held_pairs) {
            *h += i64::from(fired[n] && fired[hold]);
        }
        if let Some(r) = raster.as_mut() {
            r[t * size..(t + 1) * size].copy_from_slice(&fired);
        }
    }
    Ok(LoihiRun { sent, held, raster })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One neuron fed by the input with weight `w`, no decay of `u` (keep 4095 is du = 0).
    fn one_neuron(w: i64, threshold: i64, keep_u: i64, keep_v: i64) -> LoihiNet {
        LoihiNet {
            keep_u: vec![keep_u],
            keep_v: vec![keep_v],
            threshold: vec![threshold],
            bias: vec![0],
            graded: vec![false],
            input_weights: vec![w],
            input_shifted: vec![],
            matrices: vec![],
            held_pairs: vec![],
        }
    }

    #[test]
    fn decay_truncates_toward_zero() {
        assert_eq!(decay(4096, 2048), 2048);
        assert_eq!(decay(3, 2048), 1);
        assert_eq!(decay(-3, 2048), -1);
        assert_eq!(decay(-4096, 4095), -4095);
    }

    #[test]
    fn a_counted_input_arrives_a_step_later_and_charges_the_membrane() {
        // u keeps its charge (keep 4096), v decays to nothing each step (keep 0): v = u.
        let net = one_neuron(2, 100, 1 << DECAY_BITS, 0);
        let counts = [1, 0, 0, 0];
        let run = simulate_loihi(&net, &counts, 1, true, &crate::cancel::NEVER).unwrap();
        // Step 2 receives step 1's count: u = 2 << 6 = 128 > 100 from then on.
        assert_eq!(run[0].raster.as_ref().unwrap(), &[false, true, true, true]);
        assert_eq!(run[0].sent, vec![3]);
    }

    #[test]
    fn u_wraps_at_24_bits_and_the_port_at_16() {
        // 2^15 on a 16-bit port is -2^15: u = -2^21, no spike at threshold 0.
        let net = one_neuron(1 << 15, 0, 0, 0);
        let run = simulate_loihi(&net, &[1, 0], 1, false, &crate::cancel::NEVER).unwrap();
        assert_eq!(run[0].sent, vec![0]);
    }

    #[test]
    fn a_graded_neuron_sends_its_input_and_a_shifted_matrix_floors_its_sum() {
        // Neuron 0 graded (sends the count times 5); neuron 1 receives 5 * 3 >> 1 = 7.
        let mut net = one_neuron(5, 1 << 20, 1 << DECAY_BITS, 0);
        net.keep_u.push(1 << DECAY_BITS);
        net.keep_v.push(0);
        net.threshold.push((7 << 6) - 1);
        net.bias.push(0);
        net.graded = vec![true, false];
        net.input_weights.push(0);
        net.matrices.push(Columns {
            starts: vec![0, 1, 1],
            rows: vec![1],
            weights: vec![3],
            shift: 1,
        });
        let run = simulate_loihi(&net, &[1, 0, 0, 0], 1, true, &crate::cancel::NEVER).unwrap();
        // Step 2: neuron 0 sends 5 (a send, no spike); step 3: neuron 1's u is 7 << 6, above
        // its threshold, and stays there (no decay) at step 4.
        assert_eq!(run[0].sent, vec![1, 2]);
        assert_eq!(
            run[0].raster.as_ref().unwrap(),
            &[false, false, false, false, false, true, false, true]
        );
    }

    #[test]
    fn bad_networks_are_refused() {
        let mut net = one_neuron(1, 1, 4096, 4096);
        net.held_pairs.push((0, 3));
        let err = simulate_loihi(&net, &[0], 1, false, &crate::cancel::NEVER).unwrap_err();
        assert!(err.0.contains("held pair"), "{}", err.0);
        let net = one_neuron(1, 1, 5000, 4096);
        assert!(simulate_loihi(&net, &[0], 1, false, &crate::cancel::NEVER).is_err());
        let net = one_neuron(1, 1, 4096, 4096);
        assert!(simulate_loihi(&net, &[0, 0, 0], 2, false, &crate::cancel::NEVER).is_err());
        assert!(simulate_loihi(&net, &[], 0, false, &crate::cancel::NEVER)
            .unwrap()
            .is_empty());
    }
}
