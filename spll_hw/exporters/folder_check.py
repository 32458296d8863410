"""Check an export folder: read it back, run it against the golden model (:mod:`.check`) and,
where it fails at a time step, measure the steps beside it (:mod:`.remedies`).

A check the exporter ran from memory on what it wrote is the folder's report where it is the
same check: the same target, the same inputs train for train, and the folder read back
simulating the network by the same rules (:meth:`~spll_hw.exporters.FolderRun.runs_as`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..network import Network
from . import FolderRun, MemoryCheck, check, reader
from .check import CheckReport, verdict_limit
from .check_files import read_network
from .check_inputs import DURATION, CheckInput, reference_inputs
from .remedies import step_remedy
from .spll_verdict import failed_limit


def check_folder(
    folder: str | Path,
    target: str,
    network: Network | None = None,
    *,
    inputs: Sequence[CheckInput] | None = None,
    max_error: float | None = None,
    allowed: bool = False,
    duration: float = DURATION,
    checked: MemoryCheck | None = None,
    max_failed: int | None = None,
) -> CheckReport:
    """Check the export folder ``folder`` of ``target`` (:mod:`.check`).

    Args:
        folder: the folder the exporter wrote.
        target: its export target (``spll-hw export --to``).
        network: the network it was exported from (default: the folder's ``params.toml``).
        inputs: extra inputs beside :func:`reference_inputs` (the user's trains, the encoded
            ones of :mod:`.encoded`).
        max_error: limit of the total TDE-rate error (default: the declared tolerance).
        max_failed: how many sPLLs may fail the per-sPLL verdict (default :data:`MAX_FAILED`).
        allowed: record that the export is kept although it is off.
        duration: run length [s] of the reference inputs.
        checked: the check its exporter ran from memory on what it wrote: its report is the
            folder's where it is the same check (:mod:`.check`), with ``max_error`` and
            ``allowed``; the folder is simulated otherwise.

    Raises:
        ValueError: the folder cannot be read back (naming the file), ``max_error`` is not
            a number >= 0 or ``max_failed`` not a whole number >= 0.
    """
    folder = Path(folder)
    network = read_network(folder) if network is None else network
    start = time.perf_counter()
    run: FolderRun = reader(target)(folder, network)
    if checked is not None and _same_check(checked, run, target, network, inputs, duration):
        return replace(checked.report, runs=run.runs, remedies=run.remedies,
                       max_error=verdict_limit(run, max_error), allowed=allowed,
                       from_memory=checked.run.runs,
                       max_failed=failed_limit(max_failed))  # fmt: skip
    report = check.check_run(run, target, network, inputs=inputs, max_error=max_error,
                       allowed=allowed, duration=duration, start=start,
                       max_failed=max_failed)  # fmt: skip
    if report.passed or run.at_step is None:
        return report
    remedy = step_remedy(report, run, network, inputs, max_error, duration, max_failed)
    return replace(report, remedies=(remedy, *report.remedies))


def _same_check(
    checked: MemoryCheck,
    run: FolderRun,
    target: str,
    network: Network,
    inputs: Sequence[CheckInput] | None,
    duration: float,
) -> bool:
    """Whether :func:`~.check.check_run` of ``run`` would compute ``checked``'s report again:
    the same target, the same inputs (:func:`reference_inputs` and ``inputs``, train for train), and
    ``run`` and ``checked.run`` simulating ``network`` by the same rules
    (:meth:`FolderRun.runs_as`)."""
    every = [*reference_inputs(network, duration), *(inputs or ())]
    done = checked.report.trains
    return (
        checked.report.target == target
        and len(done) == len(every)
        and all(_same_input(a, b) for a, b in zip(done, every, strict=True))
        and run.runs_as(checked.run, network)
    )


def _same_input(a: CheckInput, b: CheckInput) -> bool:
    return a.describe() == b.describe() and np.array_equal(a.spikes, b.spikes)
