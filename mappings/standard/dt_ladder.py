"""The time step of a clocked export of the standard sPLL when ``--dt`` is not given: the
coarsest step of a ladder whose own export check passes, or a refusal that says why none does.

Both targets of the construction choose this way (``spll-hw export --to nir-standard`` in
:mod:`mappings.nir.dt_choice`, ``--to lava-standard`` in :mod:`mappings.lava.dt_choice`); each
passes its steps, its :func:`trial` and its :class:`Parts`: the backend that runs what it would
write at a step (whose declared tolerance is the limit), and what it tells a user about finer
steps and the exact construction. :func:`choose_dt` tries each step with :func:`trial`: the
writer's own refusal where the network is not representable at that step (a ``ValueError``
naming the parameter), else the export's check (:func:`spll_hw.exporters.check.check_run`: the
network's reference inputs, the total TDE-rate error against the declared tolerance, or against
the user's limit where given: ``spll-hw export --max-error``, :func:`judged`; inputs of
``spll-hw export --check-duration``, 1 s by default, for this and every other check below) run
from memory by that backend, no folder written, and where none passes the target's last rungs in
order (:attr:`Parts.last`: Lava's clock per sPLL, then that clock with graded CCO currents). At
each step it tries the gates of :data:`EXPORT_GATES` in order, with each of the target's
refractory holds (:attr:`Parts.holds`: Lava's dithered hold after its compensated one;
:func:`step_trials`) and returns the first step, hold and gate that pass; where a hold's first
gate fails at a step at which exact integration between steps (:func:`floor_check`, seconds) is
itself beyond the limit, its other gates are not tried there, unless the user keeps the closest
of a failing ladder (``--allow-error``, below; on ``vibtac-time-scaled-peak`` the NIR ladder
then writes 1 µs in 330 s instead of 647 s). The backends' default placement comes first (levels
for 300 Hz Poisson input), then levels on the network's own band of free-running frequencies:
placed for 300 Hz Poisson, a slow sPLL's facilitatory current at the CCO's spikes stays within
one level at the network's lowest frequencies, the gate passes no phase and its TDEs fall silent
(``biotac-time-scaled-lif``; docs/backends.md); last, twice as many levels on that band
(:data:`FINE_LEVELS`: a staircase half as coarse, at twice the level and AND neurons). With
``--dt`` the export still chooses the gate (:func:`choose_placement`). Where no step passes but
the user keeps an export whose check fails (``--allow-error``), it returns the trial whose check
came closest to golden (the smallest error of those the writer represents: on Loihi's integers
the finest step is not always the closest), with a note for the folder's README
(:attr:`Trial.note`).

Each check runs on 1 s of each reference input unless the user gives another length
(``--check-duration``). On 1 s, golden itself moves by more than half a 7 % limit on three
presets when its inputs move 0.5 ms (the check's resolution), so a verdict there may be
golden's own variation: :func:`judge_by` checks such a step again on :data:`LONGER` (10 s)
where that resolves the limit, and judges it by that, pass or fail (``biotac-vary-offset-peak`` and
``-time-scaled-peak`` then pass lava-standard's first rung, 50 µs, instead of 10 µs and a clock
per sPLL; docs/backends.md, "The step chosen on 10 s").

The ladder stops where finer steps stop helping (:func:`stalled`): where
:data:`STALLED_STEPS` successive steps come no closer to golden than the best step before them,
the finer ones are not tried and the refusal (or ``--allow-error``'s note) says which, so a
network that no step represents is refused in a minute, not after an hour of checks down to
1 µs (a 50-sPLL time-scaled network with the vary-offset preset's sPLLs: 100 % off at 100,
50 and 20 µs with its first gate, 57 % at 10 and 5 µs with its last; refused after 23 s instead
of running past 1200 s). A user's limit that lies below golden's own resolution on the
check's inputs (``--max-error 0``, say) is refused before any step is tried
(:func:`refuse_unjudgeable`).

Where none passes, :func:`refusal` names each step's outcome and the worst sPLLs at the finest
step the check ran at, with their ``tau_tde_fac`` and ``tau_tde_trg``, and measures the clock's
own floor, which no construction at that step beats: **exact integration between steps**
(:func:`mappings.standard.reference.simulate_reference`, golden product gate, the NIR graph's
refractory holds of ``round(t_refr/dt - 1/2)`` steps, :data:`FLOOR_HOLD`) checked as the export
is (:func:`floor_check`: the check's total TDE-rate error on the whole network, the metric its
limit judges, beside each named sPLL's own error) at that step and at the target's finer floor
steps. Where that total exceeds the limit it blames the clock and says which smaller ``--dt``
the floor allows, or that none of the floor steps does; where it is within, it blames the
construction and gives its 16-level gate's own error (``standard-exact``, the last placement
tried) on the worst sPLLs (both targets hold as the floor does). A worst sPLL's own error is no
floor: it is above the total by construction, and on a periodic train at that sPLL's own free
frequency (the check's highest) it follows the clocked CCO's whole-step period (at 10 µs
``biotac-time-scaled-peak``'s fastest CCO runs at 495 Hz instead of 497 Hz, and its TDE count
on the 497 Hz train is 910 instead of golden's 298; 228 at 5 µs)."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cache, partial
from pathlib import Path

import numpy as np

from mappings.standard.construction import DEFAULT_PLACEMENT, Gate
from spll_hw.backends.base import Backend
from spll_hw.exporters import MemoryCheck
from spll_hw.exporters.check import (
    DURATION,
    LONGER,
    RESOLUTION_SHIFT,
    golden_resolution,
    reference_duration,
)
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
    hand on as the folder's); its gate: ``levels`` placed by ``placement`` (``None``: the
    target's export levels); ``note``: why it is written although its check fails
    (:func:`choose_dt` with ``allow_error``), for the folder's README, else empty; ``hold``:
    the target's refractory hold (``None``: its only or default one); ``clock``: where it has
    a clock per sPLL instead of one step (:attr:`Parts.last`), that clock in words, ``dt``
    then NaN."""

    dt: float
    error: float | None
    limit: float
    spll_error: np.ndarray | None = None
    reason: str = ""
    checked: MemoryCheck | None = None
    placement: str = DEFAULT_PLACEMENT
    note: str = ""
    levels: int | None = None
    hold: str | None = None
    clock: str = ""

    @property
    def where(self) -> str:
        """Its step in words (``50 µs``), or its :attr:`clock` where it has no one step."""
        return self.clock or f"{self.dt * 1e6:g} µs"

    @property
    def gate(self) -> str:
        """Its gate in words: ``band-quantile`` or ``32 band-quantile`` (levels)."""
        return gate_words(self.placement, self.levels)

    @property
    def variant(self) -> str:
        """Its gate and hold in words: ``32 band-quantile gate levels, dithered hold``."""
        return f"{self.gate} gate levels{self.held}"

    @property
    def held(self) -> str:
        """Its hold in words after a comma (``, dithered hold``), or nothing where it is the
        target's default."""
        return f", {self.hold} hold" if self.hold else ""

    @property
    def passed(self) -> bool:
        return self.error is not None and self.error <= self.limit

    @property
    def on(self) -> str:
        """The length of its check's reference inputs in words where it is not the default's
        (`` on 10 s``), else nothing."""
        if self.checked is None:
            return ""
        duration = reference_duration(self.checked.report.trains)
        return "" if duration == DURATION else f" on {duration:g} s"

    def summary(self) -> str:
        """One line: the check's error against its limit, or why the step was refused."""
        if self.error is None:
            return f"refused ({self.reason.split(';')[0]})"
        verdict = "passes" if self.passed else "fails"
        return (f"TDE-rate error {100 * self.error:.1f} %{self.on}, limit {_pct(self.limit)}: "
                f"{verdict}")  # fmt: skip

    def readme(self, text: str) -> str:
        """The export's README ``text`` with :attr:`note` (``note``: why this step was
        written although its check fails, ``--allow-error``) as its last section."""
        return f"{text.rstrip()}\n\n## Time step\n\n{self.note}\n" if self.note else text


