"""What a sample's energy is spent on, per layout × chip column: the breakdown a designer acts on.

The dynamic energy of a sample is a sum of counts × per-event figures
(:attr:`spll_hw.chips.ChipCost.figure_counts`); :data:`PARTS` groups the figures by what a
designer can change:

* **neuron updates**: every compartment updated every time step (``neuron_update``) — a
  clocked chip pays them whatever the network does, so they fall in proportion to a coarser
  step or fewer compartments;
* **synaptic events**: input, trigger and feedback deliveries (``synaptic_event``) — they follow
  the input's and the network's spike rates;
* **spikes**: TDE and CCO spikes generated (``spike``);
* **messages and hops**: spike messages between cores and the router and chip hops they take
  (``message``, ``hop``, ``chip_hop``) — placement and multicast change them;
* **per-step energy**: the chip's own work per time step, whatever runs (``step``, measured on
  a Loihi 2 board) — only a coarser step cuts it.

Static and core power × the window is shown apart (:attr:`Breakdown.static`): no layout or
step changes it in real-time use. A figure no part names (another provider's) is its own
part, so the parts always sum to the dynamic total, at the figures' values and at each end of
their ranges. :func:`markdown` tabulates the breakdown of every costed cell and
:func:`plot_breakdown` draws it (``energy_breakdown.png``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..chips import EnergyRange, format_joules
from ..files import save_figure
from ..report.figure_layout import fit_layout, readable_log_axis
from ..report.plots import _pyplot

if TYPE_CHECKING:
    from .costs import CostCell, SampleEnergy

#: Parts of the dynamic energy, in report order: name and the per-event ``[energy]`` figures
#: it sums (module docstring).
PARTS = (
    ("neuron updates", ("neuron_update",)),
    ("synaptic events", ("synaptic_event",)),
    ("spikes", ("spike",)),
    ("messages and hops", ("message", "hop", "chip_hop")),
    ("per-step energy", ("step",)),
)
#: What a designer changes to cut each part (the summary's advice for its largest part).
LEVERS = {
    "neuron updates": "a coarser step or fewer compartments",
    "synaptic events": "lower input and spike rates or fewer synapses",
    "spikes": "lower spike rates or fewer neurons",
    "messages and hops": "placement (fewer cores crossed) or multicast",
    "per-step energy": "a coarser step",
}


@dataclass(frozen=True)
class Part:
    """One part of a sample's dynamic energy.

    Attributes:
        name: the part (:data:`PARTS`).
        counts: times each of its figures is paid per sample (``[energy]`` key → count).
        value: its energy at the figures' single values [J] (``None``: the provider gives no
            single values).
        low, high: its energy with its figures at their low and their high end [J].
    """

    name: str
    counts: dict[str, float]
    value: float | None
    low: float
    high: float

    def to_dict(self) -> dict:
        return {
            "counts": dict(self.counts),
            "value_J": self.value,
            "range_J": [self.low, self.high],
        }


@dataclass(frozen=True)
class Breakdown:
    """A sample's dynamic energy by part, and its static energy apart.

    Attributes:
        parts: the parts the profile prices, in :data:`PARTS` order (a figure no part names
            last, as its own part).
        static_value: static and core power × the window [J] at the figures' values
            (``None``: not modelled).
        static: its ``[low, high]`` (``None``: not modelled).
    """

    parts: tuple[Part, ...]
    static_value: float | None
    static: EnergyRange | None

    @property
    def dynamic(self) -> EnergyRange:
        """The parts' sum with every figure at its low and at its high end [J]."""
        return EnergyRange(sum(p.low for p in self.parts), sum(p.high for p in self.parts))

    @property
    def dynamic_value(self) -> float | None:
        """The parts' sum at the figures' values [J] (``None``: no single values)."""
        if any(p.value is None for p in self.parts):
            return None
        return sum(p.value for p in self.parts)

    def share(self, part: Part) -> float:
        """``part``'s fraction of the dynamic energy, at the figures' values (at the middle of
        the ranges where there are none); 0 for a sample of no dynamic energy."""
        mid = (part.low + part.high) / 2
        whole = self.dynamic_value
        if whole is None:
            whole, mine = (self.dynamic.low + self.dynamic.high) / 2, mid
        else:
            mine = part.value
        return 0.0 if whole == 0 else mine / whole

    @property
    def largest(self) -> Part | None:
        """The part with the largest share (``None``: no parts)."""
        return max(self.parts, key=self.share, default=None)

    def to_dict(self) -> dict:
        dynamic = self.dynamic
        return {
            "parts": {p.name: p.to_dict() | {"share": self.share(p)} for p in self.parts},
            "dynamic_J": {"value": self.dynamic_value, "range": [dynamic.low, dynamic.high]},
            "static_J": None if self.static is None else {
                "value": self.static_value, "range": [self.static.low, self.static.high]},
            "largest": None if self.largest is None else self.largest.name,
        }  # fmt: skip


