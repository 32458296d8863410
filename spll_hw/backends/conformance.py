"""The conformance suite: checks that a backend keeps the protocol of
:class:`~spll_hw.backends.base.Backend`, for every registered backend.

Like scikit-learn's ``check_estimator``, a backend gets all of it by registering::

    from spll_hw.backends import conformance

    conformance.check_backend("lava-float")          # AssertionError naming what broke
    for name, check in conformance.checks():          # one pytest case per check
        check(conformance.configure("golden-fixed-point"))

Every check is a function ``check(backend, runs=None)`` taking a configured backend
(:func:`configure`: the spec's options over the backend's ``CONFORMANCE_OPTIONS``). It returns
nothing, raises ``AssertionError`` with a message that names the broken rule, or raises
:class:`NotApplicable` when the backend's capabilities exclude the check (threads on a backend
that has none). ``runs`` is a :class:`Runs`, the simulations the checks share, so that a slow
backend (Lava, Brian2's C++ standalone build) runs each of them once; without it a check makes
its own.

The **reference set** (:func:`reference_set`) is three small networks (a vary-offset, a
time-scaled and a grouped one, 3-4 sPLLs each, resolvable with a 50 µs step) and
:data:`REFERENCE_DURATION` = 0.2 s of four input trains each: Poisson, periodic, a Poisson
train with spikes after the run's end, and an empty one. A backend's agreement with the golden
model is the mean of :func:`~spll_hw.harness.metrics.rate_error` over the samples of this set
whose golden TDE rates are not all zero, against the golden model of the network as the
backend realises it (:meth:`Backend.realised`); it must be at most the declared
``capabilities.rate_tolerance``. A clocked backend is also run on grid-aligned trains
(:func:`grid_trains`: spikes exactly on its step ends) and must put each spike in the step the
model's grid says (:func:`check_input_grid`).

``python -m spll_hw.backends.conformance SPEC ...`` runs every check on each spec and prints
its measured rate errors beside its declared tolerance.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from functools import cache

import numpy as np

from ..config import NetworkConfig
from ..harness.metrics import rate_error
from ..model.grid import mid_step_times, spike_steps
from ..network import Network
from ..result import SimulationResult
from ..simulate import poisson_spikes
from . import backend_class, get, parse_spec
from .base import Backend

#: Run length [s] of every reference sample.
REFERENCE_DURATION = 0.2
#: Phase noise [s] of the determinism checks: large against every step, so a different seed
#: moves spikes on every backend.
NOISE_SIGMA = 1e-3
#: Seed of the phase noise of the shared noisy run.
NOISE_SEED = 7
#: Trains of the first reference network that the batch-versus-serial check runs one by one
#: (one: every call costs a slow backend a process start or a compilation).
SERIAL_TRAINS = (1,)

#: A check: takes a configured backend and optionally the shared :class:`Runs`.
Check = Callable[..., None]


class NotApplicable(Exception):  # noqa: N818 - a verdict, not an error
    """A check that the backend's capabilities exclude (the message says which)."""


@dataclass(frozen=True)
class ReferenceCase:
    """One network of the reference set and its input trains.

    Attributes:
        name: short label (``"vary-offset"``, ...).
        network: the network, 3-4 sPLLs.
        inputs: input spike trains [s], each sorted, shape ``(n_spikes,)``.
        labels: one label per train (``"poisson"``, ``"periodic"``, ``"tail"``, ``"empty"``).
    """

    name: str
    network: Network
    inputs: tuple[np.ndarray, ...]
    labels: tuple[str, ...]

    def index(self, label: str) -> int:
        """Position of the train called ``label``."""
        return self.labels.index(label)


def reference_trains() -> tuple[tuple[str, np.ndarray], ...]:
    """The input trains of every reference network, ``(label, times [s])``: 300 Hz Poisson
    (seed 0), 150 Hz periodic from 3.3 ms, 600 Hz Poisson (seed 1) on 1.5 times the run (a
    third of it after the end) and no spike at all."""
    t = REFERENCE_DURATION
    trains = (
        ("poisson", poisson_spikes(300.0, t, seed=0)),
        ("periodic", np.arange(1 / 300, t, 1 / 150)),
        ("tail", poisson_spikes(600.0, 1.5 * t, seed=1)),
        ("empty", np.empty(0)),
    )
    for _, x in trains:
        x.setflags(write=False)
    return trains