@dataclass(frozen=True)
class Parts:
    """One export target's parts of the choice (its steps and check are passed beside them).

    Attributes:
        target: the export target (``nir-standard``), first word of every line.
        backend: ``backend(dt, placement, levels=None, hold=None)``: the backend that runs
            what the target writes at ``dt`` [s], with ``levels`` gate levels (``None``: the
            target's export levels) placed by ``placement`` and refractory hold ``hold``
            (``None``: its default); its declared tolerance is the limit at ``dt``.
        finer: ``finer(network, dt) -> str``: who runs the finer ``dt`` [s] the floor allows,
            or why none does (said where the floor allows one).
        exact: the exact construction's target, said at the end of every refusal.
        construction: ``construction(network, spll, dt) -> str``: what else of the
            construction than its gate may be off on sPLLs ``spll`` at ``dt`` (an empty
            string for nothing), said where the clock is not the cause.
        holds: the refractory holds tried at each step, in order, each with every gate
            (``None``: the backend's default).
        last: the last rungs, each ``rung(network, duration=...) -> Trial`` (checked on
            reference inputs of ``duration`` [s]), tried in order where no step
            passes: a :class:`Trial` with a :attr:`~Trial.clock` (:func:`backend_trial` of
            the backend that runs what the target writes with it).
    """

    target: str
    backend: Callable[..., Backend]
    finer: Callable[[Network, float], str]
    exact: str
    construction: Callable[[Network, np.ndarray, float], str] = lambda network, spll, dt: ""
    holds: tuple[str | None, ...] = (None,)
    last: tuple[Callable[[Network], Trial], ...] = ()

    def tolerance(self, dt: float) -> float:
        """The declared TDE-rate tolerance at ``dt`` [s]."""
        return float(self.backend(dt, DEFAULT_PLACEMENT).capabilities.rate_tolerance)


