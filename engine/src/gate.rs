//! The K-level gate of the standard-neuron sPLL, simulated exactly.
//!
//! The golden TDE multiplies at run time: a CCO spike adds `g_trg * I_fac(t⁻)` to the trigger
//! current. Chips and NIR have no such product, so the standard-neuron construction
//! (`spll_hw/construction/gate.py`) replaces it by a staircase of K comparator levels,
//! `q(x) = Σ_k increments[k] · [x > thresholds[k]]`, and a CCO spike adds `g_trg * q(I_fac(t⁻))`.
//! With a [`GateTable`] the event-driven engine applies that staircase at the exact spike time,
//! so the construction's own cost (its levels, without any time step) is measured against the
//! golden product on the same inputs.

use crate::error::{approx, bail, EngineError};
use crate::params::{SpllParams, LARGEST};

/// The levels of every sPLL of a network: `thresholds[i * k + j]` and `increments[i * k + j]`
/// are level `j` of sPLL `i` [A].
#[derive(Clone, Debug, PartialEq)]
pub struct GateTable {
    levels: usize,
    thresholds: Vec<f64>,
    increments: Vec<f64>,
}

/// The staircase of one sPLL (a view into a [`GateTable`]).
#[derive(Clone, Copy, Debug)]
pub struct Staircase<'a> {
    thresholds: &'a [f64],
    increments: &'a [f64],
}

impl Staircase<'_> {
    /// `q(x)`: the sum of the increments of the levels whose threshold `x` exceeds.
    #[inline]
    pub fn level(&self, x: f64) -> f64 {
        let mut sum = 0.0;
        for (&t, &d) in self.thresholds.iter().zip(self.increments) {
            if x <= t {
                break;
            }
            sum += d;
        }
        sum
    }
}

impl GateTable {
    /// Validate row-major `(n_spll, levels)` thresholds and increments: finite, in
    /// `[1e-100, 1e100]` like the parameters, thresholds strictly increasing per sPLL.
    pub fn new(
        thresholds: Vec<f64>,
        increments: Vec<f64>,
        levels: usize,
    ) -> Result<Self, EngineError> {
        if levels == 0 || thresholds.is_empty() || !thresholds.len().is_multiple_of(levels) {
            bail!(
                "gate thresholds must have shape (n_spll >= 1, levels >= 1); got {} values in \
                 rows of {levels}",
                thresholds.len()
            );
        }
        if increments.len() != thresholds.len() {
            bail!(
                "gate increments must have the thresholds' shape: {} values against {}",
                increments.len(),
                thresholds.len()
            );
        }
        for (what, values) in [("threshold", &thresholds), ("increment", &increments)] {
            for (n, &x) in values.iter().enumerate() {
                if !(x.is_finite() && (1.0 / LARGEST..=LARGEST).contains(&x)) {
                    bail!(
                        "sPLL {}: gate {what} {} = {x:e} must be finite and in [1e-100, 1e100]",
                        n / levels,
                        n % levels
                    );
                }
            }
        }
        for (i, row) in thresholds.chunks_exact(levels).enumerate() {
            if let Some(j) = row.windows(2).position(|w| w[1] <= w[0]) {
                bail!(
                    "sPLL {i}: gate thresholds must increase strictly, but threshold {} ({}) is \
                     not above threshold {j} ({})",
                    j + 1,
                    approx(row[j + 1]),
                    approx(row[j])
                );
            }
        }
        Ok(GateTable {
            levels,
            thresholds,
            increments,
        })
    }

    /// Check that the table has one row per sPLL of `params` and that no row's full staircase
    /// makes a trigger kick beyond [`LARGEST`] (as [`SpllParams::from_row`] checks the product).
    pub fn check(&self, params: &[SpllParams]) -> Result<(), EngineError> {
        let rows = self.thresholds.len() / self.levels;
        if rows != params.len() {
            bail!(
                "the gate has levels for {rows} sPLLs but the network has {}",
                params.len()
            );
        }
        for (i, p) in params.iter().enumerate() {
            let top: f64 = self.staircase(i).increments.iter().sum();
            let kick = p.g_trg * top;
            if kick > LARGEST || kick / p.tde.c > LARGEST {
                bail!(
                    "sPLL {i}: the gate's increments are too large: g_tde_trg times their sum is \
                     {kick:e}, beyond which the engine's state could overflow"
                );
            }
        }
        Ok(())
    }

    /// The staircase of sPLL `i`.
    pub fn staircase(&self, i: usize) -> Staircase<'_> {
        let span = i * self.levels..(i + 1) * self.levels;
        Staircase {
            thresholds: &self.thresholds[span.clone()],
            increments: &self.increments[span],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_staircase_sums_the_levels_below_its_argument() {
        let gate = GateTable::new(
            vec![1.0, 2.0, 4.0, 0.5, 3.0, 9.0],
            vec![1.0, 0.5, 0.25, 2.0, 3.0, 4.0],
            3,
        )
        .unwrap();
        let q = gate.staircase(0);
        assert_eq!(q.level(0.0), 0.0);
        assert_eq!(q.level(1.0), 0.0); // strictly above a threshold
        assert_eq!(q.level(1.5), 1.0);
        assert_eq!(q.level(3.0), 1.5);
        assert_eq!(q.level(1e9), 1.75);
        assert_eq!(gate.staircase(1).level(5.0), 5.0);
    }

    #[test]
    fn bad_tables_are_refused_naming_the_spll_and_level() {
        let error = |t: Vec<f64>, d: Vec<f64>, k| GateTable::new(t, d, k).unwrap_err().0;
        assert!(error(vec![1.0, 2.0, 3.0], vec![1.0; 3], 2).contains("shape"));
        assert!(error(vec![1.0, 2.0], vec![1.0; 3], 2).contains("increments"));
        let m = error(vec![1.0, 2.0, 1.0, f64::NAN], vec![1.0; 4], 2);
        assert!(m.starts_with("sPLL 1: gate threshold 1"), "{m}");
        let m = error(vec![1.0, 2.0], vec![1.0, 0.0], 2);
        assert!(m.starts_with("sPLL 0: gate increment 1"), "{m}");
        let m = error(vec![1.0, 2.0, 3.0, 3.0], vec![1.0; 4], 2);
        assert!(
            m.starts_with("sPLL 1: gate thresholds must increase strictly"),
            "{m}"
        );
    }
}
