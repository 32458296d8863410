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
        }
        let [tau_cco_syn, tau_cco, c_cco, g_cco, i_off, t_cco_refr, v_cco_thr, tau_fac, tau_trg, tau_tde, c_tde, g_fac, g_trg, t_tde_refr, v_tde_thr] =
            <[f64; N_PARAMS]>::try_from(row).expect("length checked above");
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