#: Gate levels of the ladder's last gate at each step: twice the targets' 16, which took
#: ``biotac-tuned-time-scaled-lif`` (10 µs) and ``vibtac-time-scaled-lif`` (25 µs) within
#: lava-standard's 7 % (docs/backends.md).
FINE_LEVELS = 32
#: Gates an export tries at each step, in this order (module docstring): ``(placement,
#: levels)``, levels ``None`` for the target's export levels.
EXPORT_GATES = ((DEFAULT_PLACEMENT, None), ("band-quantile", None), ("band-quantile", FINE_LEVELS))


def gate_words(placement: str, levels: int | None) -> str:
    """A gate in words: its placement, after its number of levels where it is not the
    target's export levels (``levels`` not ``None``)."""
    return placement if levels is None else f"{levels} {placement}"


def more_levels(levels: int, builder: str, export_levels: int) -> str:
    """The remedy a failed check of a folder with ``levels`` gate levels names: more levels
    (``builder``, the target's writer, with twice as many) or a gate the ladder does not try
    (:data:`EXPORT_GATES` in words, ``export_levels`` the target's own)."""
    tried = ", then ".join(f"{export_levels if k is None else k} {p}" for p, k in EXPORT_GATES)
    return (
        f"more gate levels than {levels} ({builder}(network, levels={2 * levels})) or a gate "
        f"placement the export does not try (it tries {tried} levels: uniform places them for "
        "300 Hz, band-quantile on the network's band, gate_levels' 'quantile' for one rate)"
    )


def trial(
    network: Network,
    dt: float,
    placement: str,
    parts: Parts,
    levels: int | None = None,
    hold: str | None = None,
    duration: float = DURATION,
) -> Trial:
    """The export check of ``network`` as ``parts.target`` would write it at step ``dt`` [s]
    with ``levels`` gate levels (``None``: its export levels) placed by ``placement`` and
    refractory hold ``hold`` (``None``: its default), run from memory by ``parts.backend``
    (which runs the written files spike for spike) on reference inputs of ``duration`` [s],
    no folder written; the backend's own ``ValueError`` (the writer's refusal) is the step's
    reason."""
    backend = parts.backend(dt, placement, levels, hold)
    base = Trial(dt, None, float("nan"), placement=placement, levels=levels, hold=hold)
    return backend_trial(network, backend, parts.target, base, f"dt = {dt:g} s", duration)


def backend_trial(
    network: Network,
    backend: Backend,
    target: str,
    base: Trial,
    at: str,
    duration: float = DURATION,
) -> Trial:
    """``base`` (its step, gate and hold) with the export check of ``network`` (reference
    inputs of ``duration`` [s]) as ``backend`` runs what ``target`` would write (``at``: its
    step in words), or the backend's own ``ValueError`` (the writer's refusal) as its
    reason."""
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run

    try:
        backend.prepared(network)  # what would be written, kept for the check's runs
    except ValueError as exc:
        return replace(base, reason=str(exc))
    run = FolderRun.by_backend(f"{backend.name} at {at}", backend, network)
    report = check_run(run, target, network, duration=duration)
    return replace(base, error=report.tde_error, limit=report.max_error,
                   spll_error=report.spll_tde_error, checked=MemoryCheck(run, report))  # fmt: skip


#: A target's trial: ``trial(network, dt, placement, levels, hold, duration)``, :func:`trial`
#: with its own :class:`Parts`.
TargetTrial = Callable[[Network, float, str, int | None, str | None, float], Trial]


def step_trials(
    network: Network,
    dt: float,
    parts: Parts,
    trial: TargetTrial,
    log,
    judge: Judge,
    floor_of: Callable[[float], Floor] | None = None,
) -> list[Trial]:
    """``trial(network, dt, placement, levels, hold, duration)`` (the target's :func:`trial`)
    of step ``dt`` [s] with each gate of :data:`EXPORT_GATES` in order, with each of
    ``parts.holds`` in turn (every gate with the first, then with the next), checked and judged
    by ``judge`` (:func:`judge_by`), up to the first that passes (or that the writer
    refuses: the step's numbers are refused whatever the gate); ``log(line)``, where given, hears
    each result as it is measured.

    With ``floor_of`` (``floor_of(dt) -> Floor``, :func:`floor_check` of the network, the ladder's),
    a hold whose first gate fails skips its other gates where exact integration at ``dt`` is
    itself beyond the limit: the clock more than the gate is then the cause, and a finer step
    is tried sooner (a gate that passes by cancellation there is missed: on none of the
    presets, docs/backends.md)."""
    trials = []
    for hold in parts.holds:
        for placement, levels in EXPORT_GATES:
            trials.append(judge(partial(trial, network, dt, placement, levels, hold)))
            last = trials[-1]
            if log is not None:
                log(f"{parts.target}: dt {dt * 1e6:g} µs, {last.variant}: {last.summary()}")
            if last.passed or last.error is None:
                return trials
            if floor_of is not None and (exact := floor_of(dt).error) > last.limit:
                if log is not None:
                    held = f" with the {last.hold} hold" if last.hold else ""
                    log(f"{parts.target}: dt {dt * 1e6:g} µs: exact integration between steps "
                        f"is {_pct(exact)} off, beyond the limit; the other gates{held} are "
                        "not tried")  # fmt: skip
                break
    return trials


