"""What each layout costs on each chip, beside its accuracy: fit, cores, energy, latency and
NeuroBench's metrics.

For every layout × column of an accuracy table, :func:`layout_costs` simulates a few of the
dataset's own samples on the column's backend and counts NeuroBench's metrics
(:mod:`spll_hw.harness.neurobench`). Where the column's profile has chip tables
(``[resources]``, :mod:`spll_hw.chips`) it also maps the layout's network onto the chip (fits or
why not, cores, chips) and costs the samples: **dynamic energy** (event counts × per-event
costs) is the headline, static and core power × time on chip is shown apart, and each says how
much of it rests on assumed figures. :func:`plot_accuracy_energy` draws accuracy against dynamic
energy per sample with the Pareto front on ranges marked (:func:`pareto`: no other cell is at
least as accurate and cheaper at both ends of the figures' ranges); static power never enters
it. What each cell's energy is spent on: :mod:`spll_hw.harness.breakdown`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import backends, chips
from ..config import NetworkConfig
from ..files import save_figure
from ..neuron_graph import GraphSize, graph_cost, graph_resources
from ..pareto import range_front
from ..report.figure_layout import legend_outside, place_labels, readable_log_axis
from ..report.plots import _pyplot, accuracy_bars
from . import neurobench
from .accuracy import Column, ScoredCell
from .breakdown import Breakdown, breakdown


@dataclass(frozen=True)
class SampleEnergy:
    """Mean energy per sample over the costed samples [J].

    Attributes:
        dynamic: event counts × per-event costs (:attr:`spll_hw.chips.ChipCost.dynamic_energy`).
        dynamic_assumed: the part of ``dynamic`` that rests on assumed figures.
        static: static and core power × the window (``None``: not modelled).
        static_assumed: the part of ``static`` that rests on assumed figures.
        dynamic_range: ``dynamic`` with every figure at its low and its high end.
        static_range: ``static`` likewise (``None``: not modelled).
        counts: mean times each per-event figure is paid per sample (``[energy]`` key →
            count, :attr:`spll_hw.chips.ChipCost.figure_counts`).
        ranges: ``(low, high)`` of each of those figures [J].
        values: each of those figures at its single value [J] (empty: the provider gives
            none).
    """

    dynamic: float
    dynamic_assumed: float
    static: float | None
    static_assumed: float | None
    dynamic_range: chips.EnergyRange | None = None
    static_range: chips.EnergyRange | None = None
    counts: dict[str, float] = field(default_factory=dict)
    ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    values: dict[str, float] = field(default_factory=dict)

    @classmethod
    def mean(cls, costs: Sequence[chips.ChipCost]) -> SampleEnergy:
        """The mean over the costs of several samples."""
        static = [c.static_energy for c in costs]
        known = None not in static
        keys = {k for c in costs for k in c.figure_counts}
        return cls(
            float(np.mean([c.dynamic_energy for c in costs])),
            float(np.mean([c.assumed_dynamic_energy for c in costs])),
            float(np.mean(static)) if known else None,
            float(np.mean([c.assumed_static_energy for c in costs])) if known else None,
            chips.EnergyRange.mean([c.dynamic_range for c in costs]),
            chips.EnergyRange.mean([c.static_range for c in costs]) if known else None,
            {k: float(np.mean([c.figure_counts.get(k, 0) for c in costs])) for k in keys},
            dict(costs[0].figure_ranges), dict(costs[0].figure_values),
        )  # fmt: skip

    def cheaper_than(self, other: SampleEnergy, same_figures: bool = True) -> bool | None:
        """Whether this costs less dynamic energy than ``other`` wherever the figures lie in
        their ranges: ``True`` when it does, ``False`` when ``other`` is cheaper throughout,
        ``None`` when the ranking flips inside the ranges (or they cost the same). On one
        chip's figures (``same_figures``) each figure is one unknown both pay
        (:func:`spll_hw.chips.cheaper`); on two chips' the figures are independent, and one
        is cheaper throughout only where its range lies wholly below the other's."""
        if same_figures:
            return chips.cheaper(self.counts, other.counts, self.ranges | other.ranges)
        mine, theirs = self.dynamic_range, other.dynamic_range
        return True if mine.high < theirs.low else False if theirs.high < mine.low else None

    def breakdown(self) -> Breakdown:
        """What the energy is spent on (:func:`spll_hw.harness.breakdown.breakdown`)."""
        return breakdown(self)

    def to_dict(self) -> dict:
        out = asdict(self)
        for key in ("dynamic_range", "static_range"):
            r = getattr(self, key)
            out[key] = None if r is None else [r.low, r.high]
        out["ranges"] = {k: list(v) for k, v in self.ranges.items()}
        return out