@cache
def reference_set() -> tuple[ReferenceCase, ...]:
    """The networks and trains every backend is checked on (module docstring).

    * ``vary-offset``: ``vibtac-vary-offset-pacinian`` with 4 sPLLs (96-486 Hz);
    * ``time-scaled``: ``vibtac-time-scaled-pacinian`` with 3 sPLLs over 68-150 Hz (the
      preset's 493 Hz top would scale the trigger time constant below 100 µs, two steps of a
      coarse backend);
    * ``grouped``: ``biotac-vary-offset-lif`` as 2 time-scale groups of 4 sPLLs, 50-200 Hz.
    """
    vary = NetworkConfig.preset("vibtac-vary-offset-pacinian").with_n(4)
    scaled = replace(NetworkConfig.preset("vibtac-time-scaled-pacinian"), n=3, f_end=150.0)
    grouped = replace(
        NetworkConfig.preset("biotac-vary-offset-lif"),
        n=4, f_start=50.0, f_end=200.0, layout="grouped:2",
    )  # fmt: skip
    labels, inputs = zip(*reference_trains(), strict=True)
    return tuple(
        ReferenceCase(name, config.build(), inputs, labels)
        for name, config in (("vary-offset", vary), ("time-scaled", scaled), ("grouped", grouped))
    )


def configure(spec: str | Backend) -> Backend:
    """The backend of ``spec`` as the suite runs it: its ``CONFORMANCE_OPTIONS`` (e.g. a
    coarser ``dt`` for a slow runtime) with the spec's own options over them. A
    :class:`Backend` instance is used as it is."""
    if isinstance(spec, Backend):
        return spec
    name, options = parse_spec(spec)
    return get(name, **(dict(backend_class(name).CONFORMANCE_OPTIONS) | options))


class Runs:
    """The simulations the checks of one backend share, each run once on first use.

    Every result list is in the order of the trains it was given; ``duration`` is always
    :data:`REFERENCE_DURATION`. ``cases`` restricts the reference set to those networks (by
    index; the first is always kept, the other checks run on it) for a backend too slow for
    all of them, e.g. one that compiles every call; the checks stay the same.
    """

    def __init__(self, backend: Backend, cases: tuple[int, ...] | None = None) -> None:
        self.backend = backend
        everything = tuple(range(len(reference_set())))
        self.cases = everything if cases is None else tuple(sorted(set(cases) | {0}))
        if not set(self.cases) <= set(everything):
            raise ValueError(f"reference cases {cases} not in {everything}")
        self._memo: dict[tuple, object] = {}

    def _once(self, key: tuple, compute: Callable[[], object]):
        if key not in self._memo:
            self._memo[key] = _quiet(compute)
        return self._memo[key]

    def reference(self, case: int) -> list[SimulationResult]:
        """Every train of reference network ``case`` in one ``simulate_batch``, spikes
        recorded."""
        c = reference_set()[case]
        return self._once(
            ("reference", case),
            lambda: self.backend.simulate_batch(
                c.network, c.inputs, REFERENCE_DURATION, record_spikes=True
            ),
        )

    def golden(self, case: int) -> list[SimulationResult]:
        """The golden model on the same trains, for the network as this backend realises it
        (:meth:`Backend.realised`)."""
        c = reference_set()[case]
        return self._once(
            ("golden", case),
            lambda: get("golden").simulate_batch(
                self.backend.realised(c.network), c.inputs, REFERENCE_DURATION
            ),
        )

    def noisy(self) -> list[SimulationResult]:
        """The first two trains of the first network with :data:`NOISE_SIGMA` phase noise
        drawn from :data:`NOISE_SEED`, spikes recorded."""
        c = reference_set()[0]
        return self._once(
            ("noisy",),
            lambda: self.backend.simulate_batch(
                c.network,
                c.inputs[:2],
                REFERENCE_DURATION,
                noise_sigma=NOISE_SIGMA,
                seed=NOISE_SEED,
                record_spikes=True,
            ),  # fmt: skip
        )

    def call(self, method: str, *args, **kwargs):
        """A fresh ``backend.<method>(*args, **kwargs)``, not kept (for a check that compares
        a second run with a shared one)."""
        return _quiet(lambda: getattr(self.backend, method)(*args, **kwargs))