def choose_placement(
    network: Network,
    dt: float,
    parts: Parts,
    trial: TargetTrial,
    log=None,
    max_error=None,
    duration: float | None = None,
) -> Trial:
    """The :class:`Trial` of ``network`` at the user's step ``dt`` [s] (``spll-hw export
    --dt``): the first placement that passes within ``max_error`` (:func:`step_trials`, each
    check on reference inputs of ``duration`` [s], ``None``: as :func:`judge_by` says), else
    the one with the smallest error (the export's check then refuses it unless
    ``--allow-error``), else the writer's refusal."""
    refuse_unjudgeable(network, parts.target, max_error, duration)
    judge = judge_by(network, parts.target, max_error, duration, log)
    trials = step_trials(network, dt, parts, trial, log, judge)
    checked = [t for t in trials if t.error is not None]
    return min(checked, key=lambda t: t.error) if checked else trials[-1]


def refuse_unjudgeable(
    network: Network, target: str, max_error: float | None, duration: float | None
) -> None:
    """``ValueError`` before any check where the user's limit ``max_error`` lies below
    golden's own resolution on the check's inputs (its total TDE-rate error on every input
    :data:`~spll_hw.exporters.check.RESOLUTION_SHIFT` later, golden alone, seconds): no check
    can tell an export within it from golden's own variation, so no step would pass and the
    ladder would try every one for nothing. The inputs are ``duration`` [s] long (``None``:
    1 s, and where 1 s does not resolve the limit, :data:`LONGER` s, on which the ladder
    judges such a verdict again, :func:`judge_by`); a limit of 0 asks for golden's counts
    exactly, refused where golden itself does not keep them on 1 s."""
    if max_error is None:
        return
    inputs = DURATION if duration is None else duration
    resolution = golden_resolution(network, inputs)
    if max_error >= resolution:
        return
    moved = (f"golden itself, on every input {1e3 * RESOLUTION_SHIFT:g} ms later, is "
             f"{_pct(resolution)} off golden on the check's inputs of {inputs:g} s")  # fmt: skip
    least = resolution
    if duration is None and max_error > 0:
        longer = golden_resolution(network, LONGER)
        if max_error >= longer:
            return
        moved += f" and {_pct(longer)} on {LONGER:g} s"
        least = min(resolution, longer)
    if max_error == 0:
        asks = "asks for golden's counts exactly, which golden does not keep itself"
    else:
        asks = (f"({_pct(max_error)}) lies below golden's own resolution, so no check can "
                "tell an export within it from golden's own variation")  # fmt: skip
    raise ValueError(
        f"{target}: --max-error {max_error:g} {asks}: {moved}. No export would pass (checked "
        f"before any step was tried); give --max-error {math.ceil(least * 1e3) / 1e3:g} or "
        "more, or --to nir, the exact sPLL, which a limit of 0 judges"
    )


#: Successive finer steps of the ladder that come no closer to golden than the best step so
#: far, after which it stops (:func:`stalled`): finer steps have stopped helping.
STALLED_STEPS = 2


def stalled(trials: list[Trial], left: tuple[float, ...]) -> str:
    """Where the last :data:`STALLED_STEPS` steps checked (``trials``, each step's best gate;
    refused steps and clocks per sPLL aside) came no closer to golden than the best step
    before them and finer steps ``left`` [s] of the ladder are still to try, the sentence that
    says so and names those; else nothing. A network that no step represents (every rung
    57-100 % off) is refused in a minute instead of checked down to 1 µs for an hour."""
    best: dict[float, float] = {}
    for t in trials:
        if t.error is not None and not t.clock:
            best[t.dt] = min(best.get(t.dt, math.inf), t.error)
    if not best:
        return ""
    closest, since = None, []
    for dt, error in best.items():  # coarsest first, as tried
        if closest is None or error < best[closest]:
            closest, since = dt, []
        else:
            since.append(dt)
    if len(since) < STALLED_STEPS or not left:
        return ""
    return (
        f"finer steps stopped helping: {_us(since)} µs came no closer to golden than "
        f"{closest * 1e6:g} µs ({_pct(best[closest])}), so {_us(left)} µs were not tried "
        "(--dt STEP checks one)"
    )


