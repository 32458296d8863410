"""Classification accuracy of an sPLL network per layout × hardware constraint profile.

The samples are encoded once; every (layout, profile) cell builds the network of that layout,
computes the TDE-rate features on a backend (:mod:`spll_hw.backends`) that realises it on the
profile (``none`` leaves it exact) and cross-validates the ridge classifier. The reference cell is
the unconstrained time-scaled network, the thesis's best layout; every other cell reports its
accuracy change against it (cell minus reference: negative is a loss). With the golden
backend a digital profile gives two cells: ``golden:profile=P``, its quantized parameters in
the exact model (the effect of the number formats), and ``golden-fixed-point:profile=P``
(adding the time step and integer arithmetic, i.e. what the chip computes). Another
``backend`` (a Brian2 device, Lava, the fixed-point reference itself) computes every column
instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import backends, chips
from ..classify import CVResult, HoldoutResult, combine, cross_validate, holdout
from ..config import NetworkConfig
from ..datasets import SampleSet
from ..encoders import Encoder, train_duration
from ..features.spll import spll_features
from ..pipeline import encode_samples, jitter
from ..stats import Interval

REFERENCE = ("time-scaled", "none")
DEFAULT_LAYOUTS = ("time-scaled", "vary-offset", "grouped:2", "grouped:4", "grouped:8")


@dataclass
class AccuracyCell:
    """One layout under one constraint profile; ``cv`` is ``None`` when the layout does not fit
    the profile (``report`` then says why)."""

    layout: str
    profile: str
    cv: CVResult | HoldoutResult | None
    report: str = ""  # the profile's per-parameter quantization report (Markdown)
    backend: str = "golden"  # the spec of the backend that computed the features


@dataclass
class AccuracyTable:
    """All cells of one run, scored on the same folds (so any two cells pair fold by fold)."""

    cells: list[AccuracyCell] = field(default_factory=list)

    def cell(self, layout: str, profile: str) -> AccuracyCell:
        for c in self.cells:
            if (c.layout, c.profile) == (layout, profile):
                return c
        raise KeyError((layout, profile))

    @property
    def has_reference(self) -> bool:
        return any((c.layout, c.profile) == REFERENCE and c.cv for c in self.cells)

    def change_ci(self, layout: str, profile: str) -> Interval | None:
        """Paired 95 % interval of the accuracy change [fraction] against the reference cell
        (negative: a loss): fold by fold under cross-validation, by a bootstrap over the test
        recordings when held out (``change_against`` of the results); ``None`` where either does
        not fit."""
        ref, cell = self.cell(*REFERENCE).cv, self.cell(layout, profile).cv
        if not (ref and cell):
            return None
        return cell.change_against(ref)

    def markdown(self) -> str:
        """Accuracy (mean ± 95 % CI half-width over folds) and its paired change against the
        reference with its 95 % CI, per layout (rows) × profile (columns); a change in bold is
        distinguishable from zero, one in plain text a tie."""
        layouts = list(dict.fromkeys(c.layout for c in self.cells))
        profiles = list(dict.fromkeys(c.profile for c in self.cells))
        lines = ["| layout | " + " | ".join(profiles) + " |", "|---" * (len(profiles) + 1) + "|"]
        for layout in layouts:
            row = []
            for profile in profiles:
                c = self.cell(layout, profile)
                if c.cv is None:
                    row.append("does not fit")
                    continue
                text = accuracy_text(c.cv)
                if self.has_reference and (layout, profile) != REFERENCE:
                    text += " (" + change_text(self.change_ci(layout, profile)) + ")"
                row.append(text)
            lines.append(f"| {layout} | " + " | ".join(row) + " |")
        return "\n".join(lines)


def accuracy_text(cv: CVResult | HoldoutResult) -> str:
    """``54.6 ± 1.8 %``: the accuracy and the half-width of its 95 % CI."""
    ci = cv.accuracy_ci()
    return f"{100 * ci.mean:.1f} ± {100 * ci.half_width:.1f} %"


def change_text(ci: Interval) -> str:
    """``**-7.9** [-11.9, -3.9]`` (bold: distinguishable from zero) in accuracy points."""
    mean = f"{100 * ci.mean:+.1f}"
    return f"{f'**{mean}**' if ci.distinct else mean} [{100 * ci.low:+.1f}, {100 * ci.high:+.1f}]"


@dataclass(frozen=True)
class Column:
    """One column of the table: ``label`` (``"none"``, a profile, ``"<profile> (chip)"``), the
    backend ``spec`` that computes its features and, for an analog profile, one spec per
    mismatch draw (``draws``; otherwise just ``spec``)."""

    label: str
    profile: str
    spec: str
    draws: tuple[str, ...] = ()

    @property
    def specs(self) -> tuple[str, ...]:
        return self.draws or (self.spec,)


def columns(
    profiles: Sequence[str], backend: str = "golden", chip: bool = True, chip_draws: int = 5
) -> list[Column]:
    """The backend of every profile column (checked before any work: an unknown or broken
    profile or backend raises ``ValueError``).

    ``none`` is ``backend`` itself (``golden`` when ``backend`` has integer arithmetic and so
    always a chip profile); profile ``P`` is ``backend:profile=P``, the network as the chip
    realises it on that backend (the golden model of an analog profile when ``backend`` is a
    fixed-point one). With ``chip``, a fixed-point profile also gets ``"P (chip)"``:
    ``golden-fixed-point:profile=P``, what the chip computes (its time step and integers). An
    analog profile's column pools ``chip_draws`` mismatch draws (``chip_seed`` 0, 1, ...), so
    its accuracy is that of the chip family, not of one chip.
    """
    if isinstance(chip_draws, bool) or not isinstance(chip_draws, int) or chip_draws < 1:
        raise ValueError(f"chip draws must be an integer >= 1, got {chip_draws!r}")
    base = backends.get(backend)
    fixed = base.capabilities.arithmetic == "fixed"
    out = []
    for profile in profiles:
        if profile == "none":
            out.append(Column("none", "none", "golden" if fixed else base.spec))
            continue
        info = chips.describe(profile)
        own = backends.get("golden" if fixed and not info.clocked else base, profile=profile)
        if info.mismatch:
            draws = tuple(backends.get(own, chip_seed=k).spec for k in range(chip_draws))
            out.append(Column(profile, profile, own.spec, draws))
            continue
        out.append(Column(profile, profile, own.spec))
        if chip and not fixed and info.clocked:
            chip_spec = backends.get("golden-fixed-point", profile=profile).spec
            out.append(Column(f"{profile} (chip)", profile, chip_spec))
    return out


def layout_accuracy(
    samples: SampleSet,
    encoder: Encoder,
    config: NetworkConfig,
    layouts: Sequence[str] = DEFAULT_LAYOUTS,
    profiles: Sequence[str] = ("none",),
    *,
    backend: str = "golden",
    phase_noise: float = 0.0,
    repeats: int = 1,
    seed: int = 0,
    n_splits: int = 5,
    cv_repeats: int = 1,
    by_recording: bool = False,
    test: SampleSet | None = None,
    chip_draws: int = 5,
    jobs: int = 1,
    chip: bool = True,
    on_cell: Callable[[AccuracyCell], None] | None = None,
    input_level: float | None = None,
) -> AccuracyTable:
    """Accuracy of every layout × profile column (module docstring; :func:`columns` says which
    backend computes each column's features).

    Every cell is scored on the same folds: ``cv_repeats`` × ``n_splits`` stratified folds
    (grouped by recording with ``by_recording``, :attr:`SampleSet.recordings`), for each of
    ``repeats`` phase-noise draws of ``phase_noise`` seconds and, for an analog profile, each of
    ``chip_draws`` mismatch draws; a cell pools them draw-major, so any two cells pair fold by
    fold (:meth:`AccuracyTable.change_ci`).

    With ``test`` (held-out recordings of the same classes) every cell instead trains on all of
    ``samples`` and is scored once on ``test`` (:func:`~spll_hw.classify.holdout`), with
    intervals by a bootstrap over the test recordings. Signals are divided by ``input_level``
    (the level the network file's encoder was tuned at) or, without one, by the median RMS of
    ``samples`` (:meth:`~spll_hw.datasets.SampleSet.input_scale`).
    """
    cols = columns(profiles, backend, chip, chip_draws)
    level, source = samples.input_scale(input_level)
    samples = samples.normalized(level, source)
    window = train_duration(encoder, samples.duration)
    trains = encode_samples(encoder, samples, jobs)
    noisy = [jitter(trains, phase_noise, window, seed + r) for r in range(repeats)]
    if test is not None:
        test = test.normalized(level, source)  # scaled like the training samples
        test_trains = encode_samples(encoder, test, jobs)
        noisy_test = [jitter(test_trains, phase_noise, window, seed + 10_000 + r)
                      for r in range(repeats)]  # fmt: skip
    groups = samples.recordings if by_recording else None
    table = AccuracyTable()

    def score(spec: str, network, r: int):
        features = spll_features(noisy[r], window, network, threads=jobs, backend=spec)
        if test is None:
            return cross_validate(
                features, samples.labels, samples.class_names, n_splits, seed=seed,
                repeats=cv_repeats, groups=groups,
            )  # fmt: skip
        held = spll_features(noisy_test[r], window, network, threads=jobs, backend=spec)
        return holdout(features, samples.labels, held, test.labels, test.recordings,
                       samples.class_names, seed=seed)  # fmt: skip

    def add(cell: AccuracyCell) -> None:
        table.cells.append(cell)
        if on_cell is not None:
            on_cell(cell)

    for layout in layouts:
        network = config.with_layout(layout).build()
        for col in cols:
            report = ""
            if col.profile != "none":
                try:  # e.g. more time-scale groups than the chip has
                    report = chips.realise(network, col.profile).report
                except ValueError as exc:
                    add(AccuracyCell(layout, col.label, None, f"does not fit: {exc}", col.spec))
                    continue
            cvs = [score(spec, network, r) for spec in col.specs for r in range(repeats)]
            chip_column = col.label.endswith("(chip)")
            add(AccuracyCell(layout, col.label, combine(cvs), "" if chip_column else report,
                             col.spec))  # fmt: skip
    return table


def accuracy_summary(table: AccuracyTable) -> dict:
    """JSON-ready accuracies: ``{layout: {profile: cell}}``, each fitting cell with its
    ``backend``, ``mean``, ``sd`` and ``ci`` (95 %) over folds, ``change`` against the
    reference (a fraction, this cell minus the reference: negative = worse) and its paired
    interval ``change_ci`` (``distinct`` when it excludes zero), and every per-fold, per-draw
    score (``fold_accuracies``, draw-major
    with ``n_folds`` folds per draw; held out: ``correct``, the per-sample hits per draw)."""
    out: dict = {}
    for c in table.cells:
        if c.cv is None:
            out.setdefault(c.layout, {})[c.profile] = {"fits": False, "why": c.report}
            continue
        cell = {
            "fits": True, "backend": c.backend, "mean": c.cv.accuracy, "sd": c.cv.accuracy_sd,
            "ci": c.cv.accuracy_ci().to_dict(),
        }  # fmt: skip
        if isinstance(c.cv, CVResult):
            cell |= {"n_splits": c.cv.n_splits, "n_folds": c.cv.n_folds,
                     "fold_accuracies": list(c.cv.fold_accuracies)}  # fmt: skip
        else:  # held out: one row of per-sample hits per draw
            cell |= {"correct": c.cv.correct.astype(int).tolist()}
        if table.has_reference:
            reference = table.cell(*REFERENCE).cv.accuracy
            cell["change"] = float(np.round(c.cv.accuracy - reference, 6))
            cell["change_ci"] = table.change_ci(c.layout, c.profile).to_dict()
        out.setdefault(c.layout, {})[c.profile] = cell
    return out