def _quiet(compute: Callable[[], object]):
    """``compute()`` without warnings: resolution and quantization notes (e.g. Brian2's
    ``DtResolutionWarning``) are a backend's report on its accuracy, which the agreement
    check measures."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return compute()


def _cases(runs: Runs) -> list[tuple[int, ReferenceCase]]:
    """``(index, case)`` of the reference networks ``runs`` covers."""
    return [(k, reference_set()[k]) for k in runs.cases]


def _runs(backend: Backend, runs: Runs | None) -> Runs:
    if runs is None:
        return Runs(backend)
    if runs.backend is not backend:
        raise ValueError(f"runs of {runs.backend!r} given for {backend!r}")
    return runs


# ------------------------------------------------------------------------------ comparisons
def _spike_lists(spikes, n: int, what: str) -> list[np.ndarray]:
    assert spikes is not None, f"{what}: spike times were asked for (record_spikes) but are None"
    assert len(spikes) == n, f"{what}: {len(spikes)} spike lists for {n} sPLLs"
    return [np.asarray(s) for s in spikes]


def _assert_same(a: SimulationResult, b: SimulationResult, what: str) -> None:
    """Identical counts and, where both recorded them, identical spike times."""
    for kind in ("tde", "cco"):
        ca, cb = getattr(a, f"{kind}_counts"), getattr(b, f"{kind}_counts")
        assert np.array_equal(ca, cb), f"{what}: {kind.upper()} counts {list(ca)} != {list(cb)}"
        sa, sb = getattr(a, f"{kind}_spikes"), getattr(b, f"{kind}_spikes")
        if sa is None or sb is None:
            continue
        for i, (x, y) in enumerate(zip(sa, sb, strict=True)):
            if not np.array_equal(x, y):
                k = next(
                    (k for k in range(min(len(x), len(y))) if x[k] != y[k]), min(len(x), len(y))
                )
                raise AssertionError(
                    f"{what}: {kind.upper()} spike times of sPLL {i} differ from spike {k} on"
                    f" ({_at(x, k)} s against {_at(y, k)} s)"
                )


def _at(x: np.ndarray, k: int) -> str:
    return f"{float(x[k])!r}" if k < len(x) else "none"


def _differ(a: SimulationResult, b: SimulationResult) -> bool:
    try:
        _assert_same(a, b, "")
    except AssertionError:
        return True
    return False


# ------------------------------------------------------------------------------ checks
def check_results(backend: Backend, runs: Runs | None = None) -> None:
    """One :class:`SimulationResult` per train in input order, ``tde_counts`` and
    ``cco_counts`` of shape ``(n_spll,)`` with non-negative integers, ``duration`` [s] as
    asked, rates [Hz] = counts / duration, a finite wall time, ``backend`` equal to the
    backend's spec (which :func:`~spll_hw.backends.get` turns back into the same
    configuration), and an empty batch giving an empty list."""
    runs = _runs(backend, runs)
    assert get(backend.spec).spec == backend.spec, (
        f"spec {backend.spec!r} does not recreate the backend: get() gives "
        f"{get(backend.spec).spec!r}"
    )
    for k, case in _cases(runs):
        results = runs.reference(k)
        assert isinstance(results, list) and len(results) == len(case.inputs), (
            f"{case.name}: simulate_batch of {len(case.inputs)} trains returned "
            f"{type(results).__name__} of {len(results)}"
        )
        n = case.network.n_spll
        for label, r in zip(case.labels, results, strict=True):
            what = f"{case.name}/{label}"
            assert isinstance(r, SimulationResult), f"{what}: got {type(r).__name__}"
            for kind in ("tde", "cco"):
                counts = np.asarray(getattr(r, f"{kind}_counts"))
                assert counts.shape == (n,), f"{what}: {kind}_counts has shape {counts.shape}"
                assert np.issubdtype(counts.dtype, np.integer), (
                    f"{what}: {kind}_counts has dtype {counts.dtype}, not integer"
                )
                assert (counts >= 0).all(), f"{what}: negative {kind}_counts {list(counts)}"
                rates = np.asarray(getattr(r, f"{kind}_rates"))
                assert np.allclose(rates, counts / REFERENCE_DURATION, rtol=1e-12, atol=0), (
                    f"{what}: {kind}_rates {list(rates)} Hz are not counts / duration"
                )
            assert r.duration == REFERENCE_DURATION, (
                f"{what}: duration {r.duration!r} s, asked for {REFERENCE_DURATION} s"
            )
            assert r.backend == backend.spec, f"{what}: backend {r.backend!r} != {backend.spec!r}"
            assert math.isfinite(r.wall_time) and r.wall_time >= 0, (
                f"{what}: wall_time {r.wall_time!r}"
            )
            assert isinstance(r.info, dict), f"{what}: info is {type(r.info).__name__}"
    empty = backend.simulate_batch(reference_set()[0].network, [], REFERENCE_DURATION)
    assert empty == [], f"an empty batch returned {empty!r}"


def check_spike_times(backend: Backend, runs: Runs | None = None) -> None:
    """With ``record_spikes``, every sPLL's TDE and CCO spike times [s] are there, 1-D,
    sorted, inside ``[0, duration]`` and as many as its count."""
    runs = _runs(backend, runs)
    for k, case in _cases(runs):
        for label, r in zip(case.labels, runs.reference(k), strict=True):
            for kind in ("tde", "cco"):
                what = f"{case.name}/{label} {kind.upper()}"
                counts = getattr(r, f"{kind}_counts")
                lists = _spike_lists(getattr(r, f"{kind}_spikes"), case.network.n_spll, what)
                for i, s in enumerate(lists):
                    assert s.ndim == 1, f"{what} sPLL {i}: spike times of shape {s.shape}"
                    assert len(s) == counts[i], (
                        f"{what} sPLL {i}: {len(s)} spike times but count {counts[i]}"
                    )
                    if not len(s):
                        continue
                    assert np.all(np.diff(s) >= 0), f"{what} sPLL {i}: spike times not sorted"
                    assert 0 <= s[0] and s[-1] <= REFERENCE_DURATION, (
                        f"{what} sPLL {i}: spike times {float(s[0])!r} .. {float(s[-1])!r} s "
                        f"outside [0, {REFERENCE_DURATION}]"
                    )


def check_seeded_noise(backend: Backend, runs: Runs | None = None) -> None:
    """Phase noise is reproducible: the same seed gives identical results, another seed
    different ones (counts or spike times somewhere)."""
    runs = _runs(backend, runs)
    case = reference_set()[0]
    first = runs.noisy()
    # The same trains as runs.noisy(): a backend that builds per batch shape (C++ standalone)
    # builds once for the three.
    again = runs.call(
        "simulate_batch", case.network, case.inputs[:2], REFERENCE_DURATION,
        noise_sigma=NOISE_SIGMA, seed=NOISE_SEED, record_spikes=True,
    )  # fmt: skip
    for label, a, b in zip(case.labels, first, again, strict=False):
        _assert_same(b, a, f"{case.name}/{label}, noise seed {NOISE_SEED} run twice")
    other = runs.call(
        "simulate_batch", case.network, case.inputs[:2], REFERENCE_DURATION,
        noise_sigma=NOISE_SIGMA, seed=NOISE_SEED + 1, record_spikes=True,
    )  # fmt: skip
    assert _differ(other[0], first[0]), (
        f"{case.name}/{case.labels[0]}: {NOISE_SIGMA} s of phase noise from seeds {NOISE_SEED} "
        f"and {NOISE_SEED + 1} gave identical results: the seed (or the noise) is ignored"
    )


def check_batch_equals_serial(backend: Backend, runs: Runs | None = None) -> None:
    """``simulate_batch`` of several trains equals ``simulate`` of each alone (trains
    :data:`SERIAL_TRAINS` of the first network, spikes recorded)."""
    runs = _runs(backend, runs)
    case = reference_set()[0]
    batch = runs.reference(0)
    for i in SERIAL_TRAINS:
        alone = runs.call("simulate", case.network, case.inputs[i], REFERENCE_DURATION)
        _assert_same(
            alone, batch[i],
            f"{case.name}/{case.labels[i]}: simulate() against sample {i} of simulate_batch()",
        )  # fmt: skip


def check_thread_count(backend: Backend, runs: Runs | None = None) -> None:
    """Results do not depend on the thread count (threads = 1, 3 and all cores, with phase
    noise), for a backend whose capabilities declare threads."""
    if not backend.capabilities.threads:
        raise NotApplicable("capabilities.threads is False: the backend runs on one thread")
    runs = _runs(backend, runs)
    case = reference_set()[0]
    for threads in (1, 3):
        got = runs.call(
            "simulate_batch", case.network, case.inputs[:2], REFERENCE_DURATION,
            noise_sigma=NOISE_SIGMA, seed=NOISE_SEED, threads=threads, record_spikes=True,
        )  # fmt: skip
        for label, a, b in zip(case.labels, got, runs.noisy(), strict=False):
            _assert_same(a, b, f"{case.name}/{label}: threads={threads} against threads=None")


def _bad_calls(backend: Backend) -> list[tuple[str, Callable[[], object]]]:
    """Calls that must raise ``ValueError``: ``(what, call)``."""
    net, t = reference_set()[0].network, REFERENCE_DURATION
    x = reference_set()[0].inputs[0]
    batch, caps = backend.simulate_batch, backend.capabilities
    calls = [
        ("unsorted train", lambda: batch(net, [x[::-1]], t)),
        ("NaN spike time", lambda: batch(net, [[0.01, math.nan, 0.05]], t)),
        ("infinite spike time", lambda: batch(net, [[0.01, math.inf]], t)),
        ("negative spike time", lambda: batch(net, [[-0.01, 0.02]], t)),
        ("2-D train", lambda: batch(net, [np.array([[0.01, 0.02], [0.03, 0.04]])], t)),
        ("bad second train of a batch", lambda: batch(net, [x, [0.02, 0.01]], t)),
        ("unsorted train, simulate()", lambda: backend.simulate(net, x[::-1], t)),
        ("unsorted train, rates()", lambda: backend.rates(net, [x[::-1]], t)),
        ("duration 0", lambda: batch(net, [x], 0.0)),
        ("negative duration", lambda: batch(net, [x], -t)),
        ("NaN duration", lambda: batch(net, [x], math.nan)),
        ("infinite duration", lambda: batch(net, [x], math.inf)),
        ("duration as text", lambda: batch(net, [x], "0.2")),
        ("negative noise_sigma", lambda: batch(net, [x], t, noise_sigma=-1e-3)),
        ("NaN noise_sigma", lambda: batch(net, [x], t, noise_sigma=math.nan)),
        ("threads = 0", lambda: batch(net, [x], t, threads=0)),
        ("a parameter matrix instead of a Network", lambda: batch(net.matrix(), [x], t)),
        ("None instead of a Network", lambda: batch(None, [x], t)),
    ]
    if not caps.resume:
        calls.append(("state without resume", lambda: backend.simulate(net, x, t, state=object())))
    if not caps.probes:
        calls.append(("probe_times without probes",
                      lambda: backend.simulate(net, x, t, probe_times=[0.1])))  # fmt: skip
    return calls


def check_bad_input(backend: Backend, runs: Runs | None = None) -> None:
    """Invalid input raises ``ValueError`` (with a message) before any work: unsorted, NaN,
    infinite or negative spike times, a 2-D train, a bad train anywhere in a batch, a
    duration that is not a finite number > 0, a negative or NaN ``noise_sigma``,
    ``threads=0``, something that is not a Network, and ``state`` / ``probe_times`` on a
    backend that cannot resume / probe."""
    failures = []
    for what, call in _bad_calls(backend):
        try:
            call()
        except ValueError as exc:
            if not str(exc):
                failures.append(f"{what}: ValueError without a message")
        except Exception as exc:  # noqa: BLE001 - any other outcome is the failure reported
            failures.append(f"{what}: raised {type(exc).__name__}: {exc}")
        else:
            failures.append(f"{what}: accepted")
    assert not failures, "bad input not refused with ValueError: " + "; ".join(failures)


def check_rates(backend: Backend, runs: Runs | None = None) -> None:
    """``rates()`` is the TDE rates [Hz] of ``simulate_batch`` (with the same phase noise),
    a float array of shape ``(n_samples, n_spll)``."""
    runs = _runs(backend, runs)
    case = reference_set()[0]
    got = runs.call(
        "rates", case.network, case.inputs[:2], REFERENCE_DURATION,
        noise_sigma=NOISE_SIGMA, seed=NOISE_SEED,
    )  # fmt: skip
    want = np.array([r.tde_rates for r in runs.noisy()])
    assert isinstance(got, np.ndarray) and got.shape == want.shape, (
        f"rates() returned {type(got).__name__} of shape {np.shape(got)}, want {want.shape}"
    )
    assert np.issubdtype(got.dtype, np.floating), f"rates() has dtype {got.dtype}"
    assert np.array_equal(got, want), f"rates() {got.tolist()} != simulate_batch {want.tolist()}"


def grid_trains(dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Two trains every clocked target at step ``dt`` [s] must treat alike: the steps of the
    first reference network's Poisson train with every spike put *on* the step's end
    (``k dt``, one in three an ulp above it, one in three an ulp below), and the same spikes in
    the middle of the steps the model's grid puts them in
    (:func:`spll_hw.model.grid.mid_step_times`)."""
    k = np.unique(spike_steps(reference_set()[0].inputs[0], dt))
    on_ends = k * dt
    on_ends[1::3] = np.nextafter(on_ends[1::3], np.inf)
    on_ends[2::3] = np.nextafter(on_ends[2::3], -np.inf)
    return on_ends, mid_step_times(on_ends, dt)


