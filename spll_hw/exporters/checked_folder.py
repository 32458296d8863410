"""One network exported into a folder and checked there: what ``spll-hw export --to TARGET``
does for one network, and for each channel group of a multichannel network
(:mod:`.multichannel`).

:func:`export_into` runs the target's exporter into a staging folder (a step ladder judging
each step on the same extra inputs and verdict as the folder's check, :mod:`.judged_on`), writes
the network as ``params.toml``, checks the folder against the golden model
(:func:`~.folder_check.check_folder`; a check the exporter already ran from memory on what it wrote
counts, :func:`~spll_hw.exporters.export_checked`) and writes ``check.json``, the README's check
section and ``cost.json``. A check that fails raises :class:`CheckFailed` unless the error is
allowed; the caller owns the staging folder and puts it in place only when everything is done
(:func:`spll_hw.files.atomic_folder`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..config import NetworkConfig
from ..files import writing
from . import check_duration, check_limit, export_checked
from .check import CheckReport
from .check_files import NETWORK_FILE, reference_duration, write_check
from .check_inputs import DURATION, CheckInput
from .cost import write_cost
from .dt_ladder import refuse_unjudgeable
from .folder_check import check_folder
from .judged_on import judged_on


class CheckFailed(ValueError):
    """The export's check against the golden model failed (``spll-hw export`` exits 2)."""


@dataclass(frozen=True)
class ExportOptions:
    """How one network is exported and checked (``spll-hw export``'s flags).

    Attributes:
        profile: chip profile of exports with integer parameters (``None``: the target's).
        dt: time step [s] of clocked exports (``None``: the target's own choice).
        max_error: limit of the check's total TDE-rate error, a fraction (``None``: the
            target's declared tolerance).
        allow_error: keep an export whose check fails.
        check_duration: the reference inputs' length [s] (``None``: the exporter's, else
            :data:`~.check_inputs.DURATION`).
        max_failed: sPLLs allowed to fail the per-sPLL verdict (``None``: the default).
    """

    profile: str | None = None
    dt: float | None = None
    max_error: float | None = None
    allow_error: bool = False
    check_duration: float | None = None
    max_failed: int | None = None


@dataclass(frozen=True)
class Exported:
    """What :func:`export_into` wrote: the files (in the staging folder, in writing order) and
    the folder's check."""

    files: list[Path]
    report: CheckReport


def export_into(
    export,
    target: str,
    config: NetworkConfig,
    stage: Path,
    inputs: Sequence[CheckInput],
    options: ExportOptions,
    failed: str = "",
) -> Exported:
    """Export ``config``'s network with ``export`` (target ``target``) into ``stage``, check it
    on the reference trains and ``inputs``, and write the check's and cost's files there. A
    ``--max-error`` below golden's own resolution on the check's reference inputs is refused
    before any work (:func:`~.dt_ladder.refuse_unjudgeable`: seconds, not the minutes of a
    check that could not pass), but for a target that refuses it itself (a step ladder,
    :func:`~spll_hw.exporters.takes_check_limit`) or whose folders run golden itself
    (:func:`~spll_hw.exporters.runs_golden`, which judges any limit).

    Raises:
        CheckFailed: the check failed and ``options.allow_error`` is not set; its message is the
            check's failure followed by ``failed`` (what the caller leaves unwritten).
    """
    network = config.build()
    if not (getattr(export, "takes_check_limit", False) or getattr(export, "runs_golden", False)):
        # a ladder refuses it itself, and golden read back judges any limit
        refuse_unjudgeable(network, target, check_limit(options.max_error),
                           check_duration(options.check_duration) or DURATION)  # fmt: skip
    with judged_on(inputs, options.max_failed):  # a step ladder judges as the check does
        files, checked = export_checked(
            export, network, stage, profile=options.profile, dt=options.dt,
            max_error=options.max_error, allow_error=options.allow_error,
            duration=options.check_duration,
        )  # fmt: skip
    with writing(stage / NETWORK_FILE) as path:
        path.write_text(config.to_toml())
    duration = options.check_duration
    if duration is None:  # the ladder may have checked its step on longer inputs
        duration = DURATION if checked is None else reference_duration(checked.report.trains)
    report = check_folder(stage, target, network, inputs=inputs, checked=checked,
                          max_error=options.max_error, allowed=options.allow_error,
                          duration=duration, max_failed=options.max_failed)  # fmt: skip
    if not report.passed and not options.allow_error:
        raise CheckFailed(f"{report.failure()}{failed}")
    written = [*files, stage / NETWORK_FILE, *write_check(stage, report),
               *write_cost(stage, target, network, report)]  # fmt: skip
    return Exported(list(dict.fromkeys(Path(p) for p in written)), report)


def verdict(report: CheckReport) -> str:
    """The check's verdict in one line, as ``spll-hw export`` prints it."""
    passed = "passed" if report.passed else "FAILED"
    passed += " (kept: --allow-error)" if not report.passed and report.allowed else ""
    return (
        f"check {passed}: TDE-rate error {100 * report.tde_error:.1f} % (CCO "
        f"{100 * report.cco_error:.1f} %) against golden, limit {report.limit_words}, "
        f"worst sPLL {report.worst} ({100 * report.spll_tde_error[report.worst]:.1f} %); "
        f"{report.spll_words()}; {len(report.inputs)} inputs, {report.wall_time:.1f} s"
        + (f". {words}" if (words := report.resolution_words()) else "")
    )