@dataclass(frozen=True)
class CostCell:
    """One layout on one column: ``fit`` (:class:`spll_hw.chips.ChipFit`; ``None`` when the
    column's profile has no chip tables), ``energy`` (:class:`SampleEnergy`; ``None`` without
    an ``[energy]`` table or a fit), step latency [s] and real-time factor (``None`` when not
    modelled), the assumed figures it rests on, and NeuroBench's metrics of the costed samples
    (``None`` when the column's chip cannot realise the layout, and on a construction: its
    counts are the two-compartment sPLL's). ``graph``: on a column whose backend runs a
    construction of standard neurons, its neurons, synapses and step (what ``fit`` placed
    and ``energy`` costs); ``None`` where the two-compartment sPLL runs."""

    layout: str
    column: str
    fit: chips.ChipFit | None
    energy: SampleEnergy | None
    step_latency: float | None
    real_time_factor: float | None
    assumed: tuple[str, ...]
    neurobench: neurobench.NeuroBenchMetrics | None = None
    graph: GraphSize | None = None

    @property
    def breakdown(self) -> Breakdown | None:
        """What a sample's energy is spent on here (``None``: not costed)."""
        return None if self.energy is None else self.energy.breakdown()

    @classmethod
    def of(
        cls, layout: str, column: str, fit: chips.ChipFit | None, costs: Sequence[chips.ChipCost],
        metrics: neurobench.NeuroBenchMetrics | None, why: str | None = None,
    ) -> CostCell:  # fmt: skip
        """The cell of ``layout`` on ``column``: the chip ``costs`` of its costed samples (none
        without chip tables, ``fit`` then ``None``) and their NeuroBench ``metrics``; or, with
        ``why``, a layout the column's chip cannot realise at all: it does not fit, whatever
        its cores would hold, and costs nothing."""
        if why is not None:
            if fit is None:
                return cls(layout, column, None, None, None, None, ())
            problems = fit.problems if why in fit.problems else (why, *fit.problems)
            fit = replace(fit, fits=False, problems=problems)
            return cls(layout, column, fit, None, None, None, fit.assumed)
        if fit is None:
            return cls(layout, column, None, None, None, None, (), metrics)
        has_energy = any(v is not None for v in costs[0].energy.values())
        return cls(
            layout, column, fit, SampleEnergy.mean(costs) if has_energy else None,
            costs[0].step_latency, costs[0].real_time_factor,
            tuple(sorted(set(fit.assumed) | {a for c in costs for a in c.assumed})), metrics,
        )  # fmt: skip

    def to_dict(self) -> dict:
        fit = self.fit
        return {
            "fits": None if fit is None else fit.fits,
            "why": [] if fit is None else list(fit.problems),
            "cores": None if fit is None else fit.cores,
            "chips": None if fit is None else fit.chips,
            "energy_J": None if self.energy is None else self.energy.to_dict(),
            "breakdown": None if self.energy is None else self.breakdown.to_dict(),
            "step_latency_s": self.step_latency, "real_time_factor": self.real_time_factor,
            "assumed": list(self.assumed),
            "neurobench": None if self.neurobench is None else self.neurobench.to_dict(),
            "construction": None if self.graph is None else self.graph.to_dict(),
        }  # fmt: skip


