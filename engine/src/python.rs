//! PyO3 bindings: `spll_hw._engine`. The Python package (`spll_hw.simulate`) wraps these with
//! friendlier types; every invalid input comes back as `ValueError`. The simulation itself runs
//! on a worker thread with the GIL released while the calling thread watches for signals, so
//! Ctrl-C stops it within a fraction of a second ([`interruptible`]); a panic in it comes back
//! as `RuntimeError`, never as a crash.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Condvar, Mutex, PoisonError};
use std::time::Duration;

use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyReadonlyArray3, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

mod loihi;
mod nir;

use crate::cancel::Cancel;
use crate::error::EngineError;
use crate::fixed_point::{FixedFormat, FixedSpll, FixedState, N_FIXED_PARAMS};
use crate::gate::GateTable;
use crate::network::{self, RunConfig, SampleResult};
use crate::params::{SpllParams, N_PARAMS, PARAM_NAMES};
use crate::readout::Readout;
use crate::spll::{SpllState, MAX_EVENTS, STATE_LEN, STATE_NAMES};

/// A K-level gate as passed from Python: `(thresholds, increments)`.
type GateArrays<'py> = (PyReadonlyArray2<'py, f64>, PyReadonlyArray2<'py, f64>);

impl From<EngineError> for PyErr {
    fn from(e: EngineError) -> PyErr {
        PyValueError::new_err(e.0)
    }
}

/// How often the calling thread looks for a Python signal while the engine runs.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Whether the worker of [`interruptible`] has ended, for the calling thread to wait on.
#[derive(Default)]
struct Finished {
    done: Mutex<bool>,
    changed: Condvar,
}

impl Finished {
    fn set(&self) {
        *self.done.lock().unwrap_or_else(PoisonError::into_inner) = true;
        self.changed.notify_all();
    }

    /// Wait until the worker ends or `timeout` passes; whether it has ended.
    fn wait(&self, timeout: Duration) -> bool {
        let done = self.done.lock().unwrap_or_else(PoisonError::into_inner);
        let (done, _) = self
            .changed
            .wait_timeout_while(done, timeout, |done| !*done)
            .unwrap_or_else(PoisonError::into_inner);
        *done
    }
}

/// Run `work` on a worker thread with the GIL released, while this thread checks for Python
/// signals every [`SIGNAL_POLL`]. When a signal handler raises (Ctrl-C: `KeyboardInterrupt`),
/// the work's [`Cancel`] flag is raised, its loops stop within a millisecond or so, and the
/// handler's exception is returned. Engine errors become `ValueError`, a panic `RuntimeError`.
fn interruptible<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel) -> Result<T, EngineError> + Send,
{
    let cancel = Cancel::new();
    let finished = Finished::default();
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("spll-engine".into())
            .spawn_scoped(scope, || {
                let outcome = catch_unwind(AssertUnwindSafe(|| work(&cancel)));
                finished.set();
                outcome
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the engine thread: {e}")))?;
        let interrupt = loop {
            if py.detach(|| finished.wait(SIGNAL_POLL)) {
                break None;
            }
            if let Err(signal) = py.check_signals() {
                cancel.request();
                break Some(signal);
            }
        };
        // The worker catches its own panics, so joining cannot fail.
        let outcome = py.detach(|| worker.join()).unwrap_or_else(Err);
        match (interrupt, outcome) {
            (Some(signal), _) => Err(signal),
            (None, Ok(result)) => Ok(result?),
            (None, Err(panic)) => Err(panic_error(panic.as_ref())),
        }
    })
}

/// sPLL-steps (time steps × sPLLs) a fixed-point call runs on the calling thread, without
/// [`interruptible`]'s worker: at most a millisecond or so of work, less than starting a
/// thread costs on a busy machine (short resumed pieces: the USB emulator runs one per packet).
const INLINE_SPLL_STEPS: u64 = 1 << 18;

