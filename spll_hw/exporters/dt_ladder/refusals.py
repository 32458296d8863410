"""Why no step passes, in words: each step's outcome, the worst sPLLs, and the floor that says
whether the clock or the construction is the cause (:func:`refusal`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from functools import partial

import numpy as np

from spll_hw.exporters.check import LONGER, golden_resolution
from spll_hw.exporters.check_inputs import DURATION
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

from .floor import Floor, floor_check, floor_errors, gate_error
from .trials import Parts, Trial, percent

#: sPLLs a refusal names.
NAMED = 3


def steps_tried(trials: list[Trial]) -> str:
    """The steps ``trials`` tried, ``50, 25, 10 µs``, and their clocks per sPLL where tried
    (``..., nor a clock per sPLL (R = 4), nor ... with graded CCO currents,``)."""
    steps = ", ".join(dict.fromkeys(f"{t.dt * 1e6:g}" for t in trials if not t.clock))
    clocks = "".join(dict.fromkeys(f", nor {t.clock}" for t in trials if t.clock))
    return f"{steps} µs{clocks}{',' if clocks else ''}"


def judged_limit(parts: Parts, trials: list[Trial], max_error: float | None) -> float:
    """The limit ``trials`` were judged by: ``max_error``, else the declared tolerance (that
    of the finest step checked, or of the first step where none was)."""
    if max_error is not None:
        return max_error
    last = next((t for t in reversed(trials) if t.error is not None), None)
    return parts.tolerance(trials[0].dt) if last is None else last.limit  # trials[0]: one step


def bound_words(parts: Parts, trials: list[Trial], max_error: float | None) -> str:
    """The limit ``trials`` were judged by, and whose it is."""
    whose = "the declared tolerance" if max_error is None else "the limit of --max-error"
    return f"{whose} ({percent(judged_limit(parts, trials, max_error))})"


def outcomes(trials: list[Trial]) -> str:
    """Each step's outcome: refused (why) or the check's error with its placement."""
    return ", ".join(
        f"{t.where} refused ({t.reason.split(';')[0]})"
        if t.error is None
        else f"{t.where} {100 * t.error:.1f} %{t.on} ({t.gate} levels{t.held})"
        for t in trials
    )


def closest_words(trials: list[Trial]) -> str:
    """The checked trial closest to golden in words, what ``--allow-error`` would write
    (``the closest, a clock per sPLL (R = 4) with 32 band-quantile gate levels at 8.3 %, is
    what --allow-error writes; ``)."""
    checked = [t for t in trials if t.error is not None]
    if not checked:
        return ""
    best = min(checked, key=lambda t: t.error)
    return (
        f"the closest, {best.where} with {best.variant} at {percent(best.error)}{best.on}, is what "
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
    limit = judged_limit(parts, trials, max_error)
    text = (
        f"{parts.target}: no time step of {steps_tried(trials)} represents this network within "
        f"{bound_words(parts, trials, max_error)}; the export check's total TDE-rate error: "
        f"{outcomes(trials)}{f'; {stopped}' if stopped else ''}"
    )
    if last is None:
        return f"{text}; {parts.exact}{unresolved_words(network, trials, limit)}"
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
        f"(spll_hw/construction/reference.py, the golden product as gate, refractory holds of "
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
            f"{parts.construction(network, worst, last.dt)}; {closest_words(trials)}{parts.exact}"
            f"{unresolved_words(network, trials, limit)}"
        )
    fine = floor[-1]
    verdict = (
        f"so --dt {fine.dt:g} might pass ({parts.finer(network, fine.dt)})"
        if fine.error <= limit
        else f"so no dt >= {fine.dt * 1e6:g} µs brings it within {percent(limit)}"
    )
    return (
        f"{measured}: the clock, not the construction, {verdict}; {closest_words(trials)}"
        f"{parts.exact}"
        f"{unresolved_words(network, trials, limit)}"
    )


def unresolved_words(network: Network, trials: list[Trial], limit: float) -> str:
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
