//! A spiking readout driven by a network's TDE spikes: one non-leaky integrate-and-fire neuron
//! per class, winner-take-all (`spll_hw.multichannel.readout` is the Python reference).
//!
//! Neuron `j`'s membrane is `v_j(t) = Σ_i w_ji N_i(t) + β_j t`: it jumps by `w_ji` at every
//! spike of TDE `i` and rises with slope `β_j` [1/s] between spikes, from 0 at `t = 0`. At a
//! threshold `θ`, the first neuron to reach it decides, at that instant, no earlier than
//! `not_before` (the readout is switched on then: a membrane already above decides at that
//! instant); neurons reaching it at the same instant are ranked by their membrane then (after
//! the jumps of that instant), the lowest index winning a tie. Where none reaches it by the
//! run's end (or `θ = ∞`), the largest membrane at the end decides, the lowest index first.
//!
//! Crossings are exact: between spikes a membrane is a straight line, so a threshold reached
//! along one is reached at `t_prev + (θ − v_prev) / β_j`; one reached by a jump, at the
//! spike. Every membrane value is computed with the same floating-point operations, in the
//! same order, as the Python reference, so the two agree bit for bit: spikes in time order
//! (ties by TDE index, then order within a train), a running sum of the jumps, the value after
//! a spike `sum + t β_j`, before it `after − w_ji`, at the end `after_last + β_j (T − t_last)`.

use std::cmp::Ordering;

use rayon::prelude::*;

use crate::cancel::Cancel;
use crate::error::{bail, EngineError};
use crate::threads;

/// Check `cancel` every this many spikes of a run.
const CANCEL_EVERY: usize = 1 << 16;

/// The readout's weights and bias currents.
#[derive(Clone, Debug)]
pub struct Readout {
    /// Weights by TDE, then class: `jumps[i * classes + j]` = `w_ji` [membrane units per spike].
    jumps: Vec<f64>,
    /// `β_j` [membrane units / s], shape `(classes,)`.
    bias: Vec<f64>,
}

/// One run's decision at one threshold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decision {
    /// Index of the winning class.
    pub label: usize,
    /// When it decided [s]: a spike time of the readout, or the run's end.
    pub time: f64,
    /// A readout neuron reached the threshold (else the largest membrane at the end decided).
    pub fired: bool,
}

impl Readout {
    /// A readout of `bias.len()` classes over `weights.len() / bias.len()` TDEs, from the
    /// row-major `(classes, tdes)` `weights`. Every value must be finite.
    pub fn new(weights: &[f64], bias: &[f64]) -> Result<Self, EngineError> {
        let classes = bias.len();
        if classes == 0 || !weights.len().is_multiple_of(classes) {
            bail!(
                "readout weights must have shape (classes, tdes) with classes = len(bias) >= 1; \
                 got {} weights for {classes} classes",
                weights.len()
            );
        }
        if let Some(j) = bias.iter().position(|b| !b.is_finite()) {
            bail!("readout bias of class {j} is {}, must be finite", bias[j]);
        }
        let tdes = weights.len() / classes;
        if let Some(at) = weights.iter().position(|w| !w.is_finite()) {
            bail!(
                "readout weight of class {} from TDE {} is {}, must be finite",
                at / tdes,
                at % tdes,
                weights[at]
            );
        }
        let mut jumps = vec![0.0; weights.len()];
        for j in 0..classes {
            for i in 0..tdes {
                jumps[i * classes + j] = weights[j * tdes + i];
            }
        }
        Ok(Self {
            jumps,
            bias: bias.to_vec(),
        })
    }

    /// Readout neurons (classes).
    pub fn classes(&self) -> usize {
        self.bias.len()
    }

    /// TDE inputs of every neuron.
    pub fn tdes(&self) -> usize {
        self.jumps.len() / self.bias.len()
    }

    fn jump(&self, tde: usize) -> &[f64] {
        let k = self.classes();
        &self.jumps[tde * k..(tde + 1) * k]
    }

    /// Decisions of one run at every threshold (module docs): `spikes[i]` the spike times [s]
    /// of TDE `i` (spikes after `duration` are ignored), `duration` the run's end [s].
    pub fn decide(
        &self,
        spikes: &[&[f64]],
        duration: f64,
        thresholds: &[f64],
        not_before: f64,
        cancel: &Cancel,
    ) -> Result<Vec<Decision>, EngineError> {
        check_run_arguments(duration, thresholds, not_before)?;
        let events = self.events(spikes, duration)?;
        let (crossings, end) = self.crossings(&events, duration, thresholds, cancel)?;
        let k = self.classes();
        let mut out = Vec::with_capacity(thresholds.len());
        for (m, theta) in thresholds.iter().enumerate() {
            let fired = theta.is_finite().then(|| {
                let crossed: Vec<f64> = (0..k)
                    .map(|j| crossings[j * thresholds.len() + m].max(not_before))
                    .collect();
                let first = crossed.iter().copied().fold(f64::INFINITY, f64::min);
                (first <= duration).then(|| {
                    let tied: Vec<usize> = (0..k).filter(|&j| crossed[j] == first).collect();
                    (tied, first)
                })
            });
            out.push(match fired.flatten() {
                Some((tied, first)) => {
                    let label = if tied.len() == 1 {
                        tied[0]
                    } else {
                        let v = self.at_time(&events, duration, first, &end);
                        first_max(tied.iter().map(|&j| v[j])).map_or(tied[0], |q| tied[q])
                    };
                    Decision {
                        label,
                        time: first,
                        fired: true,
                    }
                }
                None => Decision {
                    label: first_max(end.iter().copied()).unwrap_or(0),
                    time: duration,
                    fired: false,
                },
            });
        }
        Ok(out)
    }

