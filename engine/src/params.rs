//! The 15 parameters of one sPLL, in the column order of the network matrix.

use crate::error::{bail, EngineError};
use crate::membrane::Neuron;

/// Number of parameters per sPLL (columns of the network matrix).
pub const N_PARAMS: usize = 15;

/// Column names, identical to `spll_hw.params.PARAM_NAMES` on the Python side.
pub const PARAM_NAMES: [&str; N_PARAMS] = [
    "tau_cco_syn",
    "tau_cco",
    "c_cco",
    "g_cco",
    "i_cco_offset",
    "t_cco_refr",
    "v_cco_thr",
    "tau_tde_fac",
    "tau_tde_trg",
    "tau_tde",
    "c_tde",
    "g_tde_fac",
    "g_tde_trg",
    "t_tde_refr",
    "v_tde_thr",
];

/// Which columns must be strictly positive (the rest must be >= 0).
const POSITIVE: [bool; N_PARAMS] = [
    true, true, true, false, false, false, true, true, true, true, true, false, false, false, true,
];

/// Largest magnitude of a parameter and of the current or potential one event adds; a nonzero
/// parameter must also be at least its reciprocal. The engine multiplies and divides up to
/// three parameters at once (`I_off τ / C`, `(τ − τ_syn) / (τ τ_syn)`, `g_trg g_fac / C`,
/// reciprocals of time constants) and sums the kicks of up to ~10^18 events (inputs and
/// spikes): within these bounds every value it forms stays below ~10^220, far from overflow
/// (1.8·10^308), and no product of parameters underflows.
pub const LARGEST: f64 = 1e100;

/// Parameters of one sPLL (SI units), validated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpllParams {
    /// The CCO neuron with its synapse (driven by TDE spikes) and offset current.
    pub cco: Neuron,
    /// The TDE neuron with its trigger synapse (driven by CCO spikes).
    pub tde: Neuron,
    /// CCO synapse gain: current added per TDE spike.
    pub g_cco: f64,
    /// Facilitatory synapse time constant [s].
    pub tau_fac: f64,
    /// `1 / tau_fac` [1/s].
    pub inv_tau_fac: f64,
    /// Facilitatory gain: current added per input spike.
    pub g_fac: f64,
    /// Trigger gain: a CCO spike adds `g_trg * I_fac` to the trigger current.
    pub g_trg: f64,
}

impl SpllParams {
    /// Validate one row of the network matrix (`row` is sPLL number `index`, for messages).
    pub fn from_row(row: &[f64], index: usize) -> Result<Self, EngineError> {
        if row.len() != N_PARAMS {
            bail!(
                "sPLL {index}: expected {N_PARAMS} parameters, got {}",
                row.len()
            );
        }
        for (k, (&value, name)) in row.iter().zip(PARAM_NAMES).enumerate() {
            if !value.is_finite() {
                bail!("sPLL {index}: parameter {name} must be finite, got {value}");
            }
            if POSITIVE[k] && value <= 0.0 {
                bail!("sPLL {index}: parameter {name} must be > 0, got {value}");
            }
            if !POSITIVE[k] && value < 0.0 {
                bail!("sPLL {index}: parameter {name} must be >= 0, got {value}");
            }
            if value != 0.0 && !(1.0 / LARGEST..=LARGEST).contains(&value) {
                bail!(
                    "sPLL {index}: parameter {name} = {value:e} is outside [1e-100, 1e100], \
                     the range in which the engine's products of parameters stay finite"
                );
            }
        }
        let [tau_cco_syn, tau_cco, c_cco, g_cco, i_off, t_cco_refr, v_cco_thr, tau_fac, tau_trg, tau_tde, c_tde, g_fac, g_trg, t_tde_refr, v_tde_thr] =
            <[f64; N_PARAMS]>::try_from(row).expect("length checked above");
        let trigger = g_trg * g_fac;
        check_kicks(
            index,
            [
                (
                    "i_cco_offset",
                    "i_cco_offset * tau_cco / c_cco (the CCO's resting potential)",
                    i_off * tau_cco / c_cco,
                ),
                (
                    "g_cco",
                    "g_cco / c_cco (the CCO's potential slope per TDE spike)",
                    g_cco / c_cco,
                ),
                (
                    "g_tde_trg",
                    "g_tde_trg * g_tde_fac (the trigger current of one input and one CCO spike)",
                    trigger,
                ),
                (
                    "g_tde_trg",
                    "g_tde_trg * g_tde_fac / c_tde (the TDE's potential slope per trigger)",
                    trigger / c_tde,
                ),
            ],
        )?;
        Ok(SpllParams {
            cco: Neuron::new(tau_cco, tau_cco_syn, c_cco, i_off, v_cco_thr, t_cco_refr),
            tde: Neuron::new(tau_tde, tau_trg, c_tde, 0.0, v_tde_thr, t_tde_refr),
            g_cco,
            tau_fac,
            inv_tau_fac: 1.0 / tau_fac,
            g_fac,
            g_trg,
        })
    }