def check_input_grid(backend: Backend, runs: Runs | None = None) -> None:
    """A clocked backend puts every input spike in the step the model's grid says
    (:mod:`spll_hw.model.grid`): spikes on step ends (:func:`grid_trains`) give the same
    counts and spike times as the same spikes in the middle of the model's steps."""
    dt = backend.capabilities.dt
    if dt is None:
        raise NotApplicable("an exact backend, or a step per sPLL: no one time grid")
    runs = _runs(backend, runs)
    case = reference_set()[0]
    on_ends, mid = grid_trains(dt)
    a, b = runs.call(
        "simulate_batch", case.network, [on_ends, mid], REFERENCE_DURATION, record_spikes=True
    )
    _assert_same(
        a, b,
        f"{case.name}: {on_ends.size} input spikes on step ends (dt = {dt:g} s) against the same "
        "spikes in the middle of the steps the model's grid puts them in",
    )  # fmt: skip


def check_inputs_after_end(backend: Backend, runs: Runs | None = None) -> None:
    """Input spikes after ``duration`` are not delivered: the ``tail`` train gives the same
    result as the train cut at the end, ``info["inputs_after_end"]`` counts the spikes cut
    (absent or 0 when there are none) and ``info["n_input_spikes"]`` the others."""
    runs = _runs(backend, runs)
    t = REFERENCE_DURATION
    for k, case in _cases(runs):
        for label, x, r in zip(case.labels, case.inputs, runs.reference(k), strict=True):
            after = int(np.count_nonzero(x > t))
            what = f"{case.name}/{label}"
            got = r.info.get("inputs_after_end", 0)
            assert got == after, f"{what}: info['inputs_after_end'] = {got}, want {after}"
            assert r.info.get("n_input_spikes") == x.size - after, (
                f"{what}: info['n_input_spikes'] = {r.info.get('n_input_spikes')!r}, want "
                f"{x.size - after}"
            )
    case = reference_set()[0]
    i = case.index("tail")
    assert np.any(case.inputs[i] > t), "the tail train has no spike after the end"
    cut = runs.call(
        "simulate_batch", case.network, [case.inputs[i][case.inputs[i] <= t]], t,
        record_spikes=True,
    )  # fmt: skip
    _assert_same(
        runs.reference(0)[i], cut[0],
        f"{case.name}/tail: with its spikes after {t} s against without them",
    )  # fmt: skip