def layout_costs(
    config: NetworkConfig,
    layouts: Sequence[str],
    columns: Sequence[Column],
    trains: Sequence[np.ndarray],
    duration: float,
) -> list[CostCell]:
    """Cost every layout on every column (module docstring); ``trains`` are the samples costed
    (spike times [s], each sorted), ``duration`` their length [s]. The chip part (fit, energy,
    latency) only where the column's profile has a ``[resources]`` table. A column whose
    backend runs a construction of standard neurons (:attr:`Column.construction`) is costed
    the way that target realises it (:func:`construction_cost`)."""
    networks = {layout: config.with_layout(layout).build() for layout in layouts}
    with_tables = {c.profile for c in columns if c.profile != "none" and chips.figures(c.profile)}
    out = []
    for layout, network in networks.items():
        for col in columns:
            if col.construction:
                out.append(construction_cost(layout, network, col, col.profile in with_tables,
                                             trains, duration))  # fmt: skip
                continue
            info = None if col.profile == "none" else chips.describe(col.profile)
            fit = (
                chips.resources(chips.OnChip(network, col.profile))
                if col.profile in with_tables
                else None
            )
            why, costs, metrics = None, [], None
            try:
                if info is not None:
                    chips.realise(network, col.profile)
            except ValueError as exc:  # e.g. more circuits than an analog chip's groups
                why = str(exc)
            else:
                results = backends.get(col.spec).simulate_batch(network, list(trains), duration)
                if fit is not None:
                    costs = [chips.cost(chips.OnChip(network, col.profile), r) for r in results]
                on_chip = [c.time_on_chip for c in costs]
                metrics = neurobench.from_results(
                    network, results, duration, info,
                    None if not costs or None in on_chip else float(np.mean(on_chip)),
                )  # fmt: skip
            out.append(CostCell.of(layout, col.label, fit, costs, metrics, why))
    return out


def construction_cost(
    layout: str, network, col: Column, tables: bool, trains: Sequence[np.ndarray],
    duration: float,
) -> CostCell:  # fmt: skip
    """The cell of ``layout`` on construction column ``col``: the construction of standard
    neurons its backend runs (:meth:`~spll_hw.backends.base.Backend.neuron_graph`, at the
    column's step), placed on the column's chip where it has chip ``tables``
    (:func:`spll_hw.neuron_graph.graph_resources`) and its ``trains`` costed from each run's
    spike count of every neuron (:func:`~spll_hw.neuron_graph.graph_cost`: the same rule,
    figures and ranges as the two-compartment sPLL's :func:`spll_hw.chips.cost`). A
    construction the target cannot write (``ValueError``) does not fit, and costs nothing."""
    backend = backends.get(col.spec)
    try:
        graph = backend.neuron_graph(network)
    except ValueError as exc:  # e.g. a refractory period its step cannot hold
        why = f"does not fit: {exc}"
        if not tables:
            return CostCell.of(layout, col.label, None, [], None, why)
        fit = chips.ChipFit(chips.describe(col.profile), False, (why,), 0, 0, why, {}, ())
        return CostCell.of(layout, col.label, fit, [], None, why)
    size = GraphSize.of(graph)
    if not tables:
        return replace(CostCell.of(layout, col.label, None, [], None), graph=size)
    fit = graph_resources(graph, col.profile)
    results = backend.simulate_batch(network, list(trains), duration)
    costs = [graph_cost(graph, col.profile, r) for r in results]
    return replace(CostCell.of(layout, col.label, fit, costs, None), graph=size)


def fits(network, profile: str) -> bool:
    """Whether ``network`` fits chip ``profile``: the profile realises it (circuit budgets of
    analog chips, representable parameters) and, where it has chip tables, its cores and
    configurations hold it."""
    try:
        chips.realise(network, profile)
    except ValueError:
        return False
    return not chips.figures(profile) or chips.resources(chips.OnChip(network, profile)).fits


def auto_groups(config: NetworkConfig, profile: str) -> int:
    """The largest number of time-scale groups G (at most the network's ``n``) for which
    ``config``'s network in layout ``grouped:G`` fits chip ``profile``; ``ValueError`` when not
    even one group does. G starts at the chip's circuit budget where it has one: each G above
    it costs a grouped layout to build (quadratic in ``n``) only to be refused."""
    budget = chips.describe(profile).max_circuits
    for groups in range(min(config.n, budget or config.n), 0, -1):
        if fits(config.with_layout(f"grouped:{groups}").build(), profile):
            return groups
    raise ValueError(
        f"no grouped layout of this network fits profile {profile!r}, not even one group"
    )