def _us(steps) -> str:
    """Steps [s] in µs, ``50, 20``."""
    return ", ".join(f"{dt * 1e6:g}" for dt in steps)


def judged(trial: Trial, max_error: float | None) -> Trial:
    """``trial`` judged by the user's limit ``max_error`` (a fraction of the total TDE-rate
    error; ``None``: the declared tolerance it was checked against), its check's report too."""
    if max_error is None or trial.error is None:
        return trial
    checked = trial.checked
    if checked is not None:
        checked = replace(checked, report=replace(checked.report, max_error=max_error))
    return replace(trial, limit=max_error, checked=checked)


#: How the ladder checks a trial: ``judge(check) -> Trial``, ``check(duration) -> Trial`` the
#: trial's export check on reference inputs of ``duration`` [s] (:func:`judge_by`).
Judge = Callable[[Callable[[float], Trial]], Trial]


def judge_by(
    network: Network, target: str, max_error: float | None, duration: float | None, log=None
) -> Judge:
    """How the ladder of ``target`` checks each trial of ``network``, judged within
    ``max_error`` (:func:`judged`): on reference inputs of ``duration`` [s] where the user gave
    one (``--check-duration``); else on 1 s, and where that verdict is not resolved again on
    :data:`LONGER` s, judged by that, whichever way it went. A verdict is unresolved where
    golden on the inputs 0.5 ms later is more than half the limit off itself and at least as
    far as the check is from the limit (a pass or a failure that may be golden's own
    variation), and the longer inputs resolve it where golden's variation on them is within
    half the limit (the check's own measure of it, :attr:`~spll_hw.exporters.check.CheckReport.
    longer_resolution`, else measured once, only where a verdict asks: a user's limit the
    declared one's check did not measure it for). So a network that 1 s resolves
    costs nothing more, and one that 10 s does not resolve either (`vibtac-time-scaled-peak`)
    is not checked ten times as long for nothing; ``log(line)`` hears each check run again,
    with its first result."""
    if duration is not None:
        return lambda check: judged(check(duration), max_error)
    measured = cache(partial(golden_resolution, network, LONGER))

    def judge(check: Callable[[float], Trial]) -> Trial:
        first = judged(check(DURATION), max_error)
        if first.checked is None:
            return first
        report = first.checked.report  # judged: its limit is the trial's
        if report.resolved or abs(first.error - first.limit) > report.resolution:
            return first
        longer = report.longer_resolution  # the check's own, where it measured it
        longer = measured() if math.isnan(longer) else longer
        if longer > first.limit / 2:
            return first
        if log is not None:
            log(f"{target}: {first.clock or f'dt {first.where}'}, {first.variant}: "
                f"{first.summary()} on 1 s, where golden 0.5 ms later is "
                f"{_pct(report.resolution)} off itself ({_pct(longer)} on {LONGER:g} s): "
                f"checked again on {LONGER:g} s")  # fmt: skip
        return judged(check(LONGER), max_error)

    return judge