    /// Every spike at or before `duration` as `(time, tde)`, in time order (ties: by TDE, then
    /// order within a train); an error for a wrong number of trains or a time that is not a
    /// finite number >= 0.
    fn events(&self, spikes: &[&[f64]], duration: f64) -> Result<Vec<(f64, u32)>, EngineError> {
        if spikes.len() != self.tdes() {
            bail!(
                "{} TDE spike trains, the readout takes {}",
                spikes.len(),
                self.tdes()
            );
        }
        let mut events = Vec::with_capacity(spikes.iter().map(|s| s.len()).sum());
        for (i, train) in spikes.iter().enumerate() {
            if let Some(t) = train.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
                bail!("TDE {i} has a spike at {t} s; spike times must be finite and >= 0");
            }
            events.extend(
                train
                    .iter()
                    .filter(|&&t| t <= duration)
                    .map(|&t| (t, i as u32)),
            );
        }
        // Stable: equal times keep TDE order, then train order (numpy's stable argsort); the
        // times are finite, and -0 equals 0 as in numpy.
        events.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(Ordering::Equal));
        Ok(events)
    }

    /// The first time each neuron reaches each finite threshold (`∞`: never), flat
    /// `[j * thresholds.len() + m]`, and every membrane at the run's end.
    fn crossings(
        &self,
        events: &[(f64, u32)],
        duration: f64,
        thresholds: &[f64],
        cancel: &Cancel,
    ) -> Result<(Vec<f64>, Vec<f64>), EngineError> {
        let k = self.classes();
        let m = thresholds.len();
        let mut order: Vec<usize> = (0..m).filter(|&q| thresholds[q].is_finite()).collect();
        order.sort_by(|&a, &b| thresholds[a].total_cmp(&thresholds[b]));
        let mut out = vec![f64::INFINITY; k * m];
        // per neuron: the next threshold (in `order`) it has not reached
        let mut next = vec![0usize; k];
        let mut sum = vec![0.0; k];
        let mut prev = vec![0.0; k]; // the membrane at the last point (just after a spike)
        let mut prev_at = 0.0;
        let mut reach = |j: usize, value: f64, along: Option<(f64, f64)>, at: f64| {
            while next[j] < order.len() && value >= thresholds[order[next[j]]] {
                let theta = thresholds[order[next[j]]];
                out[j * m + order[next[j]]] = match along {
                    Some((t0, v0)) => t0 + (theta - v0) / self.bias[j],
                    None => at,
                };
                next[j] += 1;
            }
        };
        for (e, &(t, tde)) in events.iter().enumerate() {
            if e % CANCEL_EVERY == 0 {
                cancel.check()?;
            }
            for (j, w) in self.jump(tde as usize).iter().enumerate() {
                sum[j] += w;
                let after = sum[j] + t * self.bias[j];
                reach(j, after - w, Some((prev_at, prev[j])), t); // along the line to it
                reach(j, after, None, t); // by the jump
                prev[j] = after;
            }
            prev_at = t;
        }
        let end: Vec<f64> = (0..k)
            .map(|j| prev[j] + self.bias[j] * (duration - prev_at))
            .collect();
        for (j, &v) in end.iter().enumerate() {
            reach(j, v, Some((prev_at, prev[j])), duration);
        }
        Ok((out, end))
    }

    /// Every membrane at `t` in `[0, duration]`, after the jumps of spikes at `t` (at
    /// `duration`: the end values `end`).
    fn at_time(&self, events: &[(f64, u32)], duration: f64, t: f64, end: &[f64]) -> Vec<f64> {
        let k = self.classes();
        if t >= duration {
            return (0..k)
                .map(|j| end[j] + self.bias[j] * (t - duration))
                .collect();
        }
        let mut sum = vec![0.0; k];
        let mut last = 0.0;
        for &(s, tde) in events.iter().take_while(|e| e.0 <= t) {
            for (j, w) in self.jump(tde as usize).iter().enumerate() {
                sum[j] += w;
            }
            last = s;
        }
        // the membrane just after the last spike at or before t (0 at t = 0 without one)
        let seen = events.first().is_some_and(|e| e.0 <= t);
        (0..k)
            .map(|j| {
                let after = if seen {
                    sum[j] + last * self.bias[j]
                } else {
                    0.0
                };
                after + self.bias[j] * (t - last)
            })
            .collect()
    }

    /// [`Readout::decide`] of many runs, in parallel over runs on `threads` threads (`None`:
    /// rayon's pool): `out[run][threshold]`.
    pub fn decide_batch(
        &self,
        runs: &[Vec<&[f64]>],
        duration: f64,
        thresholds: &[f64],
        not_before: f64,
        threads: Option<usize>,
        cancel: &Cancel,
    ) -> Result<Vec<Vec<Decision>>, EngineError> {
        check_run_arguments(duration, thresholds, not_before)?;
        threads::install(threads, || {
            runs.par_iter()
                .enumerate()
                .map(|(r, spikes)| {
                    self.decide(spikes, duration, thresholds, not_before, cancel)
                        .map_err(|e| EngineError(format!("run {r}: {e}")))
                })
                .collect()
        })?
    }
}