    /// Validate a row-major `(n, 15)` parameter matrix.
    pub fn from_matrix(flat: &[f64]) -> Result<Vec<Self>, EngineError> {
        if flat.is_empty() || !flat.len().is_multiple_of(N_PARAMS) {
            bail!(
                "parameter matrix must have shape (n_spll >= 1, {N_PARAMS}); got {} values",
                flat.len()
            );
        }
        flat.chunks_exact(N_PARAMS)
            .enumerate()
            .map(|(i, row)| Self::from_row(row, i))
            .collect()
    }
}

/// Refuse parameters whose per-event kicks `(parameter named, what, value)` exceed [`LARGEST`]
/// (`index` names the sPLL).
fn check_kicks(index: usize, kicks: [(&str, &str, f64); 4]) -> Result<(), EngineError> {
    for (name, what, value) in kicks {
        if value > LARGEST {
            bail!(
                "sPLL {index}: parameter {name} is too large: {what} is {value:e}, more than \
                 1e100, beyond which the engine's state could overflow to inf or NaN"
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid row (Table 6's "VibTac vary offset LIF" sPLL) with the named values changed.
    fn row(changes: &[(&str, f64)]) -> [f64; N_PARAMS] {
        let mut r = [
            7.50e-3, 0.314, 1.0, 9.84, 112.7, 1e-3, 1.0, 9.59e-3, 1.25e-3, 4.52e-3, 1.0, 6.15e2,
            0.271, 1e-3, 1.0,
        ];
        for &(name, value) in changes {
            r[PARAM_NAMES.iter().position(|n| *n == name).unwrap()] = value;
        }
        r
    }

    fn error(changes: &[(&str, f64)]) -> String {
        SpllParams::from_row(&row(changes), 4).unwrap_err().0
    }

    #[test]
    fn values_outside_the_safe_range_are_refused_by_name() {
        SpllParams::from_row(&row(&[]), 0).unwrap();
        for name in PARAM_NAMES {
            for value in [1e101, 5e-324, 1e-101] {
                let message = error(&[(name, value)]);
                assert!(
                    message.starts_with(&format!("sPLL 4: parameter {name} = ")),
                    "{message}"
                );
                assert!(message.contains("outside [1e-100, 1e100]"), "{message}");
            }
        }
        // Zero stays allowed where it was, and the bounds themselves are in range.
        SpllParams::from_row(&row(&[("g_cco", 0.0), ("t_tde_refr", 0.0)]), 0).unwrap();
        SpllParams::from_row(&row(&[("tau_tde", 1e100), ("v_cco_thr", 1e-100)]), 0).unwrap();
    }

    #[test]
    fn products_that_would_overflow_the_state_are_refused_naming_a_factor() {
        for (changes, name) in [
            (
                &[("i_cco_offset", 1e60), ("tau_cco", 1e60)][..],
                "i_cco_offset",
            ),
            (&[("g_cco", 1e60), ("c_cco", 1e-60)][..], "g_cco"),
            (&[("g_tde_trg", 1e60), ("g_tde_fac", 1e60)][..], "g_tde_trg"),
            (
                &[("g_tde_trg", 1e40), ("g_tde_fac", 1e40), ("c_tde", 1e-40)][..],
                "g_tde_trg",
            ),
        ] {
            let message = error(changes);
            assert!(
                message.starts_with(&format!("sPLL 4: parameter {name} is too large")),
                "{message}"
            );
        }
    }
}