def breakdown(energy: SampleEnergy) -> Breakdown:
    """The :class:`Breakdown` of a sample's mean energy: each part is its counts × its
    figures' values and ends (:attr:`SampleEnergy.counts`, ``values``, ``ranges``), the counts
    of the placement at the figures' values (a cost's own range also spans the placements at
    the ends of a profile's placement ranges: docs/profiles.md)."""
    named = {key for _, keys in PARTS for key in keys}
    groups = list(PARTS) + [(key, (key,)) for key in sorted(energy.counts) if key not in named]
    parts = []
    for name, keys in groups:
        mine = [k for k in keys if k in energy.counts]
        if not mine:
            continue
        counts = {k: energy.counts[k] for k in mine}
        value = (
            sum(n * energy.values[k] for k, n in counts.items())
            if all(k in energy.values for k in mine)
            else None
        )
        low = sum(n * energy.ranges[k][0] for k, n in counts.items())
        high = sum(n * energy.ranges[k][1] for k, n in counts.items())
        parts.append(Part(name, counts, value, low, high))
    return Breakdown(tuple(parts), energy.static, energy.static_range)


def _costed(cells: Sequence[CostCell]) -> list[CostCell]:
    return [c for c in cells if c.fit is not None and c.fit.fits and c.energy is not None]


def markdown(cells: Sequence[CostCell]) -> str:
    """One row per costed layout × chip column: each part's energy per sample at the
    figures' values and its share of the dynamic total, the total as ``[low, high]``, the
    largest part, and static energy apart; empty without costed cells."""
    costed = _costed(cells)
    if not costed:
        return ""
    names = [n for n, _ in PARTS]
    names += sorted({p.name for c in costed for p in c.breakdown.parts} - set(names))
    lines = [
        "| layout | chip column | " + " | ".join(names) + " | dynamic [low, high] | largest "
        "part | static [low, high], apart |",
        "|---|---|" + "---:|" * len(names) + "---:|---|---:|",
    ]
    for c in costed:
        b = c.breakdown
        by_name = {p.name: p for p in b.parts}
        row = [_part_text(b, by_name[n]) if n in by_name else "-" for n in names]
        largest = b.largest
        lines.append(
            f"| {c.layout} | {c.column} | " + " | ".join(row) + f" | {b.dynamic} | "
            f"{'-' if largest is None else largest.name} | "
            f"{'-' if b.static is None else b.static} |"
        )
    return "\n".join(lines)


def _part_text(b: Breakdown, part: Part) -> str:
    energy = format_joules(_at(part.value, EnergyRange(part.low, part.high)))
    return f"{energy} ({_percent(b.share(part))})"


def _percent(share: float) -> str:
    """``"23 %"``; a share above 0 that rounds to 0 is ``"<1 %"``, not nothing."""
    return "<1 %" if 0 < share < 0.005 else f"{100 * share:.0f} %"


def levers(cells: Sequence[CostCell]) -> str:
    """Per largest part, the cells it dominates and what cuts it (:data:`LEVERS`), one
    sentence each; empty without costed cells."""
    by_part: dict[str, list[str]] = {}
    for c in _costed(cells):
        largest = c.breakdown.largest
        if largest is not None:
            share = _percent(c.breakdown.share(largest))
            by_part.setdefault(largest.name, []).append(f"{c.layout} on {c.column} ({share})")
    return " ".join(
        f"The largest part is **{name}** in {len(where)} cell(s) ({', '.join(where[:3])}"
        f"{', ...' if len(where) > 3 else ''}): {LEVERS.get(name, 'its count or its figure')} "
        "cuts it."
        for name, where in by_part.items()
    )


#: A colour per part, the same in every picture.
_COLOURS = {name: f"C{k}" for k, (name, _) in enumerate(PARTS)}