def rate_errors(backend: Backend, runs: Runs | None = None) -> dict[str, float]:
    """Rate error (:func:`~spll_hw.harness.metrics.rate_error`, relative L1 of the TDE rate
    vector) of every reference sample against the golden model of the network as ``backend``
    realises it, by ``"network/train"``; NaN where the golden TDE rates are all zero."""
    runs = _runs(backend, runs)
    out = {}
    for k, case in _cases(runs):
        for label, r, g in zip(case.labels, runs.reference(k), runs.golden(k), strict=True):
            out[f"{case.name}/{label}"] = rate_error(r, g)
    return out


def check_agrees_with_golden(backend: Backend, runs: Runs | None = None) -> None:
    """The mean rate error over the reference set (:func:`rate_errors`) is at most
    ``capabilities.rate_tolerance``, and where the golden model's TDEs stay silent (no input)
    the backend's do too."""
    runs = _runs(backend, runs)
    errors = rate_errors(backend, runs)
    for k, case in _cases(runs):
        for label, r, g in zip(case.labels, runs.reference(k), runs.golden(k), strict=True):
            if g.tde_counts.sum() == 0:
                assert r.tde_counts.sum() == 0, (
                    f"{case.name}/{label}: TDE counts {list(r.tde_counts)} where the golden "
                    "model has none"
                )
    finite = [e for e in errors.values() if not math.isnan(e)]
    mean = float(np.mean(finite))
    tolerance = backend.capabilities.rate_tolerance
    worst = sorted(errors.items(), key=lambda kv: -np.nan_to_num(kv[1]))[:3]
    assert mean <= tolerance, (
        f"mean rate error {mean:.4f} over {len(finite)} reference samples exceeds the declared "
        f"rate_tolerance {tolerance:.4f}; worst: "
        + ", ".join(f"{name} {e:.4f}" for name, e in worst)
    )