/// [`interruptible`], or on the calling thread when the work is `short` (it then cannot be
/// interrupted, and needs not be: it ends within about a millisecond).
fn run_engine<T, F>(py: Python<'_>, short: bool, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Cancel) -> Result<T, EngineError> + Send,
{
    if !short {
        return interruptible(py, work);
    }
    match catch_unwind(AssertUnwindSafe(|| work(&crate::cancel::NEVER))) {
        Ok(result) => Ok(result?),
        Err(panic) => Err(panic_error(panic.as_ref())),
    }
}

/// A panic of the engine as a Python `RuntimeError` (a bug: valid or not, input gets a
/// `ValueError`).
fn panic_error(panic: &(dyn Any + Send)) -> PyErr {
    let message = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_owned());
    PyRuntimeError::new_err(format!(
        "internal error in the spll engine (please report it): {message}"
    ))
}

/// An array element type the bindings take, with numpy's name for it (for error messages).
trait Dtype: numpy::Element + Copy {
    const NAME: &'static str;
}

impl Dtype for f64 {
    const NAME: &'static str = "float64";
}

impl Dtype for i64 {
    const NAME: &'static str = "int64";
}

fn contiguous<'a, T: Dtype>(a: &'a PyReadonlyArray1<'_, T>, what: &str) -> PyResult<&'a [T]> {
    a.as_slice().map_err(|_| {
        PyValueError::new_err(format!("{what} must be a contiguous {} array", T::NAME))
    })
}

/// `a` (int64) as indices, or an error naming `what` holds a negative one.
fn indices(a: &PyReadonlyArray1<'_, i64>, what: &str) -> PyResult<Vec<usize>> {
    contiguous(a, what)?
        .iter()
        .map(|&i| {
            usize::try_from(i)
                .map_err(|_| PyValueError::new_err(format!("{what} holds a negative index {i}")))
        })
        .collect()
}

/// Copies of every sample's input train (small next to the simulation), so the GIL can go.
fn owned_trains(inputs: &[PyReadonlyArray1<'_, f64>]) -> PyResult<Vec<Vec<f64>>> {
    inputs
        .iter()
        .enumerate()
        .map(|(i, a)| {
            contiguous(a, &format!("input spike times of sample {i}")).map(<[f64]>::to_vec)
        })
        .collect()
}

fn network_params(matrix: &PyReadonlyArray2<'_, f64>) -> PyResult<Vec<SpllParams>> {
    let shape = matrix.shape();
    if shape[1] != N_PARAMS {
        return Err(PyValueError::new_err(format!(
            "parameter matrix must have {N_PARAMS} columns, got shape {shape:?}"
        )));
    }
    let flat = matrix
        .as_slice()
        .map_err(|_| PyValueError::new_err("parameter matrix must be C-contiguous float64"))?;
    Ok(SpllParams::from_matrix(flat)?)
}

/// The K-level gate `(thresholds, increments)`, each `(n_spll, K)` float64 [A], if given.
fn gate_table(gate: &Option<GateArrays<'_>>) -> PyResult<Option<GateTable>> {
    let Some((thresholds, increments)) = gate else {
        return Ok(None);
    };
    let flat = |a: &PyReadonlyArray2<'_, f64>, what: &str| {
        a.as_slice().map(<[f64]>::to_vec).map_err(|_| {
            PyValueError::new_err(format!("gate {what} must be a C-contiguous float64 array"))
        })
    };
    if thresholds.shape() != increments.shape() {
        return Err(PyValueError::new_err(format!(
            "gate thresholds and increments must have one shape (n_spll, K); got {:?} and {:?}",
            thresholds.shape(),
            increments.shape()
        )));
    }
    let levels = thresholds.shape()[1];
    let table = GateTable::new(
        flat(thresholds, "thresholds")?,
        flat(increments, "increments")?,
        levels,
    )?;
    Ok(Some(table))
}

