"""How the ladder judges a check: by the user's limit (:func:`judged`), on 1 s and again on
:data:`~spll_hw.exporters.check.LONGER` s where 1 s does not resolve the verdict
(:func:`judge_by`), and a limit below golden's own resolution refused before any work
(:func:`refuse_unjudgeable`; for ``spll-hw export --check FOLDER``,
:func:`refuse_unjudgeable_check`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import cache, partial
from pathlib import Path

from spll_hw.exporters.check import LONGER, RESOLUTION_SHIFT, golden_resolution
from spll_hw.exporters.check_inputs import DURATION, CheckInput
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
    which = f"its declared tolerance ({percent(limit)}, at every step it tries)"
    asks = _asks(limit, which if max_error is None else f"--max-error {limit:g}", "an export")
    raise ValueError(
        f"{target}: {asks}: {moved}. No export would pass (checked before any export was tried); "
        f"give --max-error {_least(least)} or more (then judged on those "
        "inputs), or --to nir, the exact sPLL, which a limit of 0 judges"
    )


def refuse_unjudgeable_check(
    folder: Path,
    target: str,
    network: Network,
    max_error: float | None,
    duration: float,
    inputs: Sequence[CheckInput],
) -> None:
    """``ValueError`` before ``spll-hw export --check FOLDER`` runs its check, where the user's
    limit ``max_error`` lies below golden's own resolution on that check's inputs (the
    reference inputs of ``duration`` [s] and ``inputs``: golden alone on them and on them
    :data:`~spll_hw.exporters.check.RESOLUTION_SHIFT` later, a second or less, where the check
    takes tens of seconds): no check could tell the folder's export within it from golden's
    own variation, as :func:`refuse_unjudgeable` refuses it before an export. ``None`` (the
    declared tolerance, which the export judged) is not refused, nor is a target whose folders
    run golden itself (the caller's to leave out: :func:`~spll_hw.exporters.runs_golden`). The
    message names the folder, the limit, the resolution and the least limit that can be
    judged, and ``--check-duration`` :data:`LONGER` where longer inputs resolve the limit."""
    if max_error is None:
        return
    resolution = golden_resolution(network, duration, inputs)
    if max_error >= resolution:
        return
    longer = ""
    if 0 < max_error and duration < LONGER:
        finer = golden_resolution(network, LONGER, inputs)
        if max_error >= finer:
            longer = (f", or --check-duration {LONGER:g} (on reference inputs that long golden "
                      f"is {percent(finer)} off itself)")  # fmt: skip
    asks = _asks(max_error, f"--max-error {max_error:g}", "the folder's export")
    raise ValueError(
        f"--check {folder} ({target}): {asks}: golden itself, on every input "
        f"{1e3 * RESOLUTION_SHIFT:g} ms later, is {percent(resolution)} off golden on this "
        f"check's inputs (the reference inputs of {duration:g} s"
        f"{f' and {len(inputs)} more' if inputs else ''}). No check of it would pass (refused "
        f"before the check ran; nothing was written and {folder} is unchanged); give "
        f"--max-error {_least(resolution)} or more{longer}"
    )


def _asks(limit: float, which: str, what: str) -> str:
    """Why ``limit`` (named ``which``: ``--max-error 0.01``) cannot judge ``what``."""
    if limit == 0:
        return "--max-error 0 asks for golden's counts exactly, which golden does not keep itself"
    return (f"{which} lies below golden's own resolution, so no check can tell {what} within "
            "it from golden's own variation")  # fmt: skip


def _least(resolution: float) -> str:
    """The least ``--max-error`` a check of golden's ``resolution`` judges, rounded up to 0.1 %."""
    return f"{math.ceil(resolution * 1e3) / 1e3:g}"


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