def suite(*functions: Check) -> Callable[[], Iterator[tuple[str, Check]]]:
    """A conformance suite's ``checks()``: each of ``functions`` as ``(name, function)``, in
    order, named by its function's name less ``check_`` (``check_rates``: ``"rates"``), e.g.
    for ``pytest.mark.parametrize``; what :func:`outcomes` runs."""
    named = tuple((function.__name__.removeprefix("check_"), function) for function in functions)

    def checks() -> Iterator[tuple[str, Check]]:
        """Every check as ``(name, function)``, e.g. for ``pytest.mark.parametrize``."""
        yield from named

    return checks


checks = suite(check_results, check_spike_times, check_seeded_noise, check_batch_equals_serial,
               check_thread_count, check_bad_input, check_rates, check_inputs_after_end,
               check_input_grid, check_agrees_with_golden)  # fmt: skip


def check_backend(spec: str | Backend, cases: tuple[int, ...] | None = None) -> dict[str, str]:
    """Run every check on ``spec`` (configured by :func:`configure`), sharing one
    :class:`Runs` (on the reference networks ``cases``, default all).

    Returns:
        ``{check name: "passed" or "not applicable: <why>"}``.

    Raises:
        AssertionError: listing every check that failed and why.
    """
    backend = configure(spec)
    runs = Runs(backend, cases)
    return passed(f"backend {backend.spec!r}", checks(), lambda check: check(backend, runs))


