"""Classification accuracy of an sPLL network per layout × hardware constraint profile.

The samples are encoded once; every (layout, profile) cell builds the network of that layout,
constrains it to the profile (``quantize``; ``none`` leaves it exact), computes the TDE-rate
features with the golden engine and cross-validates the ridge classifier. The reference cell is
the unconstrained time-scaled network, the thesis's best layout; every other cell reports its
accuracy loss against it. A digital profile gives two cells: its quantized parameters in the
golden model (the effect of the number formats) and its fixed-point reference (adding the time
step and integer arithmetic, i.e. what the chip computes).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..classify import CVResult, combine, cross_validate
from ..config import NetworkConfig
from ..datasets import SampleSet
from ..encoders import Encoder, train_duration
from ..features.spll import spll_features
from ..network import Network
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


def constrain(network: Network, profile: str):
    """``network`` under chip profile ``profile`` (a quantize/ profile name or TOML path):
    ``(realised network, quantization report, QuantizedNetwork)``; ``"none"`` returns
    ``(network, "", None)``. Raises ``ValueError`` when the network does not fit the profile."""
    if profile == "none":
        return network, "", None
    import quantize

    q = quantize.quantize(network, quantize.load_profile(profile))
    return q.network, q.report_markdown(), q


def _chip_features(q, trains, duration: float, jobs: int) -> np.ndarray:
    """TDE rates [Hz] of the fixed-point reference of ``q`` (the chip itself), ``(n, N)``."""
    import quantize

    results = quantize.simulate_fixed_point_batch(q, trains, duration, threads=jobs)
    return np.array([r.tde_rates for r in results])


def layout_accuracy(
    samples: SampleSet,
    encoder: Encoder,
    config: NetworkConfig,
    layouts: Sequence[str] = DEFAULT_LAYOUTS,
    profiles: Sequence[str] = ("none",),
    *,
    phase_noise: float = 0.0,
    repeats: int = 1,
    seed: int = 0,
    n_splits: int = 5,
    jobs: int = 1,
    chip: bool = True,
    on_cell: Callable[[AccuracyCell], None] | None = None,
) -> AccuracyTable:
    """Accuracy of every layout × profile (module docstring). ``repeats`` phase-noise draws of
    ``phase_noise`` seconds each train their own classifiers, pooled as in the thesis. With
    ``chip``, every fixed-point profile gets a second column, ``"<profile> (chip)"``: the
    features from the discrete-time fixed-point reference (what the chip computes) instead of
    the golden model of the quantized parameters."""
    samples = samples.normalized()
    trains = encode_samples(encoder, samples, jobs)
    window = train_duration(encoder, samples.duration)
    noisy = [jitter(trains, phase_noise, window, seed + r) for r in range(repeats)]
    table = AccuracyTable()

    def evaluate(layout: str, profile: str, features_of, report: str) -> None:
        cvs = []
        for x in noisy:
            features = features_of(x)
            cvs.append(cross_validate(features, samples.labels, samples.class_names,
                                      n_splits, seed=seed))  # fmt: skip
        table.cells.append(AccuracyCell(layout, profile, combine(cvs), report))
        if on_cell is not None:
            on_cell(table.cells[-1])

    for layout in layouts:
        base = config.with_layout(layout).build()
        for profile in profiles:
            try:
                network, report, q = constrain(base, profile)
            except ValueError as exc:  # e.g. more time-scale groups than the chip has
                table.cells.append(AccuracyCell(layout, profile, None, f"does not fit: {exc}"))
                if on_cell is not None:
                    on_cell(table.cells[-1])
                continue

            def golden(x, n=network):
                return spll_features(x, window, n, threads=jobs)

            evaluate(layout, profile, golden, report)
            if chip and q is not None and q.fixed is not None:

                def on_chip(x, q=q):
                    return _chip_features(q, x, window, jobs)

                evaluate(layout, f"{profile} (chip)", on_chip, "")
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
            "fits": True, "mean": c.cv.accuracy, "sd": c.cv.accuracy_sd,
            "loss": float(np.round(loss, 6)),
        }  # fmt: skip
    return out
