"""Run a :class:`~spll_hw.network.Network` in Brian2 and return a :class:`SimulationResult`.

Brian2's build products never land in the repository: Cython's extension cache and the C++
standalone projects go under the system temp directory (``tempfile.gettempdir()``). A process
keeps a standalone project per shape of network (:func:`standalone_project`) and deletes them
at exit: Brian2 rewrites only the generated files whose text changed and ``make`` recompiles
only those, so a batch of the same shape as an earlier one (other inputs or parameters: only
``objects.cpp`` and ``main.cpp`` change) compiles in about a third of the time of the first.
The shape is what the code objects hold as constants (the number of neurons, recording).
"""

from __future__ import annotations

import atexit
import gc
import os
import shutil
import tempfile
import time
import warnings
from collections import OrderedDict
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType

import numpy as np

from spll_hw.network import Network
from spll_hw.params import SpllParams
from spll_hw.result import SimulationResult

from .checks import DtResolutionWarning, dt_warnings, n_steps
from .model import Brian2Model, build

#: Codegen targets :func:`simulate_brian2` accepts.
TARGETS = ("numpy", "cython", "cpp_standalone")

#: Parallel compile jobs for a C++ standalone project (the project's machines have 2 cores).
MAKE_JOBS = 2


def import_brian2() -> ModuleType:
    """The ``brian2`` module, or an ImportError saying how to install it."""
    try:
        import brian2
    except ImportError as exc:
        raise ImportError(
            "the Brian2 backend needs Brian2, an optional dependency of spll-hw: "
            "pip install -e .[brian2]"
        ) from exc
    return brian2


def cache_dir() -> Path:
    """Directory [path] of Brian2's Cython extension cache (under the system temp directory)."""
    return Path(tempfile.gettempdir()) / "spll-hw-brian2" / "cython"


@contextmanager
def _preferences(b2: ModuleType, **values) -> Iterator[None]:
    """Set Brian2 preferences (dotted names with ``__`` for ``.``) and restore them after."""
    names = {key.replace("__", "."): value for key, value in values.items()}
    saved = {name: b2.prefs[name] for name in names}
    try:
        for name, value in names.items():
            b2.prefs[name] = value
        yield
    finally:
        for name, value in saved.items():
            b2.prefs[name] = value


#: C++ standalone projects a process keeps (one per shape of network; the least recently
#: used is deleted when another is needed).
KEPT_PROJECTS = 4
_projects: OrderedDict[tuple, Path] = OrderedDict()


def standalone_root() -> Path:
    """Directory [path] of this process's C++ standalone projects, deleted at exit."""
    root = Path(tempfile.gettempdir()) / "spll-hw-brian2" / f"standalone-{os.getpid()}"
    if not root.exists():
        root.mkdir(parents=True)
        atexit.register(shutil.rmtree, root, ignore_errors=True)
    return root


def standalone_project(shape: tuple) -> Path:
    """Directory [path] of this process's C++ standalone project for networks of ``shape``
    (what the generated code holds as constants: sPLLs, samples, method, recording), created
    on first use and deleted when the interpreter exits. Each process has its own, so parallel
    workers never share one: a forked worker forgets its parent's projects (without deleting
    them). Building another shape in a project would be correct too, only slower (it rewrites
    the code objects)."""
    root = standalone_root()
    for inherited in [k for k, project in _projects.items() if project.parent != root]:
        del _projects[inherited]
    if shape in _projects:
        _projects.move_to_end(shape)
        return _projects[shape]
    while len(_projects) >= KEPT_PROJECTS:
        shutil.rmtree(_projects.popitem(last=False)[1], ignore_errors=True)
    project = Path(tempfile.mkdtemp(dir=root))
    _projects[shape] = project
    return project


def _spike_lists(indices: np.ndarray, times: np.ndarray, n: int) -> list[np.ndarray]:
    """Spike times [s] per neuron, each sorted, from a monitor's flat ``(i, t)`` arrays."""
    order = np.lexsort((times, indices))
    bounds = np.cumsum(np.bincount(indices, minlength=n))[:-1]
    return [np.asarray(x, dtype=float) for x in np.split(times[order], bounds)]