def outcomes(named: Iterator[tuple[str, Callable]], call: Callable) -> tuple[dict, dict]:
    """Run every ``(name, check)`` of ``named`` as ``call(check)``.

    Returns:
        ``({name: "passed" or "not applicable: <why>"}, {name: why it failed})``.
    """
    done, failed = {}, {}
    for name, check in named:
        try:
            call(check)
        except NotApplicable as exc:
            done[name] = f"not applicable: {exc}"
        except AssertionError as exc:
            failed[name] = str(exc)
        else:
            done[name] = "passed"
    return done, failed


def passed(what: str, named: Iterator[tuple[str, Callable]], call: Callable) -> dict[str, str]:
    """:func:`outcomes` of ``named`` where every check passed or does not apply, else
    ``AssertionError`` naming ``what`` and listing every check that failed and why."""
    done, failed = outcomes(named, call)
    if failed:
        raise AssertionError(f"{what} fails: " + " | ".join(f"{k}: {v}" for k, v in failed.items()))
    return done


def print_outcomes(prefix: str, done: dict, failed: dict) -> None:
    """Print each check's outcome of :func:`outcomes`, one line each, after ``prefix``."""
    for name in (*done, *failed):
        line = f"FAILED: {failed[name]}" if name in failed else done[name]
        print(f"{prefix}{name}: {line}")


def main(argv: list[str] | None = None) -> int:
    """``python -m spll_hw.backends.conformance SPEC ...``: check each spec and print its
    rate errors on the reference set beside its declared tolerance."""
    parser = argparse.ArgumentParser(description="conformance suite of spll-hw backends")
    parser.add_argument("specs", nargs="+", help="backend specs, e.g. golden-fixed-point")
    parser.add_argument("--errors-only", action="store_true", help="only measure the rate errors")
    args = parser.parse_args(argv)
    failed = 0
    for spec in args.specs:
        backend = configure(spec)
        runs = Runs(backend)
        errors = rate_errors(backend, runs)
        finite = [e for e in errors.values() if not math.isnan(e)]
        print(
            f"{backend.spec}: rate error mean {np.mean(finite):.4f}, max {np.max(finite):.4f} "
            f"(declared tolerance {backend.capabilities.rate_tolerance:.4f})"
        )
        print("  " + ", ".join(f"{k} {v:.4f}" for k, v in errors.items() if not math.isnan(v)))
        if args.errors_only:
            continue
        done, failures = outcomes(checks(), lambda check: check(backend, runs))  # noqa: B023
        print_outcomes("  ", done, failures)
        failed += len(failures)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
