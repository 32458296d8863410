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
from ..neuron_graph import at_step, runs_construction
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

    def scored(self) -> list[ScoredCell]:
        """Every cell as plain numbers (:class:`ScoredCell`), with its paired change against
        the reference cell (none without a fitting reference cell): fold by fold under
        cross-validation, by a bootstrap over the test recordings when held out
        (``change_against`` of the results)."""
        reference = self.cell(*REFERENCE).cv if self.has_reference else None
        out = []
        for c in self.cells:
            if c.cv is None:
                out.append(ScoredCell(c.layout, c.profile, c.backend, c.report))
                continue
            if isinstance(c.cv, CVResult):
                scores = {"n_splits": c.cv.n_splits, "n_folds": c.cv.n_folds,
                          "fold_accuracies": list(c.cv.fold_accuracies)}  # fmt: skip
            else:  # held out: one row of per-sample hits per draw
                scores = {"correct": c.cv.correct.astype(int).tolist()}
            change = difference = None
            if reference is not None:
                change = c.cv.change_against(reference)
                difference = float(np.round(c.cv.accuracy - reference.accuracy, 6))
            out.append(ScoredCell(
                c.layout, c.profile, c.backend, c.report, c.cv.accuracy_ci(), c.cv.accuracy,
                c.cv.accuracy_sd, scores, change, difference, c.cv.confusion_normalized(),
            ))  # fmt: skip
        return out


@dataclass(frozen=True)
class ScoredCell:
    """One layout × column of a scored :class:`AccuracyTable` as plain numbers: all that the
    report writes of it, nothing left to compute.

    Attributes:
        layout: the layout.
        column: the column's label (:class:`Column`).
        backend: the spec of the backend that computed the features.
        report: why the layout does not fit, or the profile's per-parameter quantization
            report (Markdown; ``""``: none).
        accuracy: the accuracy [fraction] with its 95 % CI (``None``: does not fit).
        mean: the mean accuracy over folds or test samples [fraction].
        sd: its standard deviation over folds (over draws when held out) [fraction].
        scores: every score, JSON-ready: ``n_splits``, ``n_folds`` and ``fold_accuracies``
            (draw-major, ``n_folds`` per draw) under cross-validation; ``correct`` (per-sample
            hits, one row per draw) on held-out recordings.
        change: the paired change against the reference cell [fraction] with its 95 % CI
            (this cell minus the reference: negative is a loss; ``None`` without a fitting
            reference cell).
        difference: ``mean`` minus the reference's, rounded to 6 digits (``None`` likewise).
        confusion: the row-normalised confusion matrix, shape ``(k, k)`` (rows: true class).
    """

    layout: str
    column: str
    backend: str
    report: str = ""
    accuracy: Interval | None = None
    mean: float | None = None
    sd: float | None = None
    scores: dict = field(default_factory=dict)
    change: Interval | None = None
    difference: float | None = None
    confusion: np.ndarray | None = None

    def to_dict(self) -> dict:
        """The cell in ``results.json``: ``fits`` and ``why``, or ``backend``, ``mean``,
        ``sd``, ``ci`` (95 %), the scores and, with a reference, ``change`` and its paired
        interval ``change_ci`` (``distinct`` when it excludes zero)."""
        if self.accuracy is None:
            return {"fits": False, "why": self.report}
        out = {
            "fits": True, "backend": self.backend, "mean": self.mean, "sd": self.sd,
            "ci": self.accuracy.to_dict(),
        } | self.scores  # fmt: skip
        if self.change is not None:
            out |= {"change": self.difference, "change_ci": self.change.to_dict()}
        return out


@dataclass(frozen=True)
class Column:
    """One column of the table: ``label`` (``"none"``, a profile, ``"<profile> (chip)"``), the
    backend ``spec`` that computes its features and, for an analog profile, one spec per
    mismatch draw (``draws``; otherwise just ``spec``). ``construction``: the backend runs a
    construction of standard neurons (:func:`spll_hw.neuron_graph.runs_construction`) at its
    own step, or at the profile's where the profile is stepped; the profile then prices it
    (cores, energy) and does not realise the two-compartment sPLL."""

    label: str
    profile: str
    spec: str
    draws: tuple[str, ...] = ()
    construction: bool = False

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

    A ``backend`` that runs a construction of standard neurons (``nir-numpy``,
    ``standard-fixed-point``) computes every column itself, as a chip would run what it
    writes: at its own step, at the profile's step under a stepped ``NAME@STEP``
    (:func:`spll_hw.neuron_graph.at_step`).
    """
    if isinstance(chip_draws, bool) or not isinstance(chip_draws, int) or chip_draws < 1:
        raise ValueError(f"chip draws must be an integer >= 1, got {chip_draws!r}")
    base = backends.get(backend)
    if runs_construction(base):
        return [
            Column(p, p, (base if p == "none" else at_step(base, p)).spec, construction=True)
            for p in profiles
            if p == "none" or chips.describe(p)  # checks the profile's name
        ]
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
    fold (:meth:`AccuracyTable.scored`).

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
            if col.construction:  # what the target writes, whatever the chip's formats
                try:  # e.g. a refractory period the target's step cannot hold
                    backends.get(col.spec).prepare(network)
                except ValueError as exc:
                    add(AccuracyCell(layout, col.label, None, f"does not fit: {exc}", col.spec))
                    continue
            elif col.profile != "none":
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