def _collect(model: Brian2Model, n: int, record_spikes: bool) -> dict:
    """Read counts, spike times [s] and whether the final state is finite from the monitors
    and groups (for a standalone run, before its project directory is deleted)."""
    states = (model.cco.v_, model.cco.I_, model.tde.v_, model.tde.I_trg_, model.tde.I_fac_)
    out: dict = {
        "tde_counts": np.asarray(model.tde_monitor.count[:], dtype=np.int64),
        "cco_counts": np.asarray(model.cco_monitor.count[:], dtype=np.int64),
        # per neuron: whether every state variable stayed finite
        "finite": np.all([np.isfinite(np.asarray(state[:])) for state in states], axis=0),
        "tde_spikes": None,
        "cco_spikes": None,
    }
    if record_spikes:
        for key, mon in (("tde_spikes", model.tde_monitor), ("cco_spikes", model.cco_monitor)):
            out[key] = _spike_lists(np.asarray(mon.i[:], dtype=np.int64), np.asarray(mon.t_[:]), n)
    return out


def _run_runtime(b2, target, matrix, inputs, duration, dt, method, record_spikes) -> dict:
    with _preferences(
        b2, codegen__target=target, codegen__runtime__cython__cache_dir=str(cache_dir())
    ):
        start = time.perf_counter()
        model = build(b2, matrix, inputs, dt, method, record_spikes)
        # A state that turns NaN is reported once after the run, not by numpy at every step.
        with np.errstate(all="ignore"):
            model.network.run(duration * b2.second)
        total = time.perf_counter() - start
        run_time = float(b2.device._last_run_time)
        out = _collect(model, matrix.shape[0] * len(inputs), record_spikes)
    out["wall_time"] = run_time
    out["timing"] = {"run": run_time, "setup_and_codegen": total - run_time}
    return out


def _run_standalone(b2, matrix, inputs, duration, dt, method, record_spikes) -> dict:
    from brian2.devices.device import reset_device

    # What the code objects hold as constants, but the input generator's size (the most
    # spikes of a sample in one step, nearly always 1: another rewrites them, as a new shape).
    shape = (matrix.shape[0], len(inputs), method, record_spikes)
    project = standalone_project(shape)
    # No result of an earlier build can be read as this one's.
    shutil.rmtree(project / "results", ignore_errors=True)
    b2.set_device("cpp_standalone", build_on_run=False)
    try:
        with _preferences(b2, devices__cpp_standalone__extra_make_args_unix=[f"-j{MAKE_JOBS}"]):
            # A previous standalone build in this process leaves its objects on the device;
            # once they are collected, Brian2's unique names (``..._codeobject*``) come out as
            # in that build, so the generated files that do not depend on the batch are equal.
            b2.device.reinit()
            gc.collect()
            b2.device.activate(build_on_run=False)
            model = build(b2, matrix, inputs, dt, method, record_spikes)
            model.network.run(duration * b2.second)
            b2.device.build(directory=str(project), compile=True, run=True, with_output=False)
            out = _collect(model, matrix.shape[0] * len(inputs), record_spikes)
            timers = b2.device.timers
            run_time = float(b2.device._last_run_time)
            out["wall_time"] = run_time
            out["timing"] = {
                "run": run_time,
                "compile": float(sum(v or 0.0 for v in timers["compile"].values())),
                "binary": float(timers["run_binary"]),
            }
    finally:
        b2.device.reinit()
        reset_device()
    return out


def simulate_brian2(
    network: Network | SpllParams,
    input_spike_times: Sequence[float] | np.ndarray,
    duration: float,
    dt: float = 10e-6,
    target: str = "numpy",
    method: str = "exact",
    *,
    record_spikes: bool = True,
) -> SimulationResult:
    """Simulate one input spike train through every sPLL of ``network`` in Brian2.

    The network is :mod:`mappings.brian2.model`'s translation of the golden model, advanced in
    steps of ``dt``: an input or threshold crossing inside a step acts at the step's end, and
    spikes are time-stamped with the step's start (Brian2's convention), so spike times are
    within about ``dt`` of the golden model's while every time scale spans many steps.
    Parameters it cannot resolve at this ``dt`` (see :func:`~mappings.brian2.checks.dt_warnings`)
    are listed in ``info["warnings"]`` and raised as :class:`DtResolutionWarning`, as is a
    state that became NaN or infinite.

    Args:
        network: the sPLL network (a bare :class:`SpllParams` is a one-sPLL network).
        input_spike_times: sorted input spike times [s], shape ``(n_spikes,)``; those after
            ``duration`` are ignored.
        duration: run length [s]; Brian2 runs ``info["n_steps"]`` whole steps.
        dt: time step [s].
        target: Brian2 codegen target, one of :data:`TARGETS`.
        method: Brian2 integration method of the neurons (``"exact"``: the linear equations'
            closed-form solution over each step; ``"euler"``, ``"rk4"``, ... also work).
        record_spikes: keep TDE and CCO spike times (counts are always kept).

    Returns:
        A :class:`SimulationResult` with ``backend=f"brian2-{target}"``. ``wall_time`` [s] is the
        time of Brian2's simulation loop only, as Brian2 reports it: for ``numpy`` and
        ``cython`` the wall time of ``Network.run``'s stepping loop (code generation and
        compilation excluded); for ``cpp_standalone`` the CPU time the compiled binary spends
        in its network loop (compilation, process start-up and file I/O excluded).
        ``info["timing"]`` [s] has the other parts: ``setup_and_codegen`` (runtime targets),
        or ``compile`` and ``binary`` (the whole binary process) for ``cpp_standalone``.
        ``info`` also holds ``dt``, ``method``, ``target``, ``n_steps``,
        ``n_input_spikes`` and ``warnings`` (list of str).

    Raises:
        ValueError: unknown target, non-positive ``dt`` or ``duration``, or input spike times
            that are not a sorted 1-D array of finite times >= 0.
        ImportError: Brian2 is not installed (``pip install -e .[brian2]``).
    """
    return simulate_brian2_batch(
        network, [input_spike_times], duration, dt, target, method, record_spikes=record_spikes
    )[0]


