//! `simulate_loihi`: the binding of [`crate::loihi`], the Loihi integer executor that
//! `mappings.lava.loihi.simulate_fixed` runs.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{contiguous, indices, run_engine};
use crate::loihi::{simulate_loihi as run, Columns, LoihiNet, ShiftedInput};

/// `(starts, rows, weights, shift)` of one CSC matrix, as `simulate_loihi` takes it.
type ColumnArrays<'py> = (
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    PyReadonlyArray1<'py, i64>,
    u32,
);
/// `(neurons, weights, shift)` of one shifted input `Dense`.
type ShiftedArrays<'py> = (PyReadonlyArray1<'py, i64>, PyReadonlyArray1<'py, i64>, u32);

fn values(a: &PyReadonlyArray1<'_, i64>, what: &str) -> PyResult<Vec<i64>> {
    Ok(contiguous(a, what)?.to_vec())
}

/// simulate_loihi(keep_u, keep_v, threshold, bias, graded, input_weights, input_shifted,
/// matrices, held_pairs, counts, record, threads=None) -> dict
///
/// Loihi's arithmetic of a network of `size` neurons (every per-neuron array int64 of length
/// `size`, `graded` 0/1) on `counts` (int64, `(steps, batch)`, the input spike count per step).
/// `matrices` are CSC by source column, `(starts, rows, weights, shift)`; `held_pairs` is
/// `(2, pairs)`. Returns `sent` `(batch, size)`, `held` `(batch, pairs)` and, with `record`,
/// `raster` `(batch, steps, size)` bool (else None).
#[pyfunction]
#[pyo3(signature = (keep_u, keep_v, threshold, bias, graded, input_weights, input_shifted, matrices, held_pairs, counts, record, threads=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn simulate_loihi<'py>(
    py: Python<'py>,
    keep_u: PyReadonlyArray1<'py, i64>,
    keep_v: PyReadonlyArray1<'py, i64>,
    threshold: PyReadonlyArray1<'py, i64>,
    bias: PyReadonlyArray1<'py, i64>,
    graded: PyReadonlyArray1<'py, i64>,
    input_weights: PyReadonlyArray1<'py, i64>,
    input_shifted: Vec<ShiftedArrays<'py>>,
    matrices: Vec<ColumnArrays<'py>>,
    held_pairs: PyReadonlyArray2<'py, i64>,
    counts: PyReadonlyArray2<'py, i64>,
    record: bool,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let pairs = held_pairs.shape();
    if pairs[0] != 2 {
        return Err(PyValueError::new_err(format!(
            "held_pairs must have shape (2, pairs), got {pairs:?}"
        )));
    }
    let flat = held_pairs
        .as_slice()
        .map_err(|_| PyValueError::new_err("held_pairs must be C-contiguous int64"))?;
    let pair_index = |i: i64| {
        usize::try_from(i).map_err(|_| PyValueError::new_err("held_pairs holds a negative index"))
    };
    let (first, second) = flat.split_at(pairs[1]);
    let held_pairs = first
        .iter()
        .zip(second)
        .map(|(&a, &b)| Ok((pair_index(a)?, pair_index(b)?)))
        .collect::<PyResult<Vec<_>>>()?;
    let net = LoihiNet {
        keep_u: values(&keep_u, "keep_u")?,
        keep_v: values(&keep_v, "keep_v")?,
        threshold: values(&threshold, "threshold")?,
        bias: values(&bias, "bias")?,
        graded: values(&graded, "graded")?.iter().map(|&g| g != 0).collect(),
        input_weights: values(&input_weights, "input_weights")?,
        input_shifted: input_shifted
            .iter()
            .map(|(n, w, shift)| {
                Ok(ShiftedInput {
                    neurons: indices(n, "a shifted input's neurons")?,
                    weights: values(w, "a shifted input's weights")?,
                    shift: *shift,
                })
            })
            .collect::<PyResult<_>>()?,
        matrices: matrices
            .iter()
            .map(|(starts, rows, weights, shift)| {
                Ok(Columns {
                    starts: indices(starts, "a matrix's column starts")?,
                    rows: indices(rows, "a matrix's rows")?,
                    weights: values(weights, "a matrix's weights")?,
                    shift: *shift,
                })
            })
            .collect::<PyResult<_>>()?,
        held_pairs,
    };
    let (n_steps, batch) = (counts.shape()[0], counts.shape()[1]);
    let counts = counts
        .as_slice()
        .map_err(|_| PyValueError::new_err("counts must be C-contiguous int64"))?
        .to_vec();
    let size = net.size();
    let runs = run_engine(py, false, |cancel| {
        crate::threads::install(threads, || run(&net, &counts, batch, record, cancel))?
    })?;
    let out = PyDict::new(py);
    let sent: Vec<i64> = runs.iter().flat_map(|r| r.sent.iter().copied()).collect();
    let held: Vec<i64> = runs.iter().flat_map(|r| r.held.iter().copied()).collect();
    out.set_item("sent", PyArray1::from_vec(py, sent).reshape([batch, size])?)?;
    let n_pairs = net.held_pairs.len();
    out.set_item(
        "held",
        PyArray1::from_vec(py, held).reshape([batch, n_pairs])?,
    )?;
    if record {
        let raster: Vec<bool> = runs
            .into_iter()
            .flat_map(|r| r.raster.unwrap_or_default())
            .collect();
        let raster = PyArray1::from_vec(py, raster).reshape([batch, n_steps, size])?;
        out.set_item("raster", raster)?;
    } else {
        out.set_item("raster", py.None())?;
    }
    Ok(out)
}