def choose_dt(
    network: Network,
    parts: Parts,
    steps: tuple[float, ...],
    floor_steps: tuple[float, ...],
    trial: TargetTrial,
    log=None,
    max_error: float | None = None,
    allow_error: bool = False,
    duration: float | None = None,
) -> Trial:
    """The :class:`Trial` of the coarsest of ``steps`` [s] (coarsest first) that passes with
    one of the placements (:func:`step_trials`: its ``dt``, placement and check) within
    ``max_error`` (a fraction; ``None``: the declared tolerance, :func:`judged`), every check
    (the steps', the last rungs' and exact integration's) on reference inputs of ``duration``
    [s] (``spll-hw export --check-duration``; ``None``: 1 s, a step's and a rung's checked
    again on :data:`LONGER` where :func:`judge_by` says);
    ``log(line)``, where given, hears each result as it is measured (a check takes seconds to
    minutes). A step's gates after the first are skipped where exact integration there is
    beyond the limit (:func:`step_trials`), but not with ``allow_error``: where none passes,
    it returns the checked trial of the smallest error of them all (the coarser of equal
    ones), with its :attr:`Trial.note`.

    Raises:
        ValueError: :func:`refusal`'s message (exact integration measured down to
            ``floor_steps`` [s]) where none passes, and with ``allow_error`` where the writer
            refuses every step.
    """
    refuse_unjudgeable(network, parts.target, max_error, duration)
    inputs = DURATION if duration is None else duration
    trials, floor_of = [], cache(partial(floor_check, network, duration=inputs))
    judge = judge_by(network, parts.target, max_error, duration, log)
    # With allow_error every gate is tried: the closest of all is written where none passes.
    skip = None if allow_error else floor_of
    stopped = ""
    for i, dt in enumerate(steps):
        trials += step_trials(network, dt, parts, trial, log, judge, skip)
        if trials[-1].passed:
            return trials[-1]
        if stopped := stalled(trials, steps[i + 1 :]):
            if log is not None:
                log(f"{parts.target}: {stopped}")
            floor_steps = ()  # exact integration is measured where the ladder checked only
            break
    for rung in parts.last:
        trials.append(judge(lambda duration, rung=rung: rung(network, duration=duration)))
        if log is not None:
            log(f"{parts.target}: {trials[-1].clock}, {trials[-1].variant}: "
                f"{trials[-1].summary()}")  # fmt: skip
        if trials[-1].passed:
            return trials[-1]
    checked = [t for t in trials if t.error is not None]
    if not (allow_error and checked):
        raise ValueError(refusal(network, trials, parts, floor_steps, max_error, floor_of, inputs,
                                 stopped))  # fmt: skip
    closest = min(checked, key=lambda t: t.error)
    if log is not None:
        log(f"{parts.target}: no step passes; writing {closest.clock or f'dt {closest.where}'} "
            f"({closest.variant}), the closest to golden "
            "(--allow-error)")  # fmt: skip
    return replace(closest, note=(
        f"No time step of {_steps(trials)} passed the export check within "
        f"{_bound(parts, trials, max_error)}: {_outcomes(trials)}"
        f"{f'; {stopped}' if stopped else ''}. Written "
        f"{f'with {closest.clock} and' if closest.clock else f'at {closest.where} with'} "
        f"{closest.variant}, the step whose check came closest to golden, because of "
        "`--allow-error`; the check below is that step's."
    ))  # fmt: skip


def at_step(choose_placement: Callable[..., Trial], dt: float) -> Callable[..., Trial]:
    """A ``choose`` for :func:`write_chosen` at the user's step ``dt`` [s] (``--dt``): a
    target's ``choose_placement(network, dt, log, max_error, duration)``, quiet (the one-line
    error of a failed check stays the last line on stderr); ``allow_error`` is the folder
    check's."""

    def choose(network: Network, log, max_error, allow_error, duration) -> Trial:
        return choose_placement(network, dt, None, max_error, duration)

    return choose


def write_chosen(
    network: Network,
    choose: Callable[..., Trial],
    write: Callable[[object, str], list[Path]],
    checked: Callable[[MemoryCheck], None] | None,
    max_error: float | None,
    allow_error: bool,
    duration: float | None = None,
) -> list[Path]:
    """An export: the step ``choose(network, log, max_error, allow_error, duration)`` returns
    (a target's ``choose_dt``, each step's line on stderr, each check on reference inputs of
    ``duration`` [s], ``None`` as :func:`judge_by` says; or :func:`at_step`'s at the user's
    ``--dt``), written by ``write(built, readme)`` from exactly what its check ran (its
    backend's ``prepared(network)``: the NIR graph or Loihi's integers) with that built
    object's README and the trial's
    :attr:`~Trial.note`; its check is then handed to ``checked``
    (:func:`~spll_hw.exporters.hands_on_check`). Returns the files ``write`` wrote."""
    chosen = choose(network, lambda line: print(line, file=sys.stderr, flush=True),
                    max_error, allow_error, duration)  # fmt: skip
    if chosen.checked is None:
        raise ValueError(chosen.reason)  # the writer's refusal at the user's step
    built = chosen.checked.run.backend.prepared(network)  # what the check ran
    files = write(built, chosen.readme(built.readme()))
    if checked is not None:
        checked(chosen.checked)
    return files


def _count_error(network: Network, spll: np.ndarray, run, duration: float = DURATION) -> float:
    """The largest TDE-count error among sPLLs ``spll`` of ``network`` over the check's
    reference inputs of ``duration`` [s] (all inputs' counts summed per sPLL, as the check
    counts them) of ``run(part, trains, duration) -> results`` against golden."""
    from spll_hw import simulate_batch
    from spll_hw.exporters.check import reference_inputs

    inputs = reference_inputs(network, duration)
    part = Network(tuple(network.spll[int(i)] for i in spll))
    trains = [x.spikes for x in inputs]
    duration = inputs[0].duration
    golden = np.array([g.tde_counts for g in simulate_batch(part, trains, duration)])
    counts = np.array([r.tde_counts for r in run(part, trains, duration)])
    return float(np.max(np.abs(counts - golden).sum(0) / np.maximum(golden.sum(0), 1)))