/// The index of the first largest value (`None` when empty).
fn first_max(values: impl Iterator<Item = f64>) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (q, v) in values.enumerate() {
        if best.is_none_or(|(_, b)| v > b) {
            best = Some((q, v));
        }
    }
    best.map(|(q, _)| q)
}

fn check_run_arguments(
    duration: f64,
    thresholds: &[f64],
    not_before: f64,
) -> Result<(), EngineError> {
    if !(duration.is_finite() && duration >= 0.0) {
        bail!("the run's duration must be finite and >= 0 s, got {duration}");
    }
    if let Some(t) = thresholds.iter().find(|t| t.is_nan() || **t <= 0.0) {
        bail!("readout thresholds must be > 0 (inf: decide at the end), got {t}");
    }
    if not_before.is_nan() {
        bail!("not_before must be a time [s], got NaN");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cancel::NEVER;

    fn two() -> Readout {
        // class 0: +1 per spike of TDE 0, no current; class 1: +0.5 per spike, 1/s
        Readout::new(&[1.0, 0.5], &[0.0, 1.0]).unwrap()
    }

    #[test]
    fn the_first_neuron_to_reach_the_threshold_decides_at_its_exact_crossing() {
        let r = two();
        let train = [0.3, 0.4];
        let thresholds = [0.2, 0.5, 1.5, 10.0, f64::INFINITY];
        let d = r.decide(&[&train], 1.2, &thresholds, 0.0, &NEVER).unwrap();
        let got: Vec<_> = d.iter().map(|d| (d.label, d.time, d.fired)).collect();
        assert_eq!(
            got,
            [
                (1, 0.2, true),  // class 1's membrane is t until 0.3: along its line
                (0, 0.3, true),  // both jump past 0.5 at 0.3: class 0 is higher then (1 > 0.8)
                (0, 0.4, true),  // class 0 jumps to 2 at 0.4, class 1 is at 1.4 then
                (1, 1.2, false), // nobody reaches 10: at the end 2 against 1.4 + 0.8
                (1, 1.2, false), // inf: the end
            ]
        );
    }

    #[test]
    fn a_neuron_above_threshold_at_switch_on_decides_then_the_largest_first() {
        let r = Readout::new(&[1.0, 2.0], &[0.0, 0.0]).unwrap();
        let train = [0.1];
        let d = r.decide(&[&train], 1.0, &[0.5], 0.3, &NEVER).unwrap();
        assert_eq!((d[0].label, d[0].time, d[0].fired), (1, 0.3, true));
    }

    #[test]
    fn bad_input_is_an_error_never_a_panic() {
        assert!(Readout::new(&[1.0, f64::NAN], &[0.0, 0.0]).is_err());
        assert!(Readout::new(&[1.0, 2.0, 3.0], &[0.0, 0.0]).is_err());
        assert!(Readout::new(&[], &[]).is_err());
        let r = two();
        let good = [0.1];
        let bad = [f64::NAN];
        assert!(r.decide(&[&good, &good], 1.0, &[1.0], 0.0, &NEVER).is_err());
        assert!(r.decide(&[&bad], 1.0, &[1.0], 0.0, &NEVER).is_err());
        assert!(r.decide(&[&good], 1.0, &[0.0], 0.0, &NEVER).is_err());
        assert!(r.decide(&[&good], f64::NAN, &[1.0], 0.0, &NEVER).is_err());
        let runs = vec![vec![&good[..]], vec![&bad[..]]];
        let err = r
            .decide_batch(&runs, 1.0, &[1.0], 0.0, Some(1), &NEVER)
            .unwrap_err();
        assert!(err.0.starts_with("run 1: TDE 0"), "{}", err.0);
    }
}
