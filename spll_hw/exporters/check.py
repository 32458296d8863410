"""Every export checks itself: the folder, read back and simulated by the rules its target runs,
against the golden model of the network it was exported from.

:func:`.folder_check.check_folder` reads the folder back with its exporter's ``read_back``
(:class:`~spll_hw.exporters.FolderRun`); :func:`check_run` runs it and the golden model on the
same inputs and measures, per input, the relative L1 error of the TDE- and of the CCO-rate vector
(:func:`~spll_hw.harness.metrics.rate_error`) and, per sPLL, the relative error of its spike
counts over all inputs together. The **inputs** (:func:`.check_inputs.reference_inputs`) are the
network's own: a Poisson and a periodic train at its lowest, middle and highest free-running
frequency, :data:`~.check_inputs.DURATION` = 1 s each, plus the user's own trains
(:func:`.check_inputs.user_input`) and, for a network that carries an encoder, samples of its
own kind of signal encoded by it (:mod:`.encoded`: windows of held-out BioTac recordings, else
synthetic textures; each input's ``kind`` and ``source`` in ``check.json``). The **verdict**
compares the total TDE-rate error, the mean of the per-input errors over the inputs on which
golden's TDEs fire (the measure backends declare ``capabilities.rate_tolerance`` in,
:mod:`spll_hw.backends.conformance`), and the same mean over the encoded inputs alone
(:attr:`CheckReport.encoded_error`), with ``max_error`` (default: that declared tolerance of the
backend that runs the same rules, :attr:`FolderRun.backend`), and it judges **each sPLL**
(:mod:`.spll_verdict`: an open-loop CCO, a TDE silent or running away against golden), of which
at most ``--max-failed-splls`` (0) may fail; the verdict, the README and the CLI name them. The
reference is the golden model of the network as exported, not as a chip profile realises it: for
``--to lava`` the error includes the profile's rounding (``quantization.md``), which
``golden-fixed-point``'s declared tolerance leaves out, so the check is the stricter of the two.

The **resolution** (:attr:`CheckReport.resolution`) is the same measure between golden and
golden on every input :data:`RESOLUTION_SHIFT` (0.5 ms) later (:func:`.check_inputs.shifted`):
one more golden batch. On a network whose TDE counts hang on the exact phase between input and
CCO, one run of a 1-s input is a sample, and golden itself is that far off; an error below it
says nothing, and where it exceeds half the limit (:attr:`CheckReport.resolved` false) the
verdict cannot tell an export at the limit from golden's own variation. The check then measures
golden's variation on reference inputs of :data:`LONGER` s as well (:func:`golden_resolution`,
golden alone: seconds) and the report says whether ``--check-duration`` that long resolves the
limit or that it does not either (docs/backends.md, "Golden against itself").

The outcome goes into the folder (:mod:`.check_files`: ``check.json``, the README's section,
``check_inputs.npz`` with every input's train, which a later check of the folder runs again).

A check an exporter ran from memory on what it wrote is taken as the folder's where it is the
same check (:mod:`spll_hw.exporters`, :attr:`CheckReport.from_memory`; :mod:`.folder_check`). A
failed check of a folder with a time step measures the steps beside it before advising one
(:mod:`.remedies`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .. import backends
from ..harness.metrics import rate_error
from ..network import Network
from ..neuron_graph import COUNTS_KEY
from ..result import SimulationResult
from . import FolderRun, check_limit
from .check_inputs import (
    DURATION,
    ENCODED_KINDS,
    CheckInput,
    reference_inputs,
    shifted,
)
from .spll_verdict import (
    FAILURE_CRITERIA,
    MAX_FAILED,
    count_error,
    failed_limit,
    failure_words,
    open_loop,
    spll_failures,
)

#: How much later [s] golden's second run sees every input (the check's resolution): a
#: shift no clocked target could be blamed for (the coarsest export step is 0.1 ms).
RESOLUTION_SHIFT = 5e-4
#: Length [s] of the longer reference inputs on which golden's own variation is measured where
#: the check's do not resolve its limit: 10 s resolves a 7 % limit on every shipped preset
#: but ``vibtac-time-scaled-peak`` (docs/backends.md, "Golden against itself").
LONGER = 10.0
#: Markers around what the check writes into the README (a new check replaces it).
SECTION = ("<!-- spll-hw check -->", "<!-- /spll-hw check -->")
WARNING = ("<!-- spll-hw check warning -->", "<!-- /spll-hw check warning -->")
#: How many of the worst sPLLs a failure names.
WORST_NAMED = 5


@dataclass
class CheckReport:
    """The outcome of :func:`.folder_check.check_folder` (all errors relative: 0.05 is 5 %).

    Attributes:
        target: the export target.
        runs: what simulated the folder (:attr:`FolderRun.runs`).
        backend: spec of the backend of the same rules (whose tolerance is the default).
        tolerance: that backend's declared rate tolerance.
        tolerance_basis: why the tolerance is what it is, in words, where the backend says
            (:attr:`~spll_hw.backends.base.Capabilities.tolerance_basis`: a chip profile's
            own ``tolerance``, or another profile's measured arithmetic); ``""`` otherwise.
        max_error: the limit the verdict used.
        inputs: the inputs, with their TDE and CCO errors and spike totals.
        tde_error, cco_error: total errors (mean over the inputs on which golden's TDEs fire;
            where they fire on none, 0 if the export's TDEs do not either, else 1).
        spll_tde_error, spll_cco_error: per sPLL, ``sum |c - c_ref| / max(sum c_ref, 1)`` of its
            spike counts over every input, shape ``(N,)``.
        spll_tde_spikes, spll_golden_tde_spikes: TDE spikes per sPLL over every input, the
            export's and golden's, shape ``(N,)``.
        free_frequencies: of the sPLLs [Hz], shape ``(N,)``.
        wall_time: seconds the check took.
        remedies: what would help (:attr:`FolderRun.remedies`).
        allowed: the export is kept although it is off (``--allow-error``).
        trains: the inputs themselves, in the order of :attr:`inputs` (``check_inputs.npz``).
        from_memory: what ran the check from memory before the folder was written, which the
            folder reads back as (:func:`check_folder`'s ``checked``); empty where the folder
            itself was simulated.
        resolution: the total TDE-rate error of golden on the inputs :data:`RESOLUTION_SHIFT`
            later against golden (module docstring); NaN where not measured.
        spll_resolution: per sPLL, that run's TDE-count error, shape ``(N,)`` (empty where not
            measured).
        longer_resolution: :attr:`resolution` on reference inputs of :data:`LONGER` s,
            measured where the inputs are shorter and do not resolve the check's limit; NaN
            elsewhere.
        neuron_counts: per input, the spikes of every neuron of what ran, shape ``(n,)``,
            where it counted them (a graph of standard neurons,
            :data:`~spll_hw.neuron_graph.COUNTS_KEY`; ``None`` elsewhere): what the folder's
            ``cost.json`` is costed from (:mod:`.cost`), not written to ``check.json``.
        failed: the sPLLs the per-sPLL verdict fails (:func:`spll_failures`), each
            ``{"spll": index, "why": [reasons]}``, by index.
        max_failed: how many of them the verdict allows (``--max-failed-splls``).
    """

    target: str
    runs: str
    backend: str
    tolerance: float
    max_error: float
    inputs: list[dict]
    tde_error: float
    cco_error: float
    spll_tde_error: np.ndarray
    spll_cco_error: np.ndarray
    spll_tde_spikes: np.ndarray
    spll_golden_tde_spikes: np.ndarray
    free_frequencies: np.ndarray
    wall_time: float
    remedies: tuple[str, ...] = ()
    allowed: bool = False
    trains: list[CheckInput] = field(default_factory=list)
    from_memory: str = ""
    resolution: float = math.nan
    spll_resolution: np.ndarray = field(default_factory=lambda: np.zeros(0))
    longer_resolution: float = math.nan
    neuron_counts: list = field(default_factory=list, repr=False)
    failed: list = field(default_factory=list)
    max_failed: int = MAX_FAILED
    tolerance_basis: str = ""

    @property
    def passed(self) -> bool:
        """The verdict: the total TDE-rate error and that on the encoded inputs alone
        (:attr:`encoded_error`, where there are any) are within :attr:`max_error`, and at
        most :attr:`max_failed` sPLLs fail (:attr:`failed`)."""
        encoded = self.encoded_error
        return bool(self.tde_error <= self.max_error
                    and (math.isnan(encoded) or encoded <= self.max_error)
                    and len(self.failed) <= self.max_failed)  # fmt: skip

    def error_of(self, kinds: Sequence[str]) -> tuple[float, float]:
        """``(TDE-rate error, golden's own)`` over the inputs of ``kinds``: the means of their
        ``tde_rate_error`` and ``golden_shifted_tde_rate_error`` over those on which golden's
        TDEs fire (the total's measure and :attr:`resolution`'s); NaN where there is none."""
        rows = [x for x in self.inputs if x["kind"] in kinds and x["golden_tde_spikes"] > 0]
        return (_mean(x["tde_rate_error"] for x in rows),
                _mean(x.get("golden_shifted_tde_rate_error") for x in rows))  # fmt: skip

    @property
    def encoded_error(self) -> float:
        """The TDE-rate error on the encoded inputs alone (:data:`ENCODED_KINDS`), NaN where
        the check ran none."""
        return self.error_of(ENCODED_KINDS)[0]

    def spll_words(self) -> str:
        """The per-sPLL verdict in one sentence (the README's, the CLI's, a failure's):
        :func:`~.spll_verdict.failure_words`."""
        return failure_words(self.failed, self.spll_tde_error.size, self.free_frequencies,
                             self.max_failed)  # fmt: skip

    @property
    def resolved(self) -> bool:
        """Golden's own variation (:attr:`resolution`) is at most half the limit: an export
        at the limit stands out from it (true where it was not measured, and for a limit of 0,
        which asks for golden's counts exactly)."""
        return self.max_error == 0 or not self.resolution > self.max_error / 2

    def resolution_words(self) -> str:
        """What the resolution means for the verdict, one sentence (the README's and the CLI's)."""
        if math.isnan(self.resolution):
            return ""
        moved = (f"Golden itself, on every input {1e3 * RESOLUTION_SHIFT:g} ms later, is "
                 f"{_pct(self.resolution)} off golden")  # fmt: skip
        if self.max_error == 0:
            return f"{moved}; the limit of 0 asks for golden's counts exactly."
        if self.resolved:
            return f"{moved}: these inputs resolve the limit."
        unresolved = (f"{moved}, more than half the limit: on these inputs golden's own "
                      "variation is as large as the errors the verdict judges, so the verdict "
                      "is not resolved")  # fmt: skip
        longer = self.longer_resolution
        if math.isnan(longer):
            longest = max((x["duration_s"] for x in self.inputs), default=DURATION)
            return f"{unresolved}; longer inputs (`--check-duration`, now {longest:g} s) may."
        on_longer = f"on {LONGER:g} s of each input golden is {_pct(longer)} off itself"
        if not longer > self.max_error / 2:
            return f"{unresolved}; {on_longer}: `--check-duration {LONGER:g}` resolves it."
        return (
            f"{unresolved}, nor on longer ones: {on_longer}. This network's counts hang on the "
            f"timing of its input; on inputs of {LONGER:g} s no limit under "
            f"{_pct(2 * longer)} can be judged."
        )

    @property
    def worst(self) -> int:
        """The sPLL with the largest TDE-count error."""
        return int(np.argmax(self.spll_tde_error))

    def over(self) -> np.ndarray:
        """sPLLs whose TDE-count error exceeds :attr:`max_error`, worst first."""
        idx = np.flatnonzero(self.spll_tde_error > self.max_error)
        return idx[np.argsort(-self.spll_tde_error[idx], kind="stable")]

    def to_json(self) -> dict:
        """``check.json``."""
        return {
            "target": self.target,
            "passed": self.passed,
            "allowed": self.allowed,
            "runs": self.runs,
            "reference": "golden model (exact, event-driven) of the network in params.toml",
            "backend": self.backend,
            "tolerance": self.tolerance,
            "tolerance_basis": self.tolerance_basis,
            "max_error": self.max_error,
            "total": {"tde_rate_error": self.tde_error, "cco_rate_error": self.cco_error},
            "by_kind": self._by_kind(),
            "failed_splls": {
                "count": len(self.failed),
                "max_failed": self.max_failed,
                "criteria": FAILURE_CRITERIA,
                "splls": self.failed,
            },
            "worst_spll": {
                "index": self.worst,
                "tde_count_error": float(self.spll_tde_error[self.worst]),
            },
            "inputs": self.inputs,
            "spll": [
                {
                    "index": i,
                    "free_frequency_hz": float(self.free_frequencies[i]),
                    "tde_spikes": int(self.spll_tde_spikes[i]),
                    "golden_tde_spikes": int(self.spll_golden_tde_spikes[i]),
                    "tde_count_error": float(self.spll_tde_error[i]),
                    "cco_count_error": float(self.spll_cco_error[i]),
                    "golden_shifted_tde_count_error": _entry(self.spll_resolution, i),
                    "failed": next((x["why"] for x in self.failed if x["spll"] == i), None),
                }
                for i in range(self.spll_tde_error.size)
            ],
            "resolution": {
                "shift_s": RESOLUTION_SHIFT,
                "golden_tde_rate_error": _number(self.resolution),
                "resolves_limit": self.resolved,
                "longer_s": LONGER,
                "golden_tde_rate_error_longer": _number(self.longer_resolution),
            },
            "remedies": list(self.remedies),
            "wall_s": round(self.wall_time, 2),
            "from_memory": self.from_memory or None,
        }

    def _by_kind(self) -> dict:
        """``check.json``'s ``by_kind``: per kind of input the check ran, how many, their
        TDE-rate error and golden's own (:meth:`error_of`)."""
        kinds = dict.fromkeys(x["kind"] for x in self.inputs)
        return {kind: dict(zip(("tde_rate_error", "golden_shifted_tde_rate_error"),
                               map(_number, self.error_of([kind])), strict=True))
                | {"inputs": sum(x["kind"] == kind for x in self.inputs)}
                for kind in kinds}  # fmt: skip

    def failure(self) -> str:
        """Why the export is off, how far, which sPLLs fail, and what would help (the
        message of a failed check)."""
        named = self.over()[:WORST_NAMED]
        if not named.size:
            named = np.array([self.worst])
        spllls = ", ".join(
            f"{i} ({self.free_frequencies[i]:.1f} Hz) {_pct(self.spll_tde_error[i])} "
            f"({self.spll_tde_spikes[i]} TDE spikes, golden {self.spll_golden_tde_spikes[i]})"
            for i in named
        )
        many = self.over().size
        return (
            f"{self.target} export is off: {self._off()}; {many} of "
            f"{self.spll_tde_error.size} sPLLs are above the limit in TDE count, worst: "
            f"{spllls}. What would help: "
            + "; ".join(self.remedies)
            + ("" if self.resolved else f". {self.resolution_words().rstrip('.')}")
        )

    @property
    def limit_words(self) -> str:
        """The verdict's limit and where it comes from: the declared tolerance of the backend
        of the same rules at the folder's step (which moves with the step), named with its chip
        profile (:func:`~spll_hw.backends.label`) and, where the backend says, why
        (:attr:`tolerance_basis`), or --max-error."""
        if self.max_error != self.tolerance:
            return f"{_pct(self.max_error)} (--max-error)"
        return (f"{_pct(self.max_error)} (`{backends.label(self.backend)}`'s declared "
                f"tolerance{self._basis_words()})")  # fmt: skip

    def _basis_words(self) -> str:
        """``": WHY"`` where the tolerance has a :attr:`tolerance_basis`, else ``""``."""
        return f": {self.tolerance_basis}" if self.tolerance_basis else ""

    def _off(self) -> str:
        """What of the verdict fails (:attr:`passed`), in words."""
        limit = self.limit_words
        above = "above" if self.tde_error > self.max_error else "within"
        words = [f"TDE-rate error {_pct(self.tde_error)} against the golden model (CCO "
                 f"{_pct(self.cco_error)}) over {len(self.inputs)} inputs, {above} the limit "
                 f"{limit}"]  # fmt: skip
        if self.encoded_error > self.max_error:
            n = sum(x["kind"] in ENCODED_KINDS for x in self.inputs)
            golden = self.error_of(ENCODED_KINDS)[1]
            words.append(f"on its {n} encoded inputs alone (the network's own kind of "
                         f"signal) {_pct(self.encoded_error)}, above the limit (golden "
                         f"{1e3 * RESOLUTION_SHIFT:g} ms later: {_pct(golden)})")  # fmt: skip
        if len(self.failed) > self.max_failed:
            words.append(self.spll_words())
        return "; ".join(words)

    def markdown(self) -> str:
        """The README section: what ran, the verdict and the tables."""
        verdict = "passed" if self.passed else "FAILED"
        lines = [
            SECTION[0],
            "## Check against the golden model",
            "",
            f"{self.runs}. Reference: the golden model (exact, event-driven) of the network in "
            f"`params.toml`. Verdict: **{verdict}**: total TDE-rate error "
            f"{_pct(self.tde_error)} (CCO {_pct(self.cco_error)}), limit {_pct(self.max_error)} "
            f"(`{self.backend}` declares {_pct(self.tolerance)}{self._basis_words()})"
            f"{self._encoded_words()}; "
            f"{self.spll_words()}; worst sPLL "
            f"{self.worst} ({_pct(self.spll_tde_error[self.worst])}). The check took "
            f"{self.wall_time:.1f} s{self._where()}; `spll-hw export --check FOLDER` runs it "
            "again, `check.json` holds the numbers.",
        ]
        if not math.isnan(self.resolution):
            lines += ["", ("" if self.resolved else "**Not resolved.** ")
                      + self.resolution_words()]  # fmt: skip
        shift = f"golden {1e3 * RESOLUTION_SHIFT:g} ms later"
        lines += [
            "",
            "Errors: per input, `sum|r - r_golden| / sum r_golden` over the sPLLs' TDE (CCO) "
            "rates; total, their mean over the inputs on which golden's TDEs fire; per sPLL, "
            "`sum|c - c_golden| / max(sum c_golden, 1)` of its spike counts over all inputs; "
            f"`{shift}`: the same TDE error of golden on the input shifted.",
            "",
            "| input | kind | duration [s] | spikes | golden TDE spikes | TDE-rate error | "
            f"CCO-rate error | {shift} |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for x in self.inputs:
            lines.append(
                f"| {x['label']} | {x['kind']} | {x['duration_s']:g} | {x['n_spikes']} | "
                f"{x['golden_tde_spikes']} | {_pct(x['tde_rate_error'])} | "
                f"{_pct(x['cco_rate_error'])} | {_pct(x.get('golden_shifted_tde_rate_error'))} |"
            )
        lines.append(f"| **total** | | | | | **{_pct(self.tde_error)}** | "
                     f"**{_pct(self.cco_error)}** | {_pct(self.resolution)} |")  # fmt: skip
        lines += ["", f"sPLL verdict: an sPLL fails where {FAILURE_CRITERIA}.", "",
                  "| sPLL | free frequency [Hz] | TDE-count error | CCO-count error | "
                  f"{shift} | fails |", "|---|---|---|---|---|---|"]  # fmt: skip
        why = {x["spll"]: ", ".join(x["why"]) for x in self.failed}
        for i, (f, t, c) in enumerate(
            zip(self.free_frequencies, self.spll_tde_error, self.spll_cco_error, strict=True)
        ):
            mark = " (worst)" if i == self.worst else ""
            lines.append(f"| {i}{mark} | {f:.1f} | {_pct(t)} | {_pct(c)} | "
                         f"{_pct(_entry(self.spll_resolution, i))} | "
                         f"{why.get(i, '')} |")  # fmt: skip
        return "\n".join([*lines, SECTION[1]])

    def _encoded_words(self) -> str:
        """The clause on the encoded inputs' error where the check ran any, else nothing."""
        if math.isnan(self.encoded_error):
            return ""
        golden = self.error_of(ENCODED_KINDS)[1]
        return (f"; on the encoded inputs alone {_pct(self.encoded_error)} (golden "
                f"{1e3 * RESOLUTION_SHIFT:g} ms later: {_pct(golden)})")  # fmt: skip

    def _where(self) -> str:
        """Where the check ran, if not on the folder: what the README says after its time."""
        if not self.from_memory:
            return ""
        return (f" (run from memory before the folder was written, by {self.from_memory}, on "
                "exactly what the folder reads back as)")  # fmt: skip

    def warning(self) -> str:
        """The block at the top of the README of an export kept although it is off."""
        return "\n".join([
            WARNING[0],
            f"> **Warning: this export is off.** Its check against the golden model failed "
            f"({self._off()})"
            + ("; it was written anyway (`--allow-error`)" if self.allowed else "")
            + ". See the check below.",
            WARNING[1],
        ])  # fmt: skip


def _pct(x) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:.1f} %"


def check_run(
    run: FolderRun,
    target: str,
    network: Network,
    *,
    inputs: Sequence[CheckInput] | None = None,
    max_error: float | None = None,
    allowed: bool = False,
    duration: float = DURATION,
    start: float | None = None,
    max_failed: int | None = None,
) -> CheckReport:
    """:func:`.folder_check.check_folder` on what simulates a folder (its read-back ``run``), or
    on a :meth:`FolderRun.by_backend` of the backend that runs what would be written, with no
    folder at all (``spll-hw export --to nir-standard`` choosing its ``dt``); ``start``: the
    :func:`time.perf_counter` the check's wall time counts from (default: now)."""
    start = time.perf_counter() if start is None else start
    capabilities = run.backend.capabilities
    tolerance = float(capabilities.rate_tolerance)
    limit = verdict_limit(run, max_error)
    most = failed_limit(max_failed)
    every = [*reference_inputs(network, duration), *(inputs or ())]
    mine: list = [None] * len(every)
    golden: list = [None] * len(every)
    moved: list = [None] * len(every)  # golden on each input RESOLUTION_SHIFT later
    for duration in dict.fromkeys(x.duration for x in every):  # one batch per run length
        idx = [i for i, x in enumerate(every) if x.duration == duration]
        trains = [every[i].spikes for i in idx]
        later = [shifted(x, RESOLUTION_SHIFT, duration) for x in trains]
        golden_runs = backends.get("golden").simulate_batch(network, [*trains, *later], duration)
        for k, (i, r) in enumerate(zip(idx, run.simulate(trains, duration), strict=True)):
            mine[i], golden[i], moved[i] = r, golden_runs[k], golden_runs[len(idx) + k]
    rows = [_input_row(i, *runs)
            for i, runs in enumerate(zip(every, mine, golden, moved, strict=True))]  # fmt: skip
    fired = [row for row in rows if row["golden_tde_spikes"] > 0]
    if not fired:  # golden's TDEs never fire: all right only if the export's do not either
        silent = all(row["tde_spikes"] == 0 for row in rows)
        for row in rows:
            row["tde_rate_error"] = 0.0 if silent else 1.0
            row["golden_shifted_tde_rate_error"] = 0.0
        fired = rows
    tde_spikes = np.sum([r.tde_counts for r in mine], axis=0)
    golden_spikes = np.sum([g.tde_counts for g in golden], axis=0)
    report = CheckReport(
        target=target, runs=run.runs, backend=run.backend.spec, tolerance=tolerance,
        max_error=limit, inputs=rows,
        tde_error=_mean(row["tde_rate_error"] for row in fired),
        cco_error=_mean(row["cco_rate_error"] for row in fired),
        spll_tde_error=count_error(mine, golden, "tde"),
        spll_cco_error=count_error(mine, golden, "cco"),
        spll_tde_spikes=tde_spikes,
        spll_golden_tde_spikes=golden_spikes,
        free_frequencies=np.asarray(network.free_frequencies(), dtype=float),
        wall_time=time.perf_counter() - start, remedies=run.remedies, allowed=allowed,
        trains=every,
        resolution=_moved_error(golden, moved),
        spll_resolution=count_error(moved, golden, "tde"),
        neuron_counts=[r.info.get(COUNTS_KEY) for r in mine],
        failed=spll_failures(tde_spikes, golden_spikes, open_loop(run, network),
                             sum(x.duration for x in every)),
        max_failed=most, tolerance_basis=capabilities.tolerance_basis,
    )  # fmt: skip
    if report.resolved or max(x.duration for x in every) >= LONGER:
        return report
    return replace(report, longer_resolution=golden_resolution(network, LONGER))


def golden_resolution(
    network: Network, duration: float, inputs: Sequence[CheckInput] = ()
) -> float:
    """Golden's own variation on the check's reference inputs of ``duration`` [s] and on
    ``inputs`` (each run for its own length): its check's total TDE-rate error on every input
    :data:`RESOLUTION_SHIFT` later (:attr:`CheckReport.resolution`; golden alone, seconds)."""
    every = [*reference_inputs(network, duration), *inputs]
    golden: list[SimulationResult] = []
    moved: list[SimulationResult] = []
    for length in dict.fromkeys(x.duration for x in every):  # one batch per run length
        trains = [x.spikes for x in every if x.duration == length]
        later = [shifted(x, RESOLUTION_SHIFT, length) for x in trains]
        runs = backends.get("golden").simulate_batch(network, [*trains, *later], length)
        golden += runs[: len(trains)]
        moved += runs[len(trains) :]
    return _moved_error(golden, moved)


def _moved_error(golden: list[SimulationResult], moved: list[SimulationResult]) -> float:
    """The check's resolution from golden's runs on each input and on it moved: the mean
    TDE-rate error of ``moved`` against ``golden`` over the inputs on which golden's TDEs fire
    (0 where they fire on none, as the verdict's total)."""
    pairs = [(g, m) for g, m in zip(golden, moved, strict=True) if g.tde_counts.sum() > 0]
    return _mean(_number(rate_error(m, g, "tde")) for g, m in pairs) if pairs else 0.0


def verdict_limit(run: FolderRun, max_error: float | None) -> float:
    """The verdict's limit: ``max_error`` (:func:`~spll_hw.exporters.check_limit`, which
    refuses what is not a fraction >= 0), or the declared tolerance of ``run``'s backend."""
    limit = check_limit(max_error)
    return float(run.backend.capabilities.rate_tolerance if limit is None else limit)


def _input_row(i: int, x: CheckInput, mine: SimulationResult, golden: SimulationResult,
               moved: SimulationResult) -> dict:  # fmt: skip
    """Input ``i``'s row of ``check.json``: what it is, where its train is in
    :data:`~.check_files.INPUTS_FILE`, spike totals, errors (``moved``: golden on the input
    :data:`RESOLUTION_SHIFT` later, the resolution) and the folder's counts per sPLL."""
    return x.describe() | {
        "train": train_key(i),
        "golden_tde_spikes": int(golden.tde_counts.sum()),
        "tde_spikes": int(mine.tde_counts.sum()),
        "golden_cco_spikes": int(golden.cco_counts.sum()),
        "cco_spikes": int(mine.cco_counts.sum()),
        "tde_rate_error": _number(rate_error(mine, golden, "tde")),
        "cco_rate_error": _number(rate_error(mine, golden, "cco")),
        "golden_shifted_tde_rate_error": _number(rate_error(moved, golden, "tde")),
        "tde_counts": np.asarray(mine.tde_counts, dtype=int).tolist(),
        "cco_counts": np.asarray(mine.cco_counts, dtype=int).tolist(),
    }


def train_key(i: int) -> str:
    """The name of input ``i``'s train in :data:`~.check_files.INPUTS_FILE`."""
    return f"train{i}"


def _number(x: float) -> float | None:
    return None if math.isnan(x) else x


def _entry(values: np.ndarray, i: int) -> float | None:
    """``values[i]``, or None where ``values`` was not measured (empty)."""
    return float(values[i]) if i < len(values) else None


def _mean(values) -> float:
    finite = [v for v in values if v is not None]
    return float(np.mean(finite)) if finite else math.nan