fn counts(result: &SampleResult) -> (Vec<i64>, Vec<i64>) {
    result
        .recorders
        .iter()
        .map(|r| (r.tde_count as i64, r.cco_count as i64))
        .unzip()
}

fn spike_lists<'py>(
    py: Python<'py>,
    result: &mut SampleResult,
) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    let tde = PyList::empty(py);
    let cco = PyList::empty(py);
    for r in &mut result.recorders {
        tde.append(std::mem::take(&mut r.tde_spikes).into_pyarray(py))?;
        cco.append(std::mem::take(&mut r.cco_spikes).into_pyarray(py))?;
    }
    Ok((tde, cco))
}

/// Store per-sample TDE and CCO spike counts (flattened, sample-major) as `tde_counts` and
/// `cco_counts` arrays of shape `(samples, n_spll)`.
fn set_counts(
    out: &Bound<'_, PyDict>,
    tde: Vec<i64>,
    cco: Vec<i64>,
    shape: [usize; 2],
) -> PyResult<()> {
    let py = out.py();
    out.set_item("tde_counts", PyArray1::from_vec(py, tde).reshape(shape)?)?;
    out.set_item("cco_counts", PyArray1::from_vec(py, cco).reshape(shape)?)?;
    Ok(())
}

/// simulate(matrix, inputs, t_end, keep_spikes, state=None, probes=None, max_events, gate=None)
/// -> dict
///
/// One sample on every sPLL of the network (`matrix`: (n, 15) float64). Returns `tde_counts`,
/// `cco_counts` ((n,) int64), `tde_spikes`/`cco_spikes` (lists of arrays, or None), `state`
/// ((n, 13) float64, to resume from) and `trace` ((n, len(probes), 5) float64:
/// I_fac, I_trg, V_tde, I_cco, V_cco). More than `max_events` events in one sPLL is an error.
/// `gate` = `(thresholds, increments)` ((n, K) float64 each) runs the standard-neuron sPLL's
/// K-level gate instead of the product ([`crate::gate`]).
#[pyfunction]
#[pyo3(signature = (matrix, inputs, t_end, keep_spikes, state=None, probes=None, max_events=MAX_EVENTS, gate=None))]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments one to one
fn simulate<'py>(
    py: Python<'py>,
    matrix: PyReadonlyArray2<'py, f64>,
    inputs: PyReadonlyArray1<'py, f64>,
    t_end: f64,
    keep_spikes: bool,
    state: Option<PyReadonlyArray2<'py, f64>>,
    probes: Option<PyReadonlyArray1<'py, f64>>,
    max_events: u64,
    gate: Option<GateArrays<'py>>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = network_params(&matrix)?;
    let gate = gate_table(&gate)?;
    let inputs = contiguous(&inputs, "input spike times")?.to_vec();
    let probes = match &probes {
        Some(p) => contiguous(p, "probe times")?.to_vec(),
        None => Vec::new(),
    };
    let states = match &state {
        Some(s) => {
            let flat = s
                .as_slice()
                .map_err(|_| PyValueError::new_err("state must be a C-contiguous float64 array"))?;
            if s.shape()[1] != STATE_LEN {
                return Err(PyValueError::new_err(format!(
                    "state must have shape (n_spll, {STATE_LEN}), got {:?}",
                    s.shape()
                )));
            }
            let parsed: Result<Vec<_>, _> = flat
                .chunks_exact(STATE_LEN)
                .enumerate()
                .map(|(i, row)| SpllState::from_array(row, i))
                .collect();
            Some(parsed?)
        }
        None => None,
    };
    let mut result = interruptible(py, |cancel| {
        network::simulate(
            &params,
            &inputs,
            t_end,
            states,
            &probes,
            RunConfig {
                keep_spikes,
                max_events,
                cancel,
                gate: gate.as_ref(),
            },
            true,
        )
    })?;
    let out = PyDict::new(py);
    let (tde_counts, cco_counts) = counts(&result);
    out.set_item("tde_counts", tde_counts.into_pyarray(py))?;
    out.set_item("cco_counts", cco_counts.into_pyarray(py))?;
    if keep_spikes {
        let (tde, cco) = spike_lists(py, &mut result)?;
        out.set_item("tde_spikes", tde)?;
        out.set_item("cco_spikes", cco)?;
    } else {
        out.set_item("tde_spikes", py.None())?;
        out.set_item("cco_spikes", py.None())?;
    }
    let n = params.len();
    let flat_state: Vec<f64> = result.states.iter().flat_map(|s| s.to_array()).collect();
    out.set_item(
        "state",
        PyArray1::from_vec(py, flat_state).reshape([n, STATE_LEN])?,
    )?;
    let flat_trace: Vec<f64> = result
        .recorders
        .iter()
        .flat_map(|r| r.trace.iter().flatten().copied())
        .collect();
    out.set_item(
        "trace",
        PyArray1::from_vec(py, flat_trace).reshape([n, probes.len(), 5])?,
    )?;
    Ok(out)
}

