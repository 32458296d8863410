"""The time step of ``spll-hw export --to nir-standard`` when ``--dt`` is not given: the coarsest
of :data:`LADDER` whose own export check passes, or a refusal that says why none does.

A clocked consumer's error against the golden model falls with ``dt`` (spikes on step ends,
refractory holds of whole steps, the gate reading ``I_fac`` on the step grid), and how fast
depends on the network: the vary-offset presets pass at 100 µs, the time-scaled ones, whose
fastest sPLLs have ``tau_tde_fac`` and ``tau_tde_trg`` of 85-500 µs and TDEs that fire every
few steps, need 20 µs or less, and ``vibtac-time-scaled-peak`` (about 15 TDE spikes per sPLL
and second) is off by more than the tolerance even with exact integration between steps of
2 µs. :func:`choose_dt` tries each step of :data:`LADDER` with the export's own check
(:func:`spll_hw.exporters.check.check_folder`: the network's reference inputs, the total
TDE-rate error against the declared tolerance at that step) and returns the first that
passes, trying at each step the gate placements of
:data:`~mappings.nir.standard.EXPORT_PLACEMENTS` in order (:func:`step_trials`: levels placed
for 300 Hz Poisson are too coarse for slow sPLLs at a network's lowest frequencies, those on
the network's band are not). snnTorch runs only 100 µs
(:func:`~mappings.nir.consumers.support`), so a graph of a finer step names Norse and the
numpy executor as its consumers.

Where no step of the ladder passes, :func:`refusal` names the worst sPLLs with their
``tau_tde_fac`` and ``tau_tde_trg``, the check's error at every step and the error of **exact
integration between steps** (:func:`mappings.standard.reference.simulate_reference`, golden
product gate) of those sPLLs at the finest step and below it (:data:`FLOOR_STEPS`): the clock's
own floor, which no construction at that step beats. It says which smaller ``--dt`` the floor
allows, or that none of :data:`FLOOR_STEPS` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

from .standard import EXPORT_LEVELS, EXPORT_PLACEMENTS, TARGET

#: Time steps [s] the export tries, coarsest first (snnTorch's 100 µs first).
LADDER = (1e-4, 5e-5, 2e-5, 1e-5)
#: Finer steps [s] at which a refusal measures exact integration's own error.
FLOOR_STEPS = (5e-6, 2e-6, 1e-6)
#: sPLLs a refusal names.
NAMED = 3


@dataclass(frozen=True)
class Trial:
    """One step of the ladder with one gate placement: the check's total TDE-rate error and
    per-sPLL TDE-count error (``None`` where the graph was refused, ``reason`` then says why)
    and its limit."""

    dt: float
    error: float | None
    limit: float
    spll_error: np.ndarray | None = None
    reason: str = ""
    placement: str = EXPORT_PLACEMENTS[0]

    @property
    def passed(self) -> bool:
        return self.error is not None and self.error <= self.limit

    def summary(self) -> str:
        """One line: the check's error against its limit, or why the step was refused."""
        if self.error is None:
            return f"refused ({self.reason.split(';')[0]})"
        verdict = "passes" if self.passed else "fails"
        return f"TDE-rate error {100 * self.error:.1f} %, limit {100 * self.limit:.0f} %: {verdict}"


def trial(network: Network, dt: float, placement: str = EXPORT_PLACEMENTS[0]) -> Trial:
    """The export check of ``network`` as it would be written at step ``dt`` [s] (with
    :data:`~mappings.nir.standard.EXPORT_LEVELS` gate levels placed by ``placement``), run
    from memory by the backend that runs the written graph spike for spike (``nir-numpy``), no
    folder written."""
    from mappings.standard.backend import NirNumpy
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run

    backend = NirNumpy(dt=dt, levels=EXPORT_LEVELS, placement=placement)
    try:
        backend.prepared(network)  # the graph, kept for the check's runs
    except ValueError as exc:
        return Trial(dt, None, float("nan"), reason=str(exc), placement=placement)
    run = FolderRun.by_backend(f"nir-numpy at dt = {dt:g} s", backend, network)
    report = check_run(run, TARGET, network)
    return Trial(dt, report.tde_error, report.max_error, report.spll_tde_error,
                 placement=placement)  # fmt: skip


def step_trials(network: Network, dt: float, log=None) -> list[Trial]:
    """:func:`trial` of step ``dt`` [s] with each placement of
    :data:`~mappings.nir.standard.EXPORT_PLACEMENTS` in order, up to the first that passes;
    ``log(line)``, where given, hears each result as it is measured."""
    trials = []
    for placement in EXPORT_PLACEMENTS:
        trials.append(trial(network, dt, placement))
        if log is not None:
            log(f"{TARGET}: dt {dt * 1e6:g} µs, {placement} gate levels: {trials[-1].summary()}")
        if trials[-1].passed or trials[-1].error is None:  # a refused step is refused by all
            break
    return trials


def choose_placement(network: Network, dt: float, log=None) -> str:
    """The first gate placement of :data:`~mappings.nir.standard.EXPORT_PLACEMENTS` whose
    export check passes at step ``dt`` [s] (``spll-hw export --dt``), the first where none
    does (the export's own check then refuses it)."""
    last = step_trials(network, dt, log)[-1]
    return last.placement if last.passed else EXPORT_PLACEMENTS[0]


