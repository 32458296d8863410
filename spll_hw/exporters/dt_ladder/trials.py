"""One rung of the step ladder: a :class:`Trial` (a step, gate and hold with its export check)
and a target's :class:`Parts`; :func:`trial` checks what a target would write at a step, from
memory, no folder written."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from spll_hw.backends.base import Backend
from spll_hw.construction.gate import DEFAULT_PLACEMENT
from spll_hw.exporters import FolderRun, MemoryCheck, check
from spll_hw.exporters.check_files import reference_duration
from spll_hw.exporters.check_inputs import DURATION
from spll_hw.exporters.judged_on import extras
from spll_hw.network import Network


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
        """Whether its check passes as the folder's will be judged: the total within the
        limit and, where it ran, the whole verdict (the encoded inputs' own error, the sPLLs
        that fail: :attr:`~spll_hw.exporters.check.CheckReport.passed`)."""
        if self.error is None or self.error > self.limit:
            return False
        return self.checked is None or self.checked.report.passed

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
        if not self.passed and self.error <= self.limit:  # the rest of the verdict fails it
            report = self.checked.report
            why = [f"on the encoded inputs {percent(report.encoded_error)}"] if (
                report.encoded_error > report.max_error) else []  # fmt: skip
            why += [report.spll_words()] if len(report.failed) > report.max_failed else []
            verdict += f" ({'; '.join(why)})"
        return (f"TDE-rate error {100 * self.error:.1f} %{self.on}, limit {percent(self.limit)}: "
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
    try:
        backend.prepared(network)  # what would be written, kept for the check's runs
    except ValueError as exc:
        return replace(base, reason=str(exc))
    run = FolderRun.by_backend(f"{backend.name} at {at}", backend, network)
    extra = extras()  # the folder's check's own extra inputs and per-sPLL allowance
    report = check.check_run(run, target, network, inputs=extra.inputs, duration=duration,
                             max_failed=extra.max_failed)  # fmt: skip
    return replace(base, error=report.tde_error, limit=report.max_error,
                   spll_error=report.spll_tde_error, checked=MemoryCheck(run, report))  # fmt: skip


#: A target's trial: ``trial(network, dt, placement, levels, hold, duration)``, :func:`trial`
#: with its own :class:`Parts`.
TargetTrial = Callable[[Network, float, str, int | None, str | None, float], Trial]


def percent(x: float) -> str:
    return f"{100 * x:.3g} %"