/// simulate_batch(matrix, inputs, t_end, keep_spikes, threads=None, max_events, gate=None) -> dict
///
/// Many samples from rest, in parallel over samples with the GIL released. Returns `tde_counts`
/// and `cco_counts` ((n_samples, n_spll) int64) and, with `keep_spikes`, `tde_spikes` and
/// `cco_spikes` (per sample, a list of per-sPLL arrays).
#[pyfunction]
#[pyo3(signature = (matrix, inputs, t_end, keep_spikes, threads=None, max_events=MAX_EVENTS, gate=None))]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments one to one
fn simulate_batch<'py>(
    py: Python<'py>,
    matrix: PyReadonlyArray2<'py, f64>,
    inputs: Vec<PyReadonlyArray1<'py, f64>>,
    t_end: f64,
    keep_spikes: bool,
    threads: Option<usize>,
    max_events: u64,
    gate: Option<GateArrays<'py>>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = network_params(&matrix)?;
    let gate = gate_table(&gate)?;
    let owned = owned_trains(&inputs)?;
    let mut results = interruptible(py, |cancel| {
        let views: Vec<&[f64]> = owned.iter().map(Vec::as_slice).collect();
        network::simulate_batch(
            &params,
            &views,
            t_end,
            RunConfig {
                keep_spikes,
                max_events,
                cancel,
                gate: gate.as_ref(),
            },
            threads,
        )
    })?;
    let n = params.len();
    let (mut tde, mut cco) = (
        Vec::with_capacity(n * results.len()),
        Vec::with_capacity(n * results.len()),
    );
    for r in &results {
        let (t, c) = counts(r);
        tde.extend(t);
        cco.extend(c);
    }
    let out = PyDict::new(py);
    set_counts(&out, tde, cco, [results.len(), n])?;
    if keep_spikes {
        let tde_all = PyList::empty(py);
        let cco_all = PyList::empty(py);
        for r in &mut results {
            let (t, c) = spike_lists(py, r)?;
            tde_all.append(t)?;
            cco_all.append(c)?;
        }
        out.set_item("tde_spikes", tde_all)?;
        out.set_item("cco_spikes", cco_all)?;
    }
    Ok(out)
}