def simulate_brian2_batch(
    network: Network | SpllParams,
    inputs: Sequence[Sequence[float] | np.ndarray],
    duration: float,
    dt: float = 10e-6,
    target: str = "numpy",
    method: str = "exact",
    *,
    record_spikes: bool = True,
) -> list[SimulationResult]:
    """:func:`simulate_brian2` of several input trains (samples) in one Brian2 network: each
    sample drives its own copy of the sPLLs (:func:`~mappings.brian2.model.build`), so a batch
    costs one build and one compilation, and every result equals that of the sample alone.

    ``wall_time`` of each result is the batch's run time divided by the number of samples;
    ``info["timing"]`` is the batch's and ``info["batch"]`` its size.
    """
    if target not in TARGETS:
        raise ValueError(f"unknown Brian2 target {target!r}; choose one of {TARGETS}")
    dt, duration = float(dt), float(duration)
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite time step > 0 s, got {dt!r}")
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0 s, got {duration!r}")
    net = Network.single(network) if isinstance(network, SpllParams) else network
    if not isinstance(net, Network):
        raise ValueError(f"expected a Network or SpllParams, got {type(network).__name__}")
    steps_run = n_steps(duration, dt)
    trains = []
    for x in inputs:
        spikes = np.asarray(x, dtype=float)
        if spikes.ndim != 1 or not np.isfinite(spikes).all() or (spikes < 0).any():
            raise ValueError("input_spike_times must be a 1-D array of finite times >= 0 s")
        if (np.diff(spikes) < 0).any():
            raise ValueError("input_spike_times must be sorted")
        trains.append(spikes[spikes < steps_run * dt])
    if not trains:
        return []
    matrix = net.matrix()
    n = matrix.shape[0]
    messages = dt_warnings(matrix, dt, duration, method)

    b2 = import_brian2()
    args = (matrix, trains, duration, dt, method, record_spikes)
    if target == "cpp_standalone":
        out = _run_standalone(b2, *args)
    else:
        out = _run_runtime(b2, target, *args)
    results = []
    for k, spikes in enumerate(trains):
        own = slice(k * n, (k + 1) * n)
        notes = list(messages)
        if not out["finite"][own].all():
            notes.append(
                "the simulated state became NaN or infinite: spike counts are not meaningful"
            )
        results.append(
            SimulationResult(
                tde_counts=out["tde_counts"][own],
                cco_counts=out["cco_counts"][own],
                duration=duration,
                backend=f"brian2-{target}",
                tde_spikes=None if out["tde_spikes"] is None else out["tde_spikes"][own],
                cco_spikes=None if out["cco_spikes"] is None else out["cco_spikes"][own],
                wall_time=out["wall_time"] / len(trains),
                info={
                    "dt": dt,
                    "method": method,
                    "target": target,
                    "n_steps": steps_run,
                    "n_input_spikes": int(spikes.size),
                    "timing": out["timing"],
                    "batch": len(trains),
                    "warnings": notes,
                },
            )
        )
    for message in dict.fromkeys(m for r in results for m in r.info["warnings"]):
        warnings.warn(message, DtResolutionWarning, stacklevel=2)
    return results
