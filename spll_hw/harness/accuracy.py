"""Classification accuracy of an sPLL network per layout × hardware constraint profile.

The samples are encoded once; every (layout, profile) cell builds the network of that layout,
constrains it to the profile (``quantize``; ``none`` leaves it exact), computes the TDE-rate
features with the golden engine and cross-validates the ridge classifier. The reference cell is
the unconstrained time-scaled network, the thesis's best layout; every other cell reports its
accuracy loss against it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..classify import CVResult, combine, cross_validate
from ..config import NetworkConfig
from ..datasets import SampleSet
from ..encoders import Encoder
from ..features.spll import spll_features
from ..network import Network
from ..pipeline import encode_samples, jitter

REFERENCE = ("time-scaled", "none")
DEFAULT_LAYOUTS = ("time-scaled", "vary-offset", "grouped:2", "grouped:4", "grouped:8")


@dataclass
class AccuracyCell:
    """One layout under one constraint profile."""

    layout: str
    profile: str
    cv: CVResult
    report: str = ""  # the profile's per-parameter quantization report (Markdown)


@dataclass
class AccuracyTable:
    """All cells, plus what was run."""

    cells: list[AccuracyCell] = field(default_factory=list)
    encoder: str = ""
    n_samples: int = 0
    class_names: tuple[str, ...] = ()

    def cell(self, layout: str, profile: str) -> AccuracyCell:
        for c in self.cells:
            if (c.layout, c.profile) == (layout, profile):
                return c
        raise KeyError((layout, profile))

    def loss(self, layout: str, profile: str) -> float:
        """Accuracy loss [fraction] against the unconstrained time-scaled network."""
        return self.cell(*REFERENCE).cv.accuracy - self.cell(layout, profile).cv.accuracy

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
                text = f"{100 * c.cv.accuracy:.1f} ± {100 * c.cv.accuracy_sd:.1f} %"
                if has_reference and (layout, profile) != REFERENCE:
                    text += f" ({-100 * self.loss(layout, profile):+.1f})"
                row.append(text)
            lines.append(f"| {layout} | " + " | ".join(row) + " |")
        return "\n".join(lines)


def constrain(network: Network, profile: str) -> tuple[Network, str]:
    """``network`` under chip profile ``profile`` (a quantize/ profile name or TOML path) and
    the quantization report; ``"none"`` returns it unchanged."""
    if profile == "none":
        return network, ""
    import quantize

    q = quantize.quantize(network, quantize.load_profile(profile))
    return q.network, q.report_markdown()


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
    on_cell: Callable[[AccuracyCell], None] | None = None,
) -> AccuracyTable:
    """Accuracy of every layout × profile (module docstring). ``repeats`` phase-noise draws of
    ``phase_noise`` seconds each train their own classifiers, pooled as in the thesis."""
    samples = samples.normalized()
    trains = encode_samples(encoder, samples, jobs)
    noisy = [jitter(trains, phase_noise, samples.duration, seed + r) for r in range(repeats)]
    table = AccuracyTable(encoder=encoder.name, n_samples=len(samples),
                          class_names=tuple(samples.class_names))  # fmt: skip
    for layout in layouts:
        base = config.with_layout(layout).build()
        for profile in profiles:
            network, report = constrain(base, profile)
            cvs = []
            for x in noisy:
                features = spll_features(x, samples.duration, network, threads=jobs)
                cvs.append(cross_validate(features, samples.labels, samples.class_names,
                                          n_splits, seed=seed))  # fmt: skip
            table.cells.append(AccuracyCell(layout, profile, combine(cvs), report))
            if on_cell is not None:
                on_cell(table.cells[-1])
    return table


def accuracy_summary(table: AccuracyTable) -> dict:
    """JSON-ready accuracies: ``{layout: {profile: {"mean", "sd", "loss"}}}``."""
    has_reference = any((c.layout, c.profile) == REFERENCE for c in table.cells)
    out: dict = {}
    for c in table.cells:
        loss = table.loss(c.layout, c.profile) if has_reference else float("nan")
        out.setdefault(c.layout, {})[c.profile] = {
            "mean": c.cv.accuracy, "sd": c.cv.accuracy_sd, "loss": float(np.round(loss, 6)),
        }  # fmt: skip
    return out