/// readout_decisions(weights, bias, runs, duration, thresholds, not_before, threads=None)
/// -> (labels, times, fired)
///
/// The spiking readout's winner-take-all decisions ([`crate::readout`]) of many runs, in
/// parallel over runs with the GIL released: `weights` ((classes, tdes) float64), `bias`
/// ((classes,)), `runs` (per run, a list of `tdes` arrays of TDE spike times [s]), every
/// run `duration` s long, at every one of `thresholds` ((m,), > 0, inf: at the end), no earlier
/// than `not_before` [s]. Returns `labels` ((runs, m) int64), `times` ((runs, m) float64 [s])
/// and `fired` ((runs, m) bool).
#[pyfunction]
#[pyo3(signature = (weights, bias, runs, duration, thresholds, not_before, threads=None))]
#[allow(clippy::too_many_arguments)] // mirrors the Python keyword arguments one to one
#[allow(clippy::type_complexity)] // the three arrays Python unpacks
fn readout_decisions<'py>(
    py: Python<'py>,
    weights: PyReadonlyArray2<'py, f64>,
    bias: PyReadonlyArray1<'py, f64>,
    runs: Vec<Vec<PyReadonlyArray1<'py, f64>>>,
    duration: f64,
    thresholds: PyReadonlyArray1<'py, f64>,
    not_before: f64,
    threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<bool>>,
)> {
    let bias = contiguous(&bias, "readout bias")?;
    if weights.shape()[0] != bias.len() {
        return Err(PyValueError::new_err(format!(
            "readout weights must have shape (classes, tdes) with one row per bias, got {:?} \
             for {} classes",
            weights.shape(),
            bias.len()
        )));
    }
    let flat = weights
        .as_slice()
        .map_err(|_| PyValueError::new_err("readout weights must be C-contiguous float64"))?;
    let readout = Readout::new(flat, bias)?;
    let thresholds = contiguous(&thresholds, "readout thresholds")?.to_vec();
    let owned: Vec<Vec<Vec<f64>>> = runs
        .iter()
        .enumerate()
        .map(|(r, run)| owned_trains(run).map_err(|e| prefixed(py, e, &format!("run {r}: "))))
        .collect::<PyResult<_>>()?;
    let decisions = interruptible(py, |cancel| {
        let views: Vec<Vec<&[f64]>> = owned
            .iter()
            .map(|run| run.iter().map(Vec::as_slice).collect())
            .collect();
        readout.decide_batch(&views, duration, &thresholds, not_before, threads, cancel)
    })?;
    let shape = [decisions.len(), thresholds.len()];
    let flat = decisions.iter().flatten();
    let labels: Vec<i64> = flat.clone().map(|d| d.label as i64).collect();
    let times: Vec<f64> = flat.clone().map(|d| d.time).collect();
    let fired: Vec<bool> = flat.map(|d| d.fired).collect();
    Ok((
        PyArray1::from_vec(py, labels).reshape(shape)?,
        PyArray1::from_vec(py, times).reshape(shape)?,
        PyArray1::from_vec(py, fired).reshape(shape)?,
    ))
}

/// `error` with `prefix` before its message (the same exception type).
fn prefixed(py: Python<'_>, error: PyErr, prefix: &str) -> PyErr {
    let message = error.value(py).to_string();
    PyValueError::new_err(format!("{prefix}{message}"))
}

#[pymodule]
fn _engine(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_fixed_point, m)?)?;
    m.add_function(wrap_pyfunction!(cco_free_periods, m)?)?;
    m.add_function(wrap_pyfunction!(readout_decisions, m)?)?;
    m.add_function(wrap_pyfunction!(loihi::simulate_loihi, m)?)?;
    m.add_class::<nir::NirStepper>()?;
    m.add("PARAM_NAMES", PARAM_NAMES.to_vec())?;
    m.add(
        "FIXED_PARAM_NAMES",
        crate::fixed_point::FIXED_PARAM_NAMES.to_vec(),
    )?;
    m.add("GRID_RTOL", crate::fixed_point::GRID_RTOL)?;
    m.add("LOIHI_UV_MAX", crate::loihi::UV_MAX)?;
    m.add("LOIHI_DECAY_BITS", crate::loihi::DECAY_BITS)?;
    m.add("STATE_LEN", STATE_LEN)?;
    m.add("STATE_NAMES", STATE_NAMES.to_vec())?;
    Ok(())
}