#: The refractory hold of the floor's exact integration (:data:`mappings.standard.reference.HOLDS`):
#: both targets' (:func:`~mappings.standard.construction.compensated_hold`), the better of the
#: whole-step holds (docs/backends.md), so that a floor above the limit is the clock's and not a
#: hold rule's.
FLOOR_HOLD = "compensated"


@dataclass(frozen=True)
class Floor:
    """Exact integration between steps of ``dt`` [s] checked as the export is: ``error``, the
    total TDE-rate error on the whole network (the check's verdict metric, against golden, on
    the check's reference inputs); ``spll_error``, the check's per-sPLL TDE-count error,
    shape ``(N,)``."""

    dt: float
    error: float
    spll_error: np.ndarray


def floor_check(
    network: Network,
    dt: float,
    hold: str = FLOOR_HOLD,
    duration: float = DURATION,
    gate: Gate | None = None,
    integrated: Network | None = None,
) -> Floor:
    """The export check (:func:`spll_hw.exporters.check.check_run`, its inputs of ``duration``
    [s] and metrics) of exact integration between steps of ``dt`` [s] with the golden product
    as gate (or ``gate``'s staircase) and refractory holds of rule ``hold``
    (:func:`mappings.standard.reference.simulate_reference`) on all of ``network``: like with
    like with the export's own check. ``integrated``: the network integrated instead, judged
    against golden of ``network`` (the same sPLLs with some parameter rounded, say)."""
    from mappings.standard.reference import simulate_reference
    from spll_hw.backends import get
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run

    ran = network if integrated is None else integrated
    run = FolderRun(
        f"exact integration between steps of {dt:g} s", get("golden"),
        lambda trains, T: simulate_reference(ran, trains, T, (gate,), dt=dt, hold=hold)[0],
    )  # fmt: skip
    report = check_run(run, "standard-reference", network, max_error=1.0, duration=duration)
    return Floor(dt, float(report.tde_error), report.spll_tde_error)


def floor_errors(
    floor_of: Callable[[float], Floor], steps, tolerance: Callable[[float], float]
) -> list[Floor]:
    """``floor_of(dt)`` (:func:`floor_check` of a network) at each of ``steps`` [s], stopping
    at the first whose total error is within ``tolerance(dt)``."""
    out = []
    for dt in steps:
        out.append(floor_of(dt))
        if out[-1].error <= tolerance(dt):
            break
    return out


def gate_error(
    network: Network, spll: np.ndarray, levels: int, placement: str, duration: float = DURATION
) -> float:
    """The TDE-count error (:func:`_count_error`, inputs of ``duration`` [s]) on sPLLs ``spll``
    of the export's gate of ``levels`` levels placed by ``placement`` alone:
    ``standard-exact``, exact in time."""
    from mappings.standard.backend import StandardExact

    gate = StandardExact(levels=levels, placement=placement)
    return _count_error(network, spll, gate.simulate_batch, duration)


def _pct(x: float) -> str:
    return f"{100 * x:.3g} %"


def _steps(trials: list[Trial]) -> str:
    """The steps ``trials`` tried, ``50, 25, 10 µs``, and their clocks per sPLL where tried
    (``..., nor a clock per sPLL (R = 4), nor ... with graded CCO currents,``)."""
    steps = ", ".join(dict.fromkeys(f"{t.dt * 1e6:g}" for t in trials if not t.clock))
    clocks = "".join(dict.fromkeys(f", nor {t.clock}" for t in trials if t.clock))
    return f"{steps} µs{clocks}{',' if clocks else ''}"


def _limit(parts: Parts, trials: list[Trial], max_error: float | None) -> float:
    """The limit ``trials`` were judged by: ``max_error``, else the declared tolerance (that
    of the finest step checked, or of the first step where none was)."""
    if max_error is not None:
        return max_error
    last = next((t for t in reversed(trials) if t.error is not None), None)
    return parts.tolerance(trials[0].dt) if last is None else last.limit  # trials[0]: one step


def _bound(parts: Parts, trials: list[Trial], max_error: float | None) -> str:
    """The limit ``trials`` were judged by, and whose it is."""
    whose = "the declared tolerance" if max_error is None else "the limit of --max-error"
    return f"{whose} ({_pct(_limit(parts, trials, max_error))})"


def _outcomes(trials: list[Trial]) -> str:
    """Each step's outcome: refused (why) or the check's error with its placement."""
    return ", ".join(
        f"{t.where} refused ({t.reason.split(';')[0]})"
        if t.error is None
        else f"{t.where} {100 * t.error:.1f} %{t.on} ({t.gate} levels{t.held})"
        for t in trials
    )


def _closest(trials: list[Trial]) -> str:
    """The checked trial closest to golden in words, what ``--allow-error`` would write
    (``the closest, a clock per sPLL (R = 4) with 32 band-quantile gate levels at 8.3 %, is
    what --allow-error writes; ``)."""
    checked = [t for t in trials if t.error is not None]
    if not checked:
        return ""
    best = min(checked, key=lambda t: t.error)
    return (
        f"the closest, {best.where} with {best.variant} at {_pct(best.error)}{best.on}, is what "
        "--allow-error writes; "
    )


