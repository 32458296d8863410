"""Classification accuracy of an sPLL network per layout × hardware constraint profile.

The samples are encoded once; every (layout, profile) cell builds the network of that layout,
computes the TDE-rate features on a backend (:mod:`spll_hw.backends`) that realises it on the
profile (``none`` leaves it exact) and cross-validates the ridge classifier. The reference cell is
the unconstrained time-scaled network, the thesis's best layout; every other cell reports its
accuracy loss against it. With the golden backend a digital profile gives two cells:
``golden:profile=P``, its quantized parameters in the exact model (the effect of the number
formats), and ``golden-fixed-point:profile=P`` (adding the time step and integer arithmetic,
i.e. what the chip computes). Another ``backend`` (a Brian2 device, Lava, the fixed-point
reference itself) computes every column instead.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import backends, chips
from ..classify import CVResult, combine, cross_validate
from ..config import NetworkConfig
from ..datasets import SampleSet
from ..encoders import Encoder, train_duration
from ..features.spll import spll_features
from ..pipeline import encode_samples, jitter

REFERENCE = ("time-scaled", "none")
DEFAULT_LAYOUTS = ("time-scaled", "vary-offset", "grouped:2", "grouped:4", "grouped:8")


@dataclass
class AccuracyCell:
    """One layout under one constraint profile; ``cv`` is ``None`` when the layout does not fit
    the profile (``report`` then says why)."""

    layout: str
    profile: str
    cv: CVResult | None
    report: str = ""  # the profile's per-parameter quantization report (Markdown)
    backend: str = "golden"  # the spec of the backend that computed the features


@dataclass
class AccuracyTable:
    """All cells of one run."""

    cells: list[AccuracyCell] = field(default_factory=list)

    def cell(self, layout: str, profile: str) -> AccuracyCell:
        for c in self.cells:
            if (c.layout, c.profile) == (layout, profile):
                return c
        raise KeyError((layout, profile))

    def loss(self, layout: str, profile: str) -> float:
        """Accuracy loss [fraction] against the unconstrained time-scaled network (NaN where
        either does not fit)."""
        ref, cell = self.cell(*REFERENCE).cv, self.cell(layout, profile).cv
        return ref.accuracy - cell.accuracy if ref and cell else float("nan")

    def markdown(self) -> str:
        """Accuracy (mean ± sd over folds) and loss per layout (rows) × profile (columns)."""
        layouts = list(dict.fromkeys(c.layout for c in self.cells))
        profiles = list(dict.fromkeys(c.profile for c in self.cells))
        has_reference = any((c.layout, c.profile) == REFERENCE for c in self.cells)
        lines = ["| layout | " + " | ".join(profiles) + " |", "|---" * (len(profiles) + 1) + "|"]
        for layout in layouts:
            row = []
            for profile in profiles:
                c = self.cell(layout, profile)
                if c.cv is None:
                    row.append("does not fit")
                    continue
                text = f"{100 * c.cv.accuracy:.1f} ± {100 * c.cv.accuracy_sd:.1f} %"
                if has_reference and (layout, profile) != REFERENCE:
                    text += f" ({-100 * self.loss(layout, profile):+.1f})"
                row.append(text)
            lines.append(f"| {layout} | " + " | ".join(row) + " |")
        return "\n".join(lines)


@dataclass(frozen=True)
class Column:
    """One column of the table: ``label`` (``"none"``, a profile, ``"<profile> (chip)"``) and
    the backend ``spec`` that computes its features."""

    label: str
    profile: str
    spec: str


def columns(profiles: Sequence[str], backend: str = "golden", chip: bool = True) -> list[Column]:
    """The backend of every profile column (checked before any work: an unknown or broken
    profile or backend raises ``ValueError``).

    ``none`` is ``backend`` itself (``golden`` when ``backend`` has integer arithmetic and so
    always a chip profile); profile ``P`` is ``backend:profile=P``, the network as the chip
    realises it on that backend (the golden model of an analog profile when ``backend`` is a
    fixed-point one). With ``chip``, a fixed-point profile also gets ``"P (chip)"``:
    ``golden-fixed-point:profile=P``, what the chip computes (its time step and integers).
    """
    base = backends.get(backend)
    fixed = base.capabilities.arithmetic == "fixed"
    out = []
    for profile in profiles:
        if profile == "none":
            out.append(Column("none", "none", "golden" if fixed else base.spec))
            continue
        kind = chips.describe(profile).kind
        if fixed and kind != "fixed-point":
            out.append(Column(profile, profile, backends.get("golden", profile=profile).spec))
            continue
        out.append(Column(profile, profile, backends.get(base, profile=profile).spec))
        if chip and not fixed and kind == "fixed-point":
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
    jobs: int = 1,
    chip: bool = True,
    on_cell: Callable[[AccuracyCell], None] | None = None,
) -> AccuracyTable:
    """Accuracy of every layout × profile column (module docstring; :func:`columns` says which
    backend computes each column's features). ``repeats`` phase-noise draws of ``phase_noise``
    seconds each train their own classifiers, pooled as in the thesis."""
    cols = columns(profiles, backend, chip)
    samples = samples.normalized()
    trains = encode_samples(encoder, samples, jobs)
    window = train_duration(encoder, samples.duration)
    noisy = [jitter(trains, phase_noise, window, seed + r) for r in range(repeats)]
    table = AccuracyTable()

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
            cvs = []
            for x in noisy:
                features = spll_features(x, window, network, threads=jobs, backend=col.spec)
                cvs.append(cross_validate(features, samples.labels, samples.class_names,
                                          n_splits, seed=seed))  # fmt: skip
            chip_column = col.label.endswith("(chip)")
            add(AccuracyCell(layout, col.label, combine(cvs), "" if chip_column else report,
                             col.spec))  # fmt: skip
    return table


def accuracy_summary(table: AccuracyTable) -> dict:
    """JSON-ready accuracies: ``{layout: {profile: {"mean", "sd", "loss"}}}``."""
    has_reference = any((c.layout, c.profile) == REFERENCE for c in table.cells)
    out: dict = {}
    for c in table.cells:
        if c.cv is None:
            out.setdefault(c.layout, {})[c.profile] = {"fits": False, "why": c.report}
            continue
        loss = table.loss(c.layout, c.profile) if has_reference else float("nan")
        out.setdefault(c.layout, {})[c.profile] = {
            "fits": True, "backend": c.backend, "mean": c.cv.accuracy, "sd": c.cv.accuracy_sd,
            "loss": float(np.round(loss, 6)),
        }  # fmt: skip
    return out
