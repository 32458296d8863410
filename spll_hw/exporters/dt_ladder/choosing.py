"""The ladder itself: the coarsest step whose check passes (:func:`choose_dt`), the gate at the
user's step (:func:`choose_placement`), where finer steps stop helping (:func:`stalled`), and
the export written from what its check ran (:func:`write_chosen`)."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import replace
from functools import cache, partial
from pathlib import Path

from spll_hw.exporters import MemoryCheck
from spll_hw.exporters.check_inputs import DURATION
from spll_hw.network import Network

from .floor import Floor, floor_check
from .judging import Judge, judge_by, refuse_unjudgeable
from .refusals import bound_words, outcomes, refusal, steps_tried
from .trials import EXPORT_GATES, Parts, TargetTrial, Trial, percent


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
                        f"is {percent(exact)} off, beyond the limit; the other gates{held} are "
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
    refuse_unjudgeable(network, parts.target, max_error, duration, parts.tolerance(dt))
    judge = judge_by(network, parts.target, max_error, duration, log)
    trials = step_trials(network, dt, parts, trial, log, judge)
    checked = [t for t in trials if t.error is not None]
    return min(checked, key=lambda t: t.error) if checked else trials[-1]


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
        f"finer steps stopped helping: {us_words(since)} µs came no closer to golden than "
        f"{closest * 1e6:g} µs ({percent(best[closest])}), so {us_words(left)} µs were not tried "
        "(--dt STEP checks one)"
    )


def us_words(steps) -> str:
    """Steps [s] in µs, ``50, 20``."""
    return ", ".join(f"{dt * 1e6:g}" for dt in steps)


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
    declared = max(parts.tolerance(dt) for dt in steps)
    refuse_unjudgeable(network, parts.target, max_error, duration, declared)
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
        f"No time step of {steps_tried(trials)} passed the export check within "
        f"{bound_words(parts, trials, max_error)}: {outcomes(trials)}"
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
