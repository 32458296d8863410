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
from .accuracy import AccuracyCell, AccuracyTable, accuracy_text, change_text


@dataclass(frozen=True)
class ConstructionCell:
    """One layout × profile under one construction: its cell and its paired change against
    the exact cell (``None`` where either does not fit)."""

    construction: str
    cell: AccuracyCell
    exact: AccuracyCell
    change: Interval | None

    def to_dict(self) -> dict:
        out = {"construction": self.construction, "layout": self.cell.layout,
               "profile": self.cell.profile, "backend": self.cell.backend}  # fmt: skip
        if self.cell.cv is None or self.change is None:
            return out | {"fits": False, "why": self.cell.report or self.exact.report}
        return out | {
            "fits": True, "mean": self.cell.cv.accuracy,
            "ci": self.cell.cv.accuracy_ci().to_dict(), "exact_mean": self.exact.cv.accuracy,
            "change": self.change.to_dict(),
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
            change = cell.cv.change_against(partner.cv) if cell.cv and partner.cv else None
            row = ConstructionCell(spec, cell, partner, change)
            out.append(row)
            if on_cell is not None:
                on_cell(row)
    return out


def markdown(cells: Sequence[ConstructionCell]) -> str:
    """Rows layout × profile, a column of exact accuracy and one per construction with its
    accuracy and, in brackets, its paired change against exact in points (bold:
    distinguishable from zero)."""
    specs = list(dict.fromkeys(c.construction for c in cells))
    rows = list(dict.fromkeys((c.cell.layout, c.cell.profile) for c in cells))
    by_key = {(c.construction, c.cell.layout, c.cell.profile): c for c in cells}
    lines = [
        "| layout | profile | exact | " + " | ".join(f"`{s}`" for s in specs) + " |",
        "|---|---|---|" + "---|" * len(specs),
    ]
    for layout, profile in rows:
        first = by_key[(specs[0], layout, profile)]
        exact = first.exact.cv
        row = [layout, profile, accuracy_text(exact) if exact else "does not fit"]
        for spec in specs:
            c = by_key.get((spec, layout, profile))
            if c is None or c.change is None:
                row.append("does not fit")
                continue
            row.append(f"{accuracy_text(c.cell.cv)} ({change_text(c.change)})")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def plot_cost(cells: Sequence[ConstructionCell], path: Path) -> None:
    """The paired change against exact [points] per construction (x) with its 95 % CI, one
    line per layout × profile; zero (no cost) as a dotted line."""
    from ..report.plots import _pyplot

    plt = _pyplot()
    specs = list(dict.fromkeys(c.construction for c in cells))
    rows = list(dict.fromkeys((c.cell.layout, c.cell.profile) for c in cells))
    fig, ax = plt.subplots(figsize=(max(7.0, 1.4 * len(specs) + 4), 4.5))
    spread = 0.5 / len(rows)
    for r, (layout, profile) in enumerate(rows):
        points = [
            (k + (r - (len(rows) - 1) / 2) * spread, c.change)
            for c in cells
            if (c.cell.layout, c.cell.profile) == (layout, profile) and c.change is not None
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
