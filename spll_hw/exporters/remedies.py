"""Remedies a failed export check has measured before it gives them.

A clocked export whose folder declares the step it was written at and how to write the same
network at another (:attr:`~spll_hw.exporters.FolderRun.step`,
:attr:`~spll_hw.exporters.FolderRun.at_step`; ``--to lava`` does) is checked again, on the
same inputs and by the same limit rule, at half and at twice its step (:data:`STEP_FACTORS`)
when its check fails. The advice then names a step only where that check passed, with what it
measured: a finer step is not always better (Loihi's decays round long time constants away as
the step shrinks, and the declared tolerance moves with the step), so the tool does not guess.
"""

from __future__ import annotations

from collections.abc import Sequence

from . import FolderRun
from .check import CheckReport, check_run
from .check_inputs import CheckInput

#: Multiples of the folder's step that a failed check tries before advising one.
STEP_FACTORS = (0.5, 2.0)


def step_remedy(
    report: CheckReport,
    run: FolderRun,
    network,
    inputs: Sequence[CheckInput] | None,
    max_error: float | None,
    duration: float,
    max_failed: int | None,
) -> str:
    """The remedy of a failed check ``report`` of ``run`` that its step would give: the steps
    of :data:`STEP_FACTORS` checked again (``inputs``, ``max_error``, ``duration`` and
    ``max_failed`` as the failed check had them), those that pass advised with what they
    measured, and said so where none does; ``""`` where ``run`` declares no step."""
    if run.step is None or run.at_step is None:
        return ""
    passed, failed = [], []  # ("--dt X", what it measured there), by verdict
    for factor in STEP_FACTORS:
        flag = f"--dt {run.step * factor:g}"
        try:
            other = check_run(run.at_step(run.step * factor), report.target, network,
                              inputs=inputs, max_error=max_error, duration=duration,
                              max_failed=max_failed)  # fmt: skip
        except ValueError as exc:  # the export would be refused at that step
            failed.append((flag, f"refused ({exc})"))
            continue
        words = f"{100 * other.tde_error:.1f} % against its limit {100 * other.max_error:.1f} %"
        (passed if other.passed else failed).append((flag, words))
    others = ", ".join(f"{flag}: {words}" for flag, words in failed)
    if passed:
        steps = " or ".join(f"{flag}, measured to pass ({words})" for flag, words in passed)
        return steps + (f" (and {others})" if others else "")
    return f"no other --dt (measured beside dt = {run.step:g} s: {others})"