def markdown(cells: Sequence[CostCell]) -> str:
    """One row per layout × chip column with chip tables: fit, cores, chips, dynamic energy
    per sample as the range its figures allow ``[low, high]`` with the single-figure value and
    the share of it on assumed figures, static energy per sample (apart, its range), step
    latency [µs], real-time factor; ``*`` marks values resting on assumed figures."""
    lines = [
        "| layout | chip column | fits | cores | chips | dynamic energy / sample [low, high] "
        "| at the figures' values | of it on assumed figures | static energy / sample "
        "[low, high], apart | step latency [µs] | real-time factor |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for c in cells:
        if c.fit is None:
            continue
        star = " *" if c.assumed else ""
        fits = "yes" if c.fit.fits else "no: " + "; ".join(c.fit.problems)
        e = c.energy
        span = dynamic = share = static = "-"
        if e is not None:
            span = str(e.dynamic_range)
            dynamic = chips.format_joules(e.dynamic) + (" *" if e.dynamic_assumed else "")
            share = _share(e.dynamic_assumed, e.dynamic)
            if e.static_range is not None:
                static = str(e.static_range) + (" *" if e.static_assumed else "")
        lines.append(
            f"| {c.layout} | {c.column} | {fits} | {c.fit.cores_words()} | {c.fit.chips} | "
            f"{span} | {dynamic} | {share} | {static} | {_number(c.step_latency, 1e6)}{star} | "
            f"{_number(c.real_time_factor, 1)}{star} |"
        )
    return "\n".join(lines)


def chip_of_column(column: str) -> str:
    """The chip a column stands for, whatever its step: ``"loihi2@40us (chip)"`` ->
    ``"loihi2 (chip)"``."""
    name, _, rest = column.partition(" ")
    return name.partition("@")[0] + (f" {rest}" if rest else "")


#: How a headline chose among the cells that tie the exact network: one rule for every column
#: and every chip (:func:`choose`, :func:`cheapest_ties`), each kind in these words (``{n}``:
#: the cells it chose among).
CHOICE_WORDS = {
    "only": "the only tie",
    "held": "the only one of {n} ties the chip holds",
    "cheapest": "the cheapest of {n} ties at every figure",
    "cores": "{n} ties the figures' ranges cannot rank: fewest cores, then energy at the "
    "figures' values",
    "mean": "{n} ties, no cost model: highest mean",
    "least loss": "no tie: least loss",
}
#: The rule itself, as the summary states it.
CHOICE_RULE = (
    "among the cells that tie the exact network (the change's 95 % CI holds zero, or a gain), "
    "the one cheaper than the others at every figure in its range; where the ranges cannot "
    "tell some apart, the one of them with the fewest cores, then the least dynamic energy at "
    "the figures' values; without a cost model, the highest mean; where none ties, the least "
    "loss"
)


@dataclass(frozen=True)
class Cheapest:
    """The cell one headline names for one chip or column (:func:`cheapest_ties`,
    :func:`choose`).

    Attributes:
        chip: the chip (:func:`chip_of_column`) or the column.
        cell: the chosen :class:`CostCell` (``None``: no cell ties, or not costed).
        change: its paired accuracy change against the exact network (fractions, 95 % CI).
        certain: it costs less dynamic energy than every other tying cell wherever the figures
            lie in their ranges; ``False``: some are not distinguishable from it on energy,
            and it was chosen among them by fewer cores, then its energy at the figures'
            values.
        rivals: the columns × layouts not distinguishable from it on energy.
        kind: which part of the rule chose it (a key of :data:`CHOICE_WORDS`).
        among: how many cells it was chosen among.
        layout: the chosen layout (also where ``cell`` is ``None``: not costed).
    """

    chip: str
    cell: CostCell | None
    change: object = None
    certain: bool = False
    rivals: tuple[str, ...] = ()
    kind: str = ""
    among: int = 0
    layout: str = ""

    def words(self) -> str:
        """Which part of the one rule chose it, in words (:data:`CHOICE_WORDS`)."""
        return CHOICE_WORDS[self.kind].format(n=self.among)


def _cheapest(tying: Sequence[CostCell]) -> tuple[CostCell, list[CostCell]]:
    """The cell of ``tying`` (fitting, costed) that no other beats at every figure, among
    those the fewest cores, then the least energy at the figures' values; and the cells the
    figures' ranges cannot tell from it."""
    unbeaten = [c for c in tying if not any(cheaper(o, c) for o in tying if o is not c)]
    best = min(unbeaten, key=lambda c: (c.fit.cores, c.energy.dynamic))  # fmt: skip
    return best, [c for c in tying if c is not best and cheaper(best, c) is not True]


def _priced(cell: CostCell | None) -> bool:
    return cell is not None and cell.fit is not None and cell.energy is not None and cell.fit.fits


def _kind(among: int, rivals: int) -> str:
    return "only" if among == 1 else "cores" if rivals else "cheapest"


def cheapest_ties(scored: Sequence[ScoredCell], cells: Sequence[CostCell]) -> list[Cheapest]:
    """Per chip (every step of it together), the layout × column whose accuracy ties the exact
    network (its paired change's CI holds 0, or it gains) at the least dynamic energy, by the
    rule of :data:`CHOICE_RULE`: the cell cheaper than every other tying cell wherever the
    figures lie; where the ranges cannot tell some apart, the one of them with the fewest
    cores, then the least energy at the figures' values."""
    change = {(c.layout, c.column): c.change for c in scored}
    by_chip: dict[str, list[CostCell]] = {}
    for c in cells:
        if _priced(c):
            by_chip.setdefault(chip_of_column(c.column), []).append(c)
    out = []
    for chip, group in by_chip.items():
        tying = [c for c in group if (ci := change.get((c.layout, c.column))) is not None
                 and ci.high >= 0]  # fmt: skip
        if not tying:
            out.append(Cheapest(chip, None, kind="least loss"))
            continue
        best, rivals = _cheapest(tying)
        out.append(Cheapest(
            chip, best, change[best.layout, best.column], not rivals,
            tuple(f"{c.layout} on {c.column}" for c in rivals), _kind(len(tying), len(rivals)),
            len(tying), best.layout,
        ))  # fmt: skip
    return out


def choose(column: Sequence[ScoredCell], cells: Sequence[CostCell]) -> Cheapest:
    """The layout one column's headline names, by the rule of :data:`CHOICE_RULE` (the same
    rule as :func:`cheapest_ties`): ``column`` its scored cells with a change against the
    exact network (at least one), ``cells`` the report's cost cells (those of this column's
    layouts price the choice; a tying layout the chip does not hold is not chosen where one
    it holds ties)."""
    label = column[0].column
    cost = {c.layout: c for c in cells if c.column == label}
    tying = [c for c in column if c.change.high >= 0]
    if not tying:
        best = max(column, key=lambda c: c.change.mean)
        return Cheapest(label, cost.get(best.layout), best.change, kind="least loss",
                        among=len(column), layout=best.layout)  # fmt: skip
    priced = [cost[c.layout] for c in tying if _priced(cost.get(c.layout))]
    if len(tying) > 1 and priced:
        best, rivals = _cheapest(priced)
        change = next(c.change for c in tying if c.layout == best.layout)
        kind = "held" if len(priced) == 1 else _kind(len(priced), len(rivals))
        return Cheapest(
            label, best, change, not rivals, tuple(c.layout for c in rivals), kind,
            len(tying) if kind == "held" else len(priced), best.layout,
        )  # fmt: skip
    best = max(tying, key=lambda c: c.change.mean)
    return Cheapest(label, cost.get(best.layout), best.change, True, (),
                    "only" if len(tying) == 1 else "mean", len(tying), best.layout)  # fmt: skip


def _share(part: float, whole: float) -> str:
    return "-" if whole == 0 else f"{100 * part / whole:.0f} %"


def _number(value: float | None, scale: float) -> str:
    return "-" if value is None else f"{scale * value:.4g}"


def chip_name(column: str) -> str:
    """The chip a column's figures are of, whatever its step or backend: ``"loihi2@40us
    (chip)"`` -> ``"loihi2"``."""
    return column.partition(" ")[0].partition("@")[0]


def cheaper(a: CostCell, b: CostCell) -> bool | None:
    """Whether cell ``a`` costs less dynamic energy per sample than ``b`` wherever the figures
    lie in their ranges (:meth:`SampleEnergy.cheaper_than`): on one chip (the same figures,
    whatever the step) by the exact box rule, across chips only where the ranges do not
    overlap."""
    same = chip_name(a.column) == chip_name(b.column) and a.energy.ranges == b.energy.ranges
    return a.energy.cheaper_than(b.energy, same_figures=same)


def pareto(cells: Sequence[CostCell], accuracy: Sequence[float]) -> list[bool]:
    """Whether each costed cell (its ``accuracy``, a fraction) is on the accuracy-energy front
    on ranges: a cell is dominated only where another is at least as accurate and cheaper at
    both ends of the figures' ranges (:func:`cheaper`), so two cells whose ranking flips
    inside the ranges both stay (:func:`spll_hw.pareto.range_front`)."""
    best = set(range_front(accuracy, lambda j, i: cheaper(cells[j], cells[i])))
    return [i in best for i in range(len(cells))]


#: The front's rule, as the accuracy-energy picture's legend says it.
FRONT_RULE = (
    "Pareto front: no other cell is at least\nas accurate and cheaper at both ends\n"
    "of the figures' ranges"
)


def plot_accuracy_energy(
    scored: Sequence[ScoredCell], cells: Sequence[CostCell], path: Path
) -> bool:
    """Accuracy [%] (95 % CI, from the ``scored`` cells of the accuracy table) against dynamic
    energy per sample [µJ] (no static power) of every fitting layout × chip column with an
    energy model, each with the ``[low, high]`` of its energy; the cells on the front on
    ranges (:func:`pareto`) in red, unjoined: with ranges the front need not fall with energy.
    ``False`` (nothing drawn) when no cell has both."""
    accuracy = {(c.layout, c.column): c.accuracy for c in scored}
    rows = [
        (c, accuracy[c.layout, c.column])
        for c in cells
        if c.fit is not None and c.fit.fits and c.energy is not None
        and accuracy[c.layout, c.column] is not None
    ]  # fmt: skip
    if not rows:
        return False
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    x = [1e6 * c.energy.dynamic for c, _ in rows]  # µJ
    front = pareto([c for c, _ in rows], [ci.mean for _, ci in rows])
    means, errors = accuracy_bars([ci for _, ci in rows])
    spans = [(1e6 * c.energy.dynamic_range.low, 1e6 * c.energy.dynamic_range.high)
             for c, _ in rows]  # fmt: skip
    for k, best in enumerate(front):
        xerr = [[x[k] - spans[k][0]], [spans[k][1] - x[k]]]
        ax.errorbar(x[k], means[k], yerr=errors[:, k : k + 1].tolist(), xerr=xerr, fmt="o",
                    color="C3" if best else "C0", capsize=2, zorder=3)  # fmt: skip
    ax.plot([], [], "o", color="C3", label=FRONT_RULE)
    ax.plot([], [], "o", color="C0", label="not on the front")
    ax.set_xscale("log")
    readable_log_axis(ax.xaxis)
    ax.margins(x=0.25, y=0.08)
    ax.set_xlabel("dynamic energy per sample [µJ] (bars: the figures' [low, high] range;\n"
                  "static power apart, see the cost table)")  # fmt: skip
    ax.set_ylabel("accuracy [%] (bars: 95 % CI)")
    ax.set_title("Accuracy against dynamic energy per sample (each point: layout, chip column)")
    legend_outside(ax)
    bars = [((xk, m - lo), (xk, m + hi))
            for xk, m, lo, hi in zip(x, means, *errors, strict=True)]  # fmt: skip
    bars += [((lo, m), (hi, m)) for (lo, hi), m in zip(spans, means, strict=True)]
    place_labels(ax, [(xk, 100 * ci.mean) for xk, (_, ci) in zip(x, rows, strict=True)],
                 [f"{c.layout}, {c.column}" for c, _ in rows], lines=bars)  # fmt: skip
    save_figure(fig, path, dpi=110, bbox_inches="tight")  # the legend sits outside the axes
    plt.close(fig)
    return True