def plot_breakdown(cells: Sequence[CostCell], path: Path) -> bool:
    """Stacked horizontal bars, one per costed layout × chip column: the dynamic parts
    stacked at the figures' values (the middle of their ranges where there are none), the
    ``[low, high]`` range of their total as an error bar, and, in a panel apart, the static
    energy hatched with its range. The energy axis is linear unless the totals span more than
    20×, then logarithmic, each bar then split by its parts' shares (:func:`_edges`).
    ``False`` (nothing drawn) without costed cells."""
    costed = _costed(cells)
    if not costed:
        return False
    plt = _pyplot()
    rows = [(f"{c.layout}, {c.column}", c.breakdown) for c in costed][::-1]  # first on top
    static = any(b.static is not None for _, b in rows)
    fig, axes = plt.subplots(
        1, 2 if static else 1, sharey=True, squeeze=False,
        figsize=(10.5 if static else 8, 1.6 + 0.3 * len(rows)),
        gridspec_kw={"width_ratios": [3, 1] if static else [1]},
    )  # fmt: skip
    ax = axes[0, 0]
    scale, unit = _unit(max(b.dynamic.high for _, b in rows))
    totals = [_at(b.dynamic_value, b.dynamic) / scale for _, b in rows]
    positive = [t for t in totals if t > 0]
    log = bool(positive) and max(positive) > 20 * min(positive)
    # On a log axis each bar runs from the axis' left edge to its total, and its parts split
    # that length in proportion to their shares: the total is read off the axis, the shares
    # off the bar, both to scale.
    origin = min(positive + [b.dynamic.low / scale for _, b in rows if b.dynamic.low > 0]) / 3
    drawn = set()
    for k, (_, b) in enumerate(rows):
        edges = _edges(b, totals[k], scale, origin if log else None)
        for part, (left, right) in zip(b.parts, itertools.pairwise(edges), strict=True):
            ax.barh(k, right - left, left=left, height=0.7,
                    color=_COLOURS.get(part.name, "0.6"),
                    label=None if part.name in drawn else part.name, edgecolor="white",
                    linewidth=0.4)  # fmt: skip
            drawn.add(part.name)
        _range_bar(ax, k, totals[k], b.dynamic, scale)
    ax.plot([], [], "|-", color="k", linewidth=0.8,
            label="[low, high] of the total\nover the figures' ranges")  # fmt: skip
    ax.set_yticks(range(len(rows)), [name for name, _ in rows], fontsize=7)
    ax.set_ylim(-0.6, len(rows) - 0.4)
    if log:
        ax.set_xscale("log")
        ax.set_xlim(left=origin)
        readable_log_axis(ax.xaxis)
    ax.set_xlabel(
        f"dynamic energy per sample [{unit}] at the figures' values"
        + ("; log axis: a bar ends at its total, its parts split it by their shares" if log
           else ", its parts stacked")
    )  # fmt: skip
    ax.set_title("What each sample's dynamic energy is spent on", fontsize=9)
    if static:
        _static_panel(axes[0, 1], rows)
    # One legend for both panels beside the last, off the data: the parts in stacking order,
    # then the range, then static.
    entries = [e for a in axes[0] for e in zip(*a.get_legend_handles_labels(), strict=True)]
    entries.sort(key=lambda e: e[1] not in _COLOURS)  # stable: the rest keep their order
    axes[0, -1].legend(*zip(*entries, strict=True), fontsize=7, loc="upper left",
                       bbox_to_anchor=(1.03, 1.0), borderaxespad=0.0)  # fmt: skip
    fit_layout(fig)
    save_figure(fig, path, dpi=110, bbox_inches="tight")  # the legend sits outside the axes
    plt.close(fig)
    return True


def _edges(b: Breakdown, total: float, scale: float, origin: float | None) -> list[float]:
    """Where each part of ``b`` starts and the last ends, drawn to ``total`` (scaled): stacked
    from 0 on a linear axis (``origin`` ``None``), or splitting the log length from ``origin``
    to ``total`` by the parts' shares."""
    widths = [_at(p.value, EnergyRange(p.low, p.high)) / scale for p in b.parts]
    cumulative = list(itertools.accumulate(widths, initial=0.0))
    if origin is None:
        return cumulative
    if total <= origin:
        return [origin] * len(cumulative)
    span = math.log(total / origin)
    return [origin * math.exp(span * c / total) for c in cumulative]


def _range_bar(ax, k: int, at: float, span: EnergyRange, scale: float) -> None:
    """The ``[low, high]`` of an energy drawn at ``at`` (scaled) as an error bar on row ``k``."""
    ax.errorbar(at, k, xerr=[[at - span.low / scale], [span.high / scale - at]], fmt="none",
                color="k", capsize=2, linewidth=0.8)  # fmt: skip


def _static_panel(ax, rows) -> None:
    """Static energy per sample, hatched, with its range, on an axis of its own."""
    scale, unit = _unit(max(b.static.high for _, b in rows if b.static is not None))
    label = "static and core power\n× the window, apart"
    for k, (_, b) in enumerate(rows):
        if b.static is not None:
            at = _at(b.static_value, b.static) / scale
            ax.barh(k, at, height=0.7, color="0.88", hatch="///", edgecolor="0.45",
                    linewidth=0.4, label=label)  # fmt: skip
            _range_bar(ax, k, at, b.static, scale)
            label = None
    ax.set_xlabel(f"static energy per sample [{unit}]")
    ax.set_title("static, apart", fontsize=9)


def _at(value: float | None, span: EnergyRange) -> float:
    """An energy drawn at its value, or the middle of its range where it has none."""
    return value if value is not None else (span.low + span.high) / 2


def _unit(top: float) -> tuple[float, str]:
    """The scale and unit that draw energies up to ``top`` [J] readably."""
    for unit, scale in (("J", 1.0), ("mJ", 1e-3), ("µJ", 1e-6), ("nJ", 1e-9)):
        if top >= scale:
            return scale, unit
    return 1e-12, "pJ"