/// Validate an (n, 16) int64 fixed-point parameter matrix.
fn fixed_params(
    matrix: &PyReadonlyArray2<'_, i64>,
    format: &FixedFormat,
) -> PyResult<Vec<FixedSpll>> {
    let shape = matrix.shape();
    if shape[1] != N_FIXED_PARAMS {
        return Err(PyValueError::new_err(format!(
            "fixed-point parameter matrix must have {N_FIXED_PARAMS} columns, got shape {shape:?}"
        )));
    }
    let flat = matrix.as_slice().map_err(|_| {
        PyValueError::new_err("fixed-point parameter matrix must be C-contiguous int64")
    })?;
    Ok(FixedSpll::from_matrix(flat, format)?)
}

/// Validate the `(n_samples, n, 9)` int64 start states of `simulate_fixed_point` against the
/// network (`FixedState::from_array`): one row per sample and sPLL.
fn fixed_states(
    state: &PyReadonlyArray3<'_, i64>,
    params: &[FixedSpll],
    format: &FixedFormat,
    samples: usize,
) -> PyResult<Vec<Vec<FixedState>>> {
    use crate::fixed_point::FIXED_STATE_LEN;
    let expected = [samples, params.len(), FIXED_STATE_LEN];
    if state.shape() != expected {
        return Err(PyValueError::new_err(format!(
            "fixed-point state must have shape (samples, n_spll, {FIXED_STATE_LEN}) = \
             {expected:?} for {samples} samples of this network, got {:?}",
            state.shape()
        )));
    }
    let flat = state
        .as_slice()
        .map_err(|_| PyValueError::new_err("fixed-point state must be C-contiguous int64"))?;
    let rows: Result<Vec<FixedState>, _> = flat
        .chunks_exact(FIXED_STATE_LEN)
        .enumerate()
        .map(|(k, row)| {
            let (sample, i) = (k / params.len(), k % params.len());
            let what = format!("start state of sample {sample}, sPLL {i}");
            FixedState::from_array(row, &params[i], format, &what)
        })
        .collect();
    Ok(rows?
        .chunks_exact(params.len())
        .map(<[FixedState]>::to_vec)
        .collect())
}

/// cco_free_periods(matrix, state_bits, decay_bits, max_steps) -> (n,) int64
///
/// Free-running period [steps] of each sPLL's CCO (`matrix`: the (n, 16) int64 parameter
/// matrix of `simulate_fixed_point`) with no input, so driven by `cco_bias >> cco_current_shift`
/// alone: the step of its first spike from rest plus `cco_refr`, or 0 if it does not fire
/// within `max_steps` steps (at most 10^9). The same membrane step as
/// `simulate_fixed_point`, which with an empty input train fires first at that step.
#[pyfunction]
fn cco_free_periods<'py>(
    py: Python<'py>,
    matrix: PyReadonlyArray2<'py, i64>,
    state_bits: u32,
    decay_bits: u32,
    max_steps: u64,
) -> PyResult<Bound<'py, PyArray1<i64>>> {
    let format = FixedFormat::new(state_bits, decay_bits)?;
    let params = fixed_params(&matrix, &format)?;
    let periods = interruptible(py, |cancel| {
        crate::fixed_point::cco_free_periods(&params, &format, max_steps, cancel)
    })?;
    // A period is at most MAX_STEPS + 2^32 - 1 steps.
    Ok(periods
        .into_iter()
        .map(|p| p as i64)
        .collect::<Vec<_>>()
        .into_pyarray(py))
}

