"""What an approximate construction of the sPLL costs in accuracy, beside the exact one.

A construction is a backend that approximates the exact sPLL on purpose, such as the
standard-neuron sPLL's K-level gate (``standard-exact:levels=K``, which chips and NIR can run).
For every construction spec the accuracy table of :func:`~.accuracy.layout_accuracy` is built
again with that backend in every column (same samples, folds, phase-noise and mismatch draws),
and each cell is paired with the exact table's cell of the same layout and profile: the change
is the accuracy the construction costs there, with its paired 95 % CI (fold by fold, or sample
by sample on held-out recordings).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..stats import Interval
from .accuracy import AccuracyTable


@dataclass(frozen=True)
class ConstructionCell:
    """One layout × profile under one construction, as plain numbers: its accuracy, the exact
    cell's, and its paired change against the exact cell.

    Attributes:
        construction: the construction's spec as typed.
        layout, profile: the cell.
        backend: the spec that computed the construction's features.
        accuracy: its accuracy [fraction] with its 95 % CI (``None``: does not fit).
        mean: its mean accuracy [fraction] (``None``: does not fit).
        exact: the exact cell's accuracy with its 95 % CI (``None``: does not fit).
        exact_mean: the exact cell's mean accuracy (``None``: does not fit).
        change: the paired change against the exact cell [fraction] with its 95 % CI
            (``None`` where either does not fit).
        why: why one of them does not fit (``""`` where both do).
    """

    construction: str
    layout: str
    profile: str
    backend: str
    accuracy: Interval | None
    mean: float | None
    exact: Interval | None
    exact_mean: float | None
    change: Interval | None
    why: str = ""

    def to_dict(self) -> dict:
        out = {"construction": self.construction, "layout": self.layout,
               "profile": self.profile, "backend": self.backend}  # fmt: skip
        if self.change is None:
            return out | {"fits": False, "why": self.why}
        return out | {
            "fits": True, "mean": self.mean, "ci": self.accuracy.to_dict(),
            "exact_mean": self.exact_mean, "change": self.change.to_dict(),
        }  # fmt: skip


def construction_cost(
    exact: AccuracyTable,
    constructions: Sequence[str],
    score: Callable[[str], AccuracyTable],
    on_cell: Callable[[ConstructionCell], None] | None = None,
) -> list[ConstructionCell]:
    """Every construction's cells paired with the ``exact`` table's (module docstring).

    ``score(spec)`` builds the table of backend ``spec`` exactly as ``exact`` was built (the
    same :func:`~.accuracy.layout_accuracy` arguments; ``chip=False``, since a construction
    computes every column itself); cells of ``exact`` without a partner (its ``(chip)``
    columns) are left out.
    """
    out = []
    for spec in constructions:
        for cell in score(spec).cells:
            partner = exact.cell(cell.layout, cell.profile)
            fits = cell.cv is not None and partner.cv is not None
            row = ConstructionCell(
                spec, cell.layout, cell.profile, cell.backend,
                cell.cv.accuracy_ci() if cell.cv else None, cell.cv.accuracy if cell.cv else None,
                partner.cv.accuracy_ci() if partner.cv else None,
                partner.cv.accuracy if partner.cv else None,
                cell.cv.change_against(partner.cv) if fits else None,
                "" if fits else cell.report or partner.report,
            )  # fmt: skip
            out.append(row)
            if on_cell is not None:
                on_cell(row)
    return out


def plot_cost(cells: Sequence[ConstructionCell], path: Path) -> None:
    """The paired change against exact [points] per construction (x) with its 95 % CI, one
    line per layout × profile; zero (no cost) as a dotted line."""
    from ..report.plots import _pyplot

    plt = _pyplot()
    specs = list(dict.fromkeys(c.construction for c in cells))
    rows = list(dict.fromkeys((c.layout, c.profile) for c in cells))
    fig, ax = plt.subplots(figsize=(max(7.0, 1.4 * len(specs) + 4), 4.5))
    spread = 0.5 / len(rows)
    for r, (layout, profile) in enumerate(rows):
        points = [
            (k + (r - (len(rows) - 1) / 2) * spread, c.change)
            for c in cells
            if (c.layout, c.profile) == (layout, profile) and c.change is not None
            for k in [specs.index(c.construction)]
        ]
        if not points:
            continue
        xs = [x for x, _ in points]
        means = np.array([100 * ci.mean for _, ci in points])
        lows = np.array([100 * ci.low for _, ci in points])
        highs = np.array([100 * ci.high for _, ci in points])
        ax.errorbar(xs, means, yerr=[means - lows, highs - means], marker="o", capsize=2,
                    linewidth=1, label=f"{layout}, {profile}")  # fmt: skip
    ax.axhline(0.0, linestyle=":", color="0.4")
    ax.set_xticks(range(len(specs)), specs, rotation=15, fontsize=7)
    ax.set_ylabel("accuracy change vs exact [points] (95 % CI)")
    ax.set_title("What the construction costs, per layout and chip profile")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
