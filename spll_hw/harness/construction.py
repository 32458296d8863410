"""What an approximate construction of the sPLL costs in accuracy, beside the exact one.

A construction is a backend that approximates the exact sPLL on purpose, such as the
standard-neuron sPLL's K-level gate (``standard-exact:levels=K``, which chips and NIR can run).
For every construction spec the accuracy table of :func:`~.accuracy.layout_accuracy` is built
again with that backend in every column (same samples, folds, phase-noise and mismatch draws),
and each cell is paired with the exact table's cell of the same layout and profile: the change
is the accuracy the construction costs there, with its paired 95 % CI (fold by fold, or sample
by sample on held-out recordings).

Beside it, what the construction costs on the chip (:func:`priced`): a construction backend that
has a graph of standard neurons (``nir-numpy``, ``standard-fixed-point``:
:meth:`~spll_hw.backends.base.Backend.neuron_graph`) is costed the way that target realises
it, its neurons, synapses and cores at its step and its dynamic energy per sample from each
run's spike count of every neuron (:func:`spll_hw.harness.costs.construction_cost`), and
set against the two-compartment sPLL of the same cell by the report's rule
(:func:`spll_hw.harness.costs.cheaper`: more or less at every figure in its range, or a
ranking that flips inside the ranges). ``standard-exact`` runs the K-level gate in the exact
engine, no graph of neurons: it is scored, not costed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import backends, chips
from ..neuron_graph import runs_construction
from ..report.plots import _pyplot
from ..stats import Interval
from .accuracy import AccuracyTable
from .costs import CostCell, cheaper


@dataclass(frozen=True)
class AgainstSpll:
    """A construction cell's dynamic energy per sample against the two-compartment sPLL's on
    the same chip column (the same figures, so one unknown per figure both pay).

    Attributes:
        column: the column of the sPLL's cost cell (the construction cell's profile).
        spll: the sPLL's dynamic energy per sample [J] at the figures' values.
        spll_range: the same with every figure at its low and its high end.
        ratio: construction / sPLL at the figures' values.
        ratio_low, ratio_high: the same with every figure at its low end, at its high end.
        cheaper: ``True``: the construction costs less at every figure in its range,
            ``False``: more, ``None``: the ranking flips inside the ranges
            (:func:`spll_hw.harness.costs.cheaper`).
    """

    column: str
    spll: float
    spll_range: chips.EnergyRange
    ratio: float
    ratio_low: float
    ratio_high: float
    cheaper: bool | None

    @classmethod
    def of(cls, construction: CostCell, spll: CostCell) -> AgainstSpll:
        mine, theirs = construction.energy, spll.energy
        a, b = mine.dynamic_range, theirs.dynamic_range
        return cls(
            spll.column, theirs.dynamic, b, mine.dynamic / theirs.dynamic, a.low / b.low,
            a.high / b.high, cheaper(construction, spll),
        )  # fmt: skip

    def words(self) -> str:
        """One line: how much more (or less) the construction costs."""
        verdict = {
            True: "less at every figure in its range",
            False: "more at every figure in its range",
            None: "the ranking flips inside the figures' ranges",
        }[self.cheaper]
        return (
            f"{self.ratio:.3g}x the two-compartment sPLL's {chips.format_joules(self.spll)} "
            f"({self.ratio_low:.3g}x with every figure at its low end, {self.ratio_high:.3g}x "
            f"at its high end): {verdict}"
        )

    def to_dict(self) -> dict:
        return {
            "column": self.column, "spll_dynamic_J": self.spll,
            "spll_dynamic_range_J": [self.spll_range.low, self.spll_range.high],
            "ratio": self.ratio, "ratio_low": self.ratio_low, "ratio_high": self.ratio_high,
            "cheaper": self.cheaper, "words": self.words(),
        }  # fmt: skip


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
        cost: what the construction costs here (:func:`priced`; ``None``: not costed): its
            graph (neurons, synapses, step: ``cost.graph``, ``None`` for a backend without
            one) and, where the profile has chip tables, its fit, cores and energy.
        against: its dynamic energy against the two-compartment sPLL's of the same cell
            (``None`` where either is not costed).
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
    cost: CostCell | None = None
    against: AgainstSpll | None = None

    def to_dict(self) -> dict:
        """The cell in ``results.json``: its accuracy and change, and what it costs: its
        ``neurons``, ``synapses`` and ``dt_s`` (a construction with a graph), its ``cores``,
        ``chips`` and ``energy_J`` per sample (a chip with tables; ``null`` otherwise) and
        ``against_spll``."""
        out = {"construction": self.construction, "layout": self.layout,
               "profile": self.profile, "backend": self.backend} | self._cost_dict()  # fmt: skip
        if self.change is None:
            return out | {"fits": False, "why": self.why}
        return out | {
            "fits": True, "mean": self.mean, "ci": self.accuracy.to_dict(),
            "exact_mean": self.exact_mean, "change": self.change.to_dict(),
        }  # fmt: skip

    def _cost_dict(self) -> dict:
        c = self.cost
        graph = None if c is None else c.graph
        fit = None if c is None else c.fit
        return {
            "target": None if graph is None else graph.target,
            "neurons": None if graph is None else graph.neurons,
            "synapses": None if graph is None else graph.synapses,
            "dt_s": None if graph is None else list(graph.dts),
            "fits_chip": None if fit is None else fit.fits,
            "cores": None if fit is None else fit.cores,
            "chips": None if fit is None else fit.chips,
            "energy_J": None if c is None or c.energy is None else c.energy.to_dict(),
            "against_spll": None if self.against is None else self.against.to_dict(),
        }


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


def priced(
    cells: Sequence[ConstructionCell],
    cost: Callable[[str], Sequence[CostCell]],
    spll: Sequence[CostCell],
) -> list[ConstructionCell]:
    """``cells`` with what each construction costs (module docstring; a backend with no graph
    of neurons is left uncosted): ``cost(spec)`` costs every layout on every column of
    construction ``spec``
    (:func:`~spll_hw.harness.costs.layout_costs` on its columns, the columns' labels its
    cells' profiles), ``spll`` are the report's cost cells of the two-compartment sPLL, whose
    cell of the same layout and column each construction cell is set against."""
    of_spll = {(c.layout, c.column): c for c in spll if c.graph is None}
    costed: dict[tuple[str, str, str], CostCell] = {}
    for spec in dict.fromkeys(c.construction for c in cells):
        if not runs_construction(backends.get(spec)):  # e.g. standard-exact: no neurons
            continue
        for c in cost(spec):
            costed[spec, c.layout, c.column] = c
    out = []
    for cell in cells:
        mine = costed.get((cell.construction, cell.layout, cell.profile))
        theirs = of_spll.get((cell.layout, cell.profile))
        against = None
        if mine is not None and theirs is not None and _costed(mine) and _costed(theirs):
            against = AgainstSpll.of(mine, theirs)
        out.append(replace(cell, cost=mine, against=against))
    return out


def _costed(cell: CostCell) -> bool:
    return cell.fit is not None and cell.fit.fits and cell.energy is not None


def plot_cost(cells: Sequence[ConstructionCell], path: Path) -> None:
    """Left: the paired change against exact [points] per construction (x) with its 95 % CI,
    one line per layout × profile; zero (no cost) as a dotted line. Right, where a
    construction was costed on a chip: its dynamic energy per sample [µJ] with the figures'
    [low, high], beside the two-compartment sPLL's of the same cell (x = 0), one line per
    layout × chip profile."""
    plt = _pyplot()
    specs = list(dict.fromkeys(c.construction for c in cells))
    rows = list(dict.fromkeys((c.layout, c.profile) for c in cells))
    costed = [c for c in cells if c.against is not None]
    width = max(7.0, 1.4 * len(specs) + 4)
    if costed:
        fig, (ax, energy_ax) = plt.subplots(1, 2, figsize=(2 * width - 2, 4.8))
    else:
        fig, ax = plt.subplots(figsize=(width, 4.5))
    spread = 0.5 / len(rows)

    def offset(k: int, layout: str, profile: str) -> float:
        return k + (rows.index((layout, profile)) - (len(rows) - 1) / 2) * spread

    for r, (layout, profile) in enumerate(rows):
        points = [
            (offset(specs.index(c.construction), layout, profile), c.change)
            for c in cells
            if (c.layout, c.profile) == (layout, profile) and c.change is not None
        ]
        if not points:
            continue
        xs = [x for x, _ in points]
        means = np.array([100 * ci.mean for _, ci in points])
        lows = np.array([100 * ci.low for _, ci in points])
        highs = np.array([100 * ci.high for _, ci in points])
        ax.errorbar(xs, means, yerr=[means - lows, highs - means], marker="o", capsize=2,
                    linewidth=1, color=f"C{r % 10}", label=f"{layout}, {profile}")  # fmt: skip
    ax.axhline(0.0, linestyle=":", color="0.4")
    ax.set_xticks(range(len(specs)), specs, rotation=15, fontsize=7)
    ax.set_ylabel("accuracy change vs exact [points] (95 % CI)")
    ax.set_title("What the construction costs in accuracy")
    if costed:
        _plot_energy(energy_ax, costed, rows, offset)
        handles, labels = ax.get_legend_handles_labels()
        fig.legend(handles, labels, fontsize=7, loc="upper right", title="layout, profile",
                   title_fontsize=7)  # fmt: skip
        fig.tight_layout(rect=(0, 0, 0.86, 1))
    else:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _plot_energy(ax, costed: Sequence[ConstructionCell], rows, offset) -> None:
    """The right panel of :func:`plot_cost`: x = 0 the two-compartment sPLL, then each
    costed construction; µJ per sample on a log axis, bars over the figures' ranges."""
    specs = list(dict.fromkeys(c.construction for c in costed))
    for layout, profile in dict.fromkeys((c.layout, c.profile) for c in costed):
        mine = [c for c in costed if (c.layout, c.profile) == (layout, profile)]
        spll = mine[0].against
        points = [(offset(0, layout, profile), spll.spll, spll.spll_range)] + [
            (offset(1 + specs.index(c.construction), layout, profile), c.cost.energy.dynamic,
             c.cost.energy.dynamic_range)
            for c in mine
        ]  # fmt: skip
        xs = [x for x, _, _ in points]
        values = np.array([1e6 * v for _, v, _ in points])
        lows = np.array([1e6 * r.low for _, _, r in points])
        highs = np.array([1e6 * r.high for _, _, r in points])
        ax.errorbar(xs, values, yerr=[values - lows, highs - values], marker="s", capsize=2,
                    linewidth=1, color=f"C{rows.index((layout, profile)) % 10}")  # fmt: skip
    ax.set_yscale("log")
    ax.set_xticks(range(len(specs) + 1), ["two-compartment sPLL", *specs], rotation=15,
                  fontsize=7)  # fmt: skip
    ax.set_ylabel("dynamic energy per sample [µJ]\n(bars: the figures' [low, high])")
    ax.set_title("What it costs on the chip, against the sPLL")