/// simulate_fixed_point(matrix, inputs, dt, duration, state_bits, decay_bits, keep_spikes,
/// threads=None, max_steps=MAX_STEPS, state=None, start_step=0) -> dict
///
/// The discrete-time fixed-point reference (`crate::fixed_point`): `matrix` is the (n, 16) int64
/// integer parameter matrix, `inputs` a list of input trains [s] (one per sample). Returns
/// `tde_counts`, `cco_counts` ((n_samples, n) int64), `saturations` ((n_samples, n, 5) int64:
/// f, g, TDE v, CCO u, CCO v), `state` ((n_samples, n, 9) int64, the state after the last step),
/// `n_steps`, and with `keep_spikes` `tde_spikes`/`cco_spikes` (per sample, per-sPLL arrays of
/// times k·dt [s]; otherwise None).
///
/// `state` (the `state` of a call that ended at step `start_step`) continues those runs: steps
/// `start_step + 1 ..= round(duration / dt)` run from it, and every input must arrive after
/// `start_step`. Counts and saturations are then those of the continuation; joined, the pieces
/// equal one whole run bit for bit.
#[pyfunction]
#[pyo3(signature = (matrix, inputs, dt, duration, state_bits, decay_bits, keep_spikes, threads=None, max_steps=crate::fixed_point::MAX_STEPS, state=None, start_step=0))]
#[allow(clippy::too_many_arguments)]
fn simulate_fixed_point<'py>(
    py: Python<'py>,
    matrix: PyReadonlyArray2<'py, i64>,
    inputs: Vec<PyReadonlyArray1<'py, f64>>,
    dt: f64,
    duration: f64,
    state_bits: u32,
    decay_bits: u32,
    keep_spikes: bool,
    threads: Option<usize>,
    max_steps: u64,
    state: Option<PyReadonlyArray3<'py, i64>>,
    start_step: u64,
) -> PyResult<Bound<'py, PyDict>> {
    use crate::fixed_point::{simulate_fixed, StepConfig, FIXED_STATE_LEN, N_SATURATION};
    let format = FixedFormat::new(state_bits, decay_bits)?;
    let params = fixed_params(&matrix, &format)?;
    let owned = owned_trains(&inputs)?;
    let starts = match &state {
        Some(s) => fixed_states(s, &params, &format, inputs.len())?,
        None => Vec::new(),
    };
    let config = StepConfig {
        dt,
        duration,
        start_step,
        starts: &starts,
        keep_spikes,
        max_steps,
        cancel: &crate::cancel::NEVER,
    };
    let n_steps = config.n_steps()?;
    let spll_steps = (n_steps - start_step).saturating_mul((params.len() * owned.len()) as u64);
    let results = run_engine(py, spll_steps <= INLINE_SPLL_STEPS, |cancel| {
        let views: Vec<&[f64]> = owned.iter().map(Vec::as_slice).collect();
        simulate_fixed(
            &params,
            &format,
            &views,
            StepConfig { cancel, ..config },
            threads,
        )
    })?;
    let (samples, n) = (results.len(), params.len());
    let records = results.iter().flatten();
    let tde: Vec<i64> = records.clone().map(|r| r.tde_count as i64).collect();
    let cco: Vec<i64> = records.clone().map(|r| r.cco_count as i64).collect();
    let sat: Vec<i64> = records
        .clone()
        .flat_map(|r| r.saturations.map(|c| c as i64))
        .collect();
    let state: Vec<i64> = records.flat_map(|r| r.state.to_array()).collect();
    let out = PyDict::new(py);
    set_counts(&out, tde, cco, [samples, n])?;
    out.set_item(
        "saturations",
        PyArray1::from_vec(py, sat).reshape([samples, n, N_SATURATION])?,
    )?;
    out.set_item(
        "state",
        PyArray1::from_vec(py, state).reshape([samples, n, FIXED_STATE_LEN])?,
    )?;
    out.set_item("n_steps", n_steps)?;
    if keep_spikes {
        let tde_all = PyList::empty(py);
        let cco_all = PyList::empty(py);
        for sample in results {
            let tde = PyList::empty(py);
            let cco = PyList::empty(py);
            for r in sample {
                tde.append(r.tde_spikes.into_pyarray(py))?;
                cco.append(r.cco_spikes.into_pyarray(py))?;
            }
            tde_all.append(tde)?;
            cco_all.append(cco)?;
        }
        out.set_item("tde_spikes", tde_all)?;
        out.set_item("cco_spikes", cco_all)?;
    } else {
        out.set_item("tde_spikes", py.None())?;
        out.set_item("cco_spikes", py.None())?;
    }
    Ok(out)
}
