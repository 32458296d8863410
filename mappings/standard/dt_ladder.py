"""The time step of a clocked export of the standard sPLL when ``--dt`` is not given: the
coarsest step of a ladder whose own export check passes, or a refusal that says why none does.

Both targets of the construction choose this way (``spll-hw export --to nir-standard`` in
:mod:`mappings.nir.dt_choice`, ``--to lava-standard`` in :mod:`mappings.lava.dt_choice`); each
passes its steps, its :func:`trial` and its :class:`Parts`: the backend that runs what it would
write at a step (whose declared tolerance is the limit), and what it tells a user about finer
steps and the exact construction. :func:`choose_dt` tries each step with :func:`trial`: the
writer's own refusal where the network is not representable at that step (a
``ValueError`` naming the parameter), else the export's check
(:func:`spll_hw.exporters.check.check_run`: the network's reference inputs, the total
TDE-rate error against the declared tolerance) run from memory by that backend, no folder
written. At each step it tries the gate placements of :data:`EXPORT_PLACEMENTS` in order
(:func:`step_trials`) and returns the first step and placement that pass. The backends'
default placement comes first (levels for 300 Hz Poisson input), then levels on the network's
own band of free-running frequencies: placed for 300 Hz Poisson, a slow sPLL's facilitatory
current at the CCO's spikes stays within one level at the network's lowest frequencies, the
gate passes no phase and its TDEs fall silent (``biotac-time-scaled-lif``; docs/backends.md).
With ``--dt`` the export still chooses the placement (:func:`choose_placement`).

Where none passes, :func:`refusal` names each step's outcome, the worst sPLLs at the finest
step the check ran at, with their ``tau_tde_fac`` and ``tau_tde_trg``, and the error of
**exact integration between steps** (:func:`mappings.standard.reference.simulate_reference`,
golden product gate) of those sPLLs at that step and at the target's finer floor steps:
the clock's own floor, which no construction at that step beats. It says which smaller
``--dt`` the floor allows, or that none of the floor steps does; where the floor is within the
tolerance it blames the construction and gives its 16-level gate's own error
(``standard-exact``, the last placement tried) on those sPLLs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mappings.standard.construction import DEFAULT_PLACEMENT
from spll_hw.backends.base import Backend
from spll_hw.exporters import MemoryCheck
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

#: sPLLs a refusal names.
NAMED = 3


@dataclass(frozen=True)
class Trial:
    """One step of the ladder with one gate placement: the check's total TDE-rate error and
    per-sPLL TDE-count error (``None`` where the writer refused the step, ``reason`` then says
    why), its limit and the check itself (``checked``: the run and report, which the export can
    hand on as the folder's)."""

    dt: float
    error: float | None
    limit: float
    spll_error: np.ndarray | None = None
    reason: str = ""
    checked: MemoryCheck | None = None
    placement: str = DEFAULT_PLACEMENT

    @property
    def passed(self) -> bool:
        return self.error is not None and self.error <= self.limit

    def summary(self) -> str:
        """One line: the check's error against its limit, or why the step was refused."""
        if self.error is None:
            return f"refused ({self.reason.split(';')[0]})"
        verdict = "passes" if self.passed else "fails"
        return f"TDE-rate error {100 * self.error:.1f} %, limit {100 * self.limit:.0f} %: {verdict}"


@dataclass(frozen=True)
class Parts:
    """One export target's parts of the choice (its steps and check are passed beside them).

    Attributes:
        target: the export target (``nir-standard``), first word of every line.
        backend: ``backend(dt, placement)``: the backend that runs what the target writes at
            ``dt`` [s], with the export's gate levels placed by ``placement``; its declared
            tolerance is the limit at ``dt``.
        finer: ``finer(network, dt) -> str``: who runs the finer ``dt`` [s] the floor allows,
            or why none does (said where the floor allows one).
        exact: the exact construction's target, said at the end of every refusal.
        construction: ``construction(network, spll, dt) -> str``: what else of the
            construction than its gate may be off on sPLLs ``spll`` at ``dt`` (an empty
            string for nothing), said where the clock is not the cause.
    """

    target: str
    backend: Callable[[float, str], Backend]
    finer: Callable[[Network, float], str]
    exact: str
    construction: Callable[[Network, np.ndarray, float], str] = lambda network, spll, dt: ""

    def tolerance(self, dt: float) -> float:
        """The declared TDE-rate tolerance at ``dt`` [s]."""
        return float(self.backend(dt, DEFAULT_PLACEMENT).capabilities.rate_tolerance)


#: Gate placements an export tries at each step, in this order (module docstring).
EXPORT_PLACEMENTS = (DEFAULT_PLACEMENT, "band-quantile")


def trial(network: Network, dt: float, placement: str, parts: Parts) -> Trial:
    """The export check of ``network`` as ``parts.target`` would write it at step ``dt`` [s]
    with its gate levels placed by ``placement``, run from memory by ``parts.backend`` (which
    runs the written files spike for spike), no folder written; the backend's own
    ``ValueError`` (the writer's refusal) is the step's reason."""
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run

    backend = parts.backend(dt, placement)
    try:
        backend.prepared(network)  # what would be written, kept for the check's runs
    except ValueError as exc:
        return Trial(dt, None, float("nan"), reason=str(exc), placement=placement)
    run = FolderRun.by_backend(f"{backend.name} at dt = {dt:g} s", backend, network)
    report = check_run(run, parts.target, network)
    return Trial(dt, report.tde_error, report.max_error, report.spll_tde_error,
                 checked=MemoryCheck(run, report), placement=placement)  # fmt: skip


def step_trials(network: Network, dt: float, parts: Parts, trial=trial, log=None) -> list[Trial]:
    """``trial(network, dt, placement, parts)`` (:func:`trial`) of step ``dt`` [s] with each
    placement of :data:`EXPORT_PLACEMENTS` in order, up to the first that passes (or that the
    writer refuses: the step's numbers are refused whatever the placement); ``log(line)``,
    where given, hears each result as it is measured."""
    trials = []
    for placement in EXPORT_PLACEMENTS:
        trials.append(trial(network, dt, placement, parts))
        if log is not None:
            log(f"{parts.target}: dt {dt * 1e6:g} µs, {placement} gate levels: "
                f"{trials[-1].summary()}")  # fmt: skip
        if trials[-1].passed or trials[-1].error is None:
            break
    return trials


def choose_placement(network: Network, dt: float, parts: Parts, trial=trial, log=None) -> Trial:
    """The :class:`Trial` of ``network`` at the user's step ``dt`` [s] (``spll-hw export
    --dt``): the first placement that passes (:func:`step_trials`), else the one with the
    smallest error (the export's check then refuses it unless ``--allow-error``), else the
    writer's refusal."""
    trials = step_trials(network, dt, parts, trial, log)
    checked = [t for t in trials if t.error is not None]
    return min(checked, key=lambda t: t.error) if checked else trials[-1]


def choose_dt(
    network: Network,
    parts: Parts,
    steps: tuple[float, ...],
    floor_steps: tuple[float, ...],
    trial: Callable[[Network, float, str, Parts], Trial] = trial,
    log=None,
) -> Trial:
    """The :class:`Trial` of the coarsest of ``steps`` [s] (coarsest first) that passes with
    one of the placements (:func:`step_trials`: its ``dt``, placement and check);
    ``log(line)``, where given, hears each result as it is measured (a check takes seconds to
    minutes).

    Raises:
        ValueError: :func:`refusal`'s message (exact integration measured down to
            ``floor_steps`` [s]) where none does.
    """
    trials = []
    for dt in steps:
        trials += step_trials(network, dt, parts, trial, log)
        if trials[-1].passed:
            return trials[-1]
    raise ValueError(refusal(network, trials, parts, floor_steps))


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


def floor_errors(
    network: Network, spll: np.ndarray, steps, tolerance: Callable[[float], float]
) -> list[tuple[float, float]]:
    """``(dt, error)``: the TDE-count error (:func:`_count_error`) of exact integration between
    steps of ``dt`` [s] for each of ``steps``, stopping at the first within ``tolerance(dt)``."""
    from mappings.standard.reference import simulate_reference

    out = []
    for dt in steps:
        error = _count_error(
            network, spll, lambda part, trains, T, dt=dt: simulate_reference(
                part, trains, T, (None,), dt=dt)[0],
        )  # fmt: skip
        out.append((dt, error))
        if error <= tolerance(dt):
            break
    return out


def gate_error(network: Network, spll: np.ndarray, levels: int, placement: str) -> float:
    """The TDE-count error (:func:`_count_error`) on sPLLs ``spll`` of the export's gate of
    ``levels`` levels placed by ``placement`` alone: ``standard-exact``, exact in time."""
    from mappings.standard.backend import StandardExact

    gate = StandardExact(levels=levels, placement=placement)
    return _count_error(network, spll, gate.simulate_batch)


def _outcomes(trials: list[Trial]) -> str:
    """Each step's outcome: refused (why) or the check's error with its placement."""
    return ", ".join(
        f"{t.dt * 1e6:g} µs refused ({t.reason.split(';')[0]})"
        if t.error is None
        else f"{t.dt * 1e6:g} µs {100 * t.error:.1f} % ({t.placement} levels)"
        for t in trials
    )


def refusal(network: Network, trials: list[Trial], parts: Parts, floor_steps=()) -> str:
    """Why no step of ``trials`` represents ``network``: each step's outcome, and where the
    check ran, its worst sPLLs and exact integration's error on them at the finest step it ran
    at and at ``floor_steps`` [s] (module docstring)."""
    r = roles()
    last = next((t for t in reversed(trials) if t.error is not None), None)
    limit = parts.tolerance(trials[0].dt) if last is None else last.limit
    text = (
        f"{parts.target}: no time step of "
        f"{', '.join(dict.fromkeys(f'{t.dt * 1e6:g}' for t in trials))} µs "
        f"represents this network within the declared tolerance ({100 * limit:.0f} %); the "
        f"export check's total TDE-rate error: {_outcomes(trials)}"
    )
    if last is None:
        return f"{text}; {parts.exact}"
    worst = np.argsort(-last.spll_error, kind="stable")[:NAMED]
    m = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    named = ", ".join(
        f"{i} (tau_tde_fac {m[r.fac.tau][i] * 1e6:.0f} µs, tau_tde_trg "
        f"{m[r.trg.tau][i] * 1e6:.0f} µs: {100 * last.spll_error[i]:.0f} % off)"
        for i in worst
    )
    floor = floor_errors(network, worst, (last.dt, *floor_steps), parts.tolerance)
    floors = ", ".join(f"{100 * e:.1f} % at {dt * 1e6:g} µs" for dt, e in floor)
    measured = (
        f"{text}. Worst sPLLs at {last.dt * 1e6:g} µs: {named}. Exact integration between steps "
        f"(mappings/standard/reference.py, the golden product as gate) is off on them by "
        f"{floors} (the largest TDE-count error among them)"
    )
    if floor[0][1] <= limit:
        levels = int(parts.backend(last.dt, last.placement).options["levels"])
        gate = gate_error(network, worst, levels, last.placement)
        return (
            f"{measured}, within the tolerance: the clock is not the cause but the construction "
            f"is; its {levels}-level gate alone, exact in time (standard-exact), is off on them "
            f"by {100 * gate:.1f} % on the check's inputs ({last.placement} levels)"
            f"{parts.construction(network, worst, last.dt)}; {parts.exact}"
        )
    fine_dt, fine_error = floor[-1]
    verdict = (
        f"so --dt {fine_dt:g} might pass ({parts.finer(network, fine_dt)})"
        if fine_error <= limit
        else f"so no dt >= {fine_dt * 1e6:g} µs brings them within {100 * limit:.0f} %"
    )
    return f"{measured}: the clock, not the construction, {verdict}; {parts.exact}"