def choose_dt(network: Network, log=None) -> tuple[float, str]:
    """The coarsest step [s] of :data:`LADDER` whose export check passes with one of the gate
    placements (:func:`step_trials`), and that placement; ``log(line)``, where given, hears
    each result as it is measured (a check takes seconds to minutes).

    Raises:
        ValueError: :func:`refusal`'s message where none does.
    """
    trials = []
    for dt in LADDER:
        trials += step_trials(network, dt, log)
        if trials[-1].passed:
            return dt, trials[-1].placement
    raise ValueError(refusal(network, trials))


def _count_error(network: Network, spll: np.ndarray, run) -> float:
    """The largest TDE-count error among sPLLs ``spll`` of ``network`` over the check's
    reference inputs (all inputs' counts summed per sPLL, as the check counts them) of
    ``run(part, trains, duration) -> results`` against golden."""
    from spll_hw import simulate_batch
    from spll_hw.exporters.check import reference_inputs

    inputs = reference_inputs(network)
    part = Network(tuple(network.spll[int(i)] for i in spll))
    trains = [x.spikes for x in inputs]
    duration = inputs[0].duration
    golden = np.array([g.tde_counts for g in simulate_batch(part, trains, duration)])
    counts = np.array([r.tde_counts for r in run(part, trains, duration)])
    return float(np.max(np.abs(counts - golden).sum(0) / np.maximum(golden.sum(0), 1)))


def floor_errors(network: Network, spll: np.ndarray, steps) -> list[tuple[float, float]]:
    """``(dt, error)``: the TDE-count error (:func:`_count_error`) of exact integration between
    steps of ``dt`` [s] for each of ``steps``, stopping at the first within the tolerance at
    that step."""
    from mappings.standard.backend import NirNumpy
    from mappings.standard.reference import simulate_reference

    out = []
    for dt in steps:
        error = _count_error(
            network, spll, lambda part, trains, T, dt=dt: simulate_reference(
                part, trains, T, (None,), dt=dt)[0],
        )  # fmt: skip
        out.append((dt, error))
        if error <= NirNumpy(dt=dt).capabilities.rate_tolerance:
            break
    return out


def gate_error(network: Network, spll: np.ndarray, placement: str) -> float:
    """The TDE-count error (:func:`_count_error`) of the export's gate alone: ``standard-exact``
    with :data:`~mappings.nir.standard.EXPORT_LEVELS` levels placed by ``placement``, exact in
    time."""
    from mappings.standard.backend import StandardExact

    gate = StandardExact(levels=EXPORT_LEVELS, placement=placement)
    return _count_error(network, spll, gate.simulate_batch)


def refusal(network: Network, trials: list[Trial]) -> str:
    """Why no step of ``trials`` (:func:`step_trials` of each step of :data:`LADDER`)
    represents ``network``."""
    r = roles()
    last = next((t for t in reversed(trials) if t.error is not None), None)
    tried = ", ".join(
        f"{t.dt * 1e6:g} µs refused ({t.reason.split(';')[0]})"
        if t.error is None
        else f"{t.dt * 1e6:g} µs {100 * t.error:.1f} % ({t.placement} levels)"
        for t in trials
    )
    steps = ", ".join(dict.fromkeys(f"{t.dt * 1e6:g}" for t in trials))
    text = (
        f"{TARGET}: no time step of {steps} µs represents "
        f"this network within the declared tolerance ({100 * trials[0].limit:.0f} %); the "
        f"export check's total TDE-rate error: {tried}"
    )
    if last is None:
        return text
    worst = np.argsort(-last.spll_error, kind="stable")[:NAMED]
    m = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    named = ", ".join(
        f"{i} (tau_tde_fac {m[r.fac.tau][i] * 1e6:.0f} µs, tau_tde_trg "
        f"{m[r.trg.tau][i] * 1e6:.0f} µs: {100 * last.spll_error[i]:.0f} % off)"
        for i in worst
    )
    floor = floor_errors(network, worst, (last.dt, *FLOOR_STEPS))
    floors = ", ".join(f"{100 * e:.1f} % at {dt * 1e6:g} µs" for dt, e in floor)
    limit = last.limit
    measured = (
        f"{text}. Worst sPLLs at {last.dt * 1e6:g} µs: {named}. Exact integration between steps "
        f"(mappings/standard/reference.py, the golden product as gate) is off on them by "
        f"{floors} (the largest TDE-count error of the three)"
    )
    exact = "; --to nir writes the exact sPLL (run by spll-hw's NIR reader)"
    if floor[0][1] <= limit:
        gate = gate_error(network, worst, last.placement)
        return (
            f"{measured}, within the tolerance: the clock is not the cause but the construction "
            f"is; its {EXPORT_LEVELS}-level gate alone, exact in time (standard-exact), is off on "
            f"them by {100 * gate:.1f} % on the check's inputs ({last.placement} levels){exact}"
        )
    fine_dt, fine_error = floor[-1]
    verdict = (
        f"so --dt {fine_dt:g} might pass (Norse and nir-numpy run any dt; snnTorch only 1e-4 s)"
        if fine_error <= limit
        else f"so no dt >= {FLOOR_STEPS[-1] * 1e6:g} µs brings them within {100 * limit:.0f} %"
    )
    return f"{measured}: the clock, not the construction, {verdict}{exact}"