def refusal(
    network: Network,
    trials: list[Trial],
    parts: Parts,
    floor_steps=(),
    max_error: float | None = None,
    floor_of: Callable[[float], Floor] | None = None,
    duration: float = DURATION,
    stopped: str = "",
) -> str:
    """Why no step of ``trials`` represents ``network`` within ``max_error`` (a fraction;
    ``None``: the declared tolerance), named with its source: each step's outcome, and where
    the check ran, its worst sPLLs and exact integration's error on them at the finest step it
    ran at and at ``floor_steps`` [s] (module docstring; ``floor_of(dt)``, where given, measures
    it: the ladder's, which keeps what it measured), on reference inputs of ``duration``
    [s], the trials' own; ``stopped``: why the ladder stopped before its finest step
    (:func:`stalled`), said after the outcomes."""
    r = roles()
    # the floor is measured at the finest one step checked (not at a clock per sPLL)
    last = next((t for t in reversed(trials) if t.error is not None and not t.clock), None)
    limit = _limit(parts, trials, max_error)
    text = (
        f"{parts.target}: no time step of {_steps(trials)} represents this network within "
        f"{_bound(parts, trials, max_error)}; the export check's total TDE-rate error: "
        f"{_outcomes(trials)}{f'; {stopped}' if stopped else ''}"
    )
    if last is None:
        return f"{text}; {parts.exact}{_resolution(network, trials, limit)}"
    worst = np.argsort(-last.spll_error, kind="stable")[:NAMED]
    m = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    tolerance = parts.tolerance if max_error is None else lambda dt: max_error
    floor_of = floor_of or partial(floor_check, network, duration=duration)
    floor = floor_errors(floor_of, (last.dt, *floor_steps), tolerance)
    named = ", ".join(
        f"{i} (tau_tde_fac {m[r.fac.tau][i] * 1e6:.0f} µs, tau_tde_trg "
        f"{m[r.trg.tau][i] * 1e6:.0f} µs: {100 * last.spll_error[i]:.0f} % off, exact "
        f"integration {100 * floor[0].spll_error[i]:.0f} %)"
        for i in worst
    )
    floors = ", ".join(f"{100 * f.error:.1f} % at {f.dt * 1e6:g} µs" for f in floor)
    measured = (
        f"{text}. Worst sPLLs at {last.dt * 1e6:g} µs: {named}. Exact integration between steps "
        f"(mappings/standard/reference.py, the golden product as gate, refractory holds of "
        f"round(t_refr/dt - 1/2) steps), checked as the export is, is off by {floors} "
        f"(the total TDE-rate error)"
    )
    if floor[0].error <= limit:
        levels = int(parts.backend(last.dt, last.placement, last.levels, last.hold)
                     .options["levels"])  # fmt: skip
        gate = gate_error(network, worst, levels, last.placement, duration)
        return (
            f"{measured}, within the tolerance: the clock is not the cause but the construction "
            f"is; its {levels}-level gate alone, exact in time (standard-exact), is off on the "
            f"worst sPLLs by {100 * gate:.1f} % on the check's inputs ({last.placement} levels)"
            f"{parts.construction(network, worst, last.dt)}; {_closest(trials)}{parts.exact}"
            f"{_resolution(network, trials, limit)}"
        )
    fine = floor[-1]
    verdict = (
        f"so --dt {fine.dt:g} might pass ({parts.finer(network, fine.dt)})"
        if fine.error <= limit
        else f"so no dt >= {fine.dt * 1e6:g} µs brings it within {_pct(limit)}"
    )
    return (
        f"{measured}: the clock, not the construction, {verdict}; {_closest(trials)}{parts.exact}"
        f"{_resolution(network, trials, limit)}"
    )


def _resolution(network: Network, trials: list[Trial], limit: float) -> str:
    """Where the checks' inputs do not resolve ``limit`` (golden on them 0.5 ms later is more
    than half of it off, :attr:`~spll_hw.exporters.check.CheckReport.resolved`), the sentence
    that says so and whether :data:`LONGER` s would, to end a refusal; else nothing."""
    report = next((t.checked.report for t in trials if t.checked is not None), None)
    if report is None:
        return ""
    report = replace(report, max_error=limit)
    if report.resolved:
        return ""
    shorter = max(x["duration_s"] for x in report.inputs) < LONGER
    if shorter and math.isnan(report.longer_resolution):  # the check's limit was resolved
        report = replace(report, longer_resolution=golden_resolution(network, LONGER))
    return f". {report.resolution_words().rstrip('.')}"
