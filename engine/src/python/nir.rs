//! `NirStepper`: the binding of [`crate::nir_graph`], the executor that
//! `mappings.nir.executor` runs, keeping every sample's state between calls.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{contiguous, indices, run_engine};
use crate::nir_graph::{run_steps, Kind, Lif, NirGraph, Node, SampleState};

/// One node as Python passes it: `(kind, size_in, preds, arrays, matrix)`; `arrays` are the
/// coefficients (`Affine`: data[, bias]; `LIF`: a, r, v_leak, v_threshold, v_reset;
/// `CubaLIF`: a_syn, w_in and the LIF's), `matrix` an `Affine`'s CSC `(starts, rows, n_rows)`.
type NodeSpec<'py> = (
    String,
    usize,
    Vec<(usize, bool)>,
    Vec<PyReadonlyArray1<'py, f64>>,
    Option<(
        PyReadonlyArray1<'py, i64>,
        PyReadonlyArray1<'py, i64>,
        usize,
    )>,
);

fn lif(v: &mut std::vec::IntoIter<Vec<f64>>) -> Lif {
    let mut next = || v.next().unwrap_or_default();
    Lif {
        a: next(),
        r: next(),
        leak: next(),
        threshold: next(),
        reset: next(),
    }
}

fn node(k: usize, spec: NodeSpec<'_>) -> PyResult<Node> {
    let (kind, size_in, preds, arrays, matrix) = spec;
    let wanted = match kind.as_str() {
        "Input" | "Output" => 0,
        "Affine" => 2,
        "Linear" => 1,
        "LIF" => 5,
        "CubaLIF" => 7,
        other => {
            return Err(PyValueError::new_err(format!(
                "node {k}: unknown kind {other:?}"
            )))
        }
    };
    if arrays.len() != wanted {
        return Err(PyValueError::new_err(format!(
            "node {k}: a {kind} takes {wanted} coefficient arrays, got {}",
            arrays.len()
        )));
    }
    let mut values = arrays
        .iter()
        .map(|a| Ok(contiguous(a, &format!("node {k}'s coefficients"))?.to_vec()))
        .collect::<PyResult<Vec<_>>>()?
        .into_iter();
    let kind = match kind.as_str() {
        "Input" => Kind::Input,
        "Output" => Kind::Output,
        "LIF" => Kind::Lif(lif(&mut values)),
        "CubaLIF" => Kind::CubaLif {
            a_syn: values.next().unwrap_or_default(),
            w_in: values.next().unwrap_or_default(),
            lif: lif(&mut values),
        },
        _ => {
            let Some((starts, rows, n_rows)) = matrix else {
                return Err(PyValueError::new_err(format!(
                    "node {k}: an {kind} needs its matrix"
                )));
            };
            Kind::Affine {
                starts: indices(&starts, &format!("node {k}'s column starts"))?,
                rows: indices(&rows, &format!("node {k}'s rows"))?,
                data: values.next().unwrap_or_default(),
                n_rows,
                bias: values.next(),
            }
        }
    };
    Ok(Node {
        kind,
        size_in,
        preds,
    })
}

/// NirStepper(nodes, output, batch): a graph's nodes in execution order (input first; each
/// `(kind, size_in, preds, arrays, matrix)`), the output node's position, and `batch` samples,
/// each with its state. `run(inputs)` steps them on `(steps, batch, n_in)` float64 and returns
/// the output's values `(steps, batch, n_out)`; `spikes()` each neuron node's spikes so far.
#[pyclass(module = "spll_hw._engine")]
pub(super) struct NirStepper {
    graph: NirGraph,
    states: Vec<SampleState>,
}

#[pymethods]
impl NirStepper {
    #[new]
    fn new(nodes: Vec<NodeSpec<'_>>, output: usize, batch: usize) -> PyResult<Self> {
        let nodes = nodes
            .into_iter()
            .enumerate()
            .map(|(k, spec)| node(k, spec))
            .collect::<PyResult<Vec<_>>>()?;
        let graph = NirGraph::new(nodes, output)?;
        let states = (0..batch).map(|_| graph.start()).collect();
        Ok(NirStepper { graph, states })
    }

    fn run<'py>(
        &mut self,
        py: Python<'py>,
        inputs: PyReadonlyArray3<'py, f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let shape = inputs.shape().to_vec();
        if shape[1] != self.states.len() || shape[2] != self.graph.n_in() {
            return Err(PyValueError::new_err(format!(
                "inputs must have shape (steps, {}, {}), got {shape:?}",
                self.states.len(),
                self.graph.n_in()
            )));
        }
        let values = inputs
            .as_slice()
            .map_err(|_| PyValueError::new_err("inputs must be C-contiguous float64"))?
            .to_vec();
        let (graph, states) = (&self.graph, &mut self.states);
        let out = run_engine(py, false, |cancel| {
            run_steps(graph, states, &values, cancel)
        })?;
        let n_out = self.graph.n_out();
        Ok(PyArray1::from_vec(py, out)
            .reshape([shape[0], shape[1], n_out])?
            .into_any())
    }

    /// `{position in the order: (batch, size) spikes so far}` of every neuron node.
    fn spikes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (k, node) in self.graph.nodes.iter().enumerate() {
            if !matches!(node.kind, Kind::Lif(_) | Kind::CubaLif { .. }) {
                continue;
            }
            let size = node.size_out();
            let all: Vec<f64> = self
                .states
                .iter()
                .flat_map(|s| s.spikes[k].iter().copied())
                .collect();
            out.set_item(
                k,
                PyArray1::from_vec(py, all).reshape([self.states.len(), size])?,
            )?;
        }
        Ok(out)
    }
}
