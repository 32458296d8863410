"""How the ladder judges a check: by the user's limit (:func:`judged`), on 1 s and again on
:data:`~spll_hw.exporters.check.LONGER` s where 1 s does not resolve the verdict
(:func:`judge_by`), and a limit below golden's own resolution refused before any work
(:func:`refuse_unjudgeable`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from functools import cache, partial

from spll_hw.exporters.check import DURATION, LONGER, RESOLUTION_SHIFT, golden_resolution
from spll_hw.network import Network

from .trials import Trial, percent


def refuse_unjudgeable(
    network: Network,
    target: str,
    max_error: float | None,
    duration: float | None,
    declared: float | None = None,
) -> None:
    """``ValueError`` before any check where the limit lies below golden's own resolution on
    the check's inputs (its total TDE-rate error on every input
    :data:`~spll_hw.exporters.check.RESOLUTION_SHIFT` later, golden alone, seconds): no check
    can tell an export within it from golden's own variation, so no step would pass and the
    ladder would try every one for nothing. The limit is the user's ``max_error`` or, without
    one, ``declared``, the most lenient tolerance the target declares at any step it tries
    (``None``: not judged). The inputs are ``duration`` [s] long (``None``: 1 s, and where 1 s
    does not resolve the limit, :data:`LONGER` s, on which the ladder judges such a verdict
    again, :func:`judge_by`); a limit of 0 asks for golden's counts exactly, refused where
    golden itself does not keep them on 1 s."""
    limit = declared if max_error is None else max_error
    if limit is None or not isinstance(network, Network):  # not a network: the writer says so
        return
    inputs = DURATION if duration is None else duration
    resolution = golden_resolution(network, inputs)
    if limit >= resolution:
        return
    moved = (f"golden itself, on every input {1e3 * RESOLUTION_SHIFT:g} ms later, is "
             f"{percent(resolution)} off golden on the check's inputs of {inputs:g} s")  # fmt: skip
    least = resolution
    if duration is None and limit > 0:
        longer = golden_resolution(network, LONGER)
        if limit >= longer:
            return
        moved += f" and {percent(longer)} on {LONGER:g} s"
        least = min(resolution, longer)
    if limit == 0:
        asks = "--max-error 0 asks for golden's counts exactly, which golden does not keep itself"
    else:
        which = f"its declared tolerance ({percent(limit)}, at every step it tries)"
        which = which if max_error is None else f"--max-error {limit:g}"
        asks = (f"{which} lies below golden's own resolution, so no check can tell an export "
                "within it from golden's own variation")  # fmt: skip
    raise ValueError(
        f"{target}: {asks}: {moved}. No export would pass (checked before any export was tried); "
        f"give --max-error {math.ceil(least * 1e3) / 1e3:g} or more (then judged on those "
        "inputs), or --to nir, the exact sPLL, which a limit of 0 judges"
    )


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
                f"{percent(report.resolution)} off itself ({percent(longer)} on {LONGER:g} s): "
                f"checked again on {LONGER:g} s")  # fmt: skip
        return judged(check(LONGER), max_error)

    return judge
