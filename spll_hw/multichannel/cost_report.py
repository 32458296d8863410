"""``spll-hw chips --network MULTICHANNEL``: a multichannel network on every chip profile, as
Markdown and JSON (:mod:`.chips` does the work)."""

from __future__ import annotations

import argparse
import os

import numpy as np

from .. import chips
from ..chips import format_joules
from ..datasets.biotac import BIOTAC_ENV
from ..datasets.biotac_channels import CHANNELS, LONGEST_WINDOW, load_biotac_channels
from ..datasets.recordings import parse_ranges
from .chips import (
    ClassificationCost,
    ClockedCost,
    Placement,
    classification_cost,
    clocks,
    describe_fit,
    placement,
    readout_placement,
)
from .clocks import parse_group_steps
from .config import MultichannelConfig
from .features import input_levels

#: Marks a value that rests on at least one assumed figure.
ASSUMED_MARK = "*"


def _samples(args: argparse.Namespace, config: MultichannelConfig):
    """The opening samples of ``--recordings`` (every material), ``--windows`` s long, and
    each channel's input level (their own median RMS); ``(None, None)`` without ``--data``."""
    root = args.data or os.environ.get(BIOTAC_ENV)
    if not root:
        return None, None
    if not 0 < args.window <= LONGEST_WINDOW:
        raise ValueError(
            f"--windows must lie in (0, {LONGEST_WINDOW:g}] s (a classification's seconds of "
            f"the slide), got {args.window!r}"
        )
    numbers = parse_ranges(args.recordings)
    samples = load_biotac_channels(root, config.channels, "all", numbers, args.window).openings()
    return samples, input_levels(config, samples)


def report(args: argparse.Namespace, names: list[str]) -> tuple[str, dict]:
    """The Markdown report and JSON payload of a multichannel ``--network`` on every profile of
    ``names`` that has a ``[resources]`` table; with ``--group-steps``, each clocked profile
    runs those groups on clocks (chips) of their own (:func:`.chips.clocks`), one row per clock
    and their sum."""
    config = MultichannelConfig.load(args.network)
    config.check_channels(CHANNELS)
    steps = parse_group_steps(getattr(args, "group_steps", None), config)
    samples, levels = _samples(args, config)
    classes = args.readout_classes
    if classes < 0:
        raise ValueError(f"--readout-classes must be >= 0 (0: no readout), got {classes}")
    places: list[Placement] = []
    rows, readout_rows, sections, results, skipped = [], [], [], [], []
    for name in names:
        if not any(f.table == "resources" for f in chips.figures(name)):
            skipped.append(name)
            continue
        clocked = bool(steps) and chips.describe(name).clocked
        parts = (
            [
                _Part(f"{c.profile}: {c.label}", c.profile, c.config, 0)
                for c in clocks(config, name, steps)
            ]  # fmt: skip
            if clocked
            else [_Part(name, name, config, classes)]
        )
        for part in parts:
            part.run(args, samples, levels)
            places.append(part.place)
            rows.append(part.row())
            sections += part.section + [""]
            readout_rows += [part.readout_row] if part.readout_row else []
        if not clocked:
            results.append(parts[0].entry)
            continue
        rows.append(_clocked_row(name, parts))
        results.append({"profile": name, "clocks": [p.entry for p in parts],
                        "classification": _clocked_entry(parts)})  # fmt: skip
    costed = (
        f"one classification = the first {args.window:g} s of every channel of the opening "
        f"samples of recordings {args.recordings}, every material ({len(samples)} samples, "
        "each channel divided by its own median RMS over them); mean per classification"
        if samples is not None
        else "no --data: fit and placement only, nothing costed"
    )
    head = [
        "# A multichannel network on the chips: fit, placement and cost",
        "",
        f"`{args.network}`: {len(config.channels)} channels, {config.n_spll} sPLLs, each "
        "channel's spikes sent only to the cores holding its TDEs; " + costed + ".",
        "",
        "| profile | fits | cores | chips | sPLLs split over 2 cores | input messages per "
        "spike, all channels | dynamic energy / classification | of it on assumed figures "
        "| static energy, apart | real-time factor (worst sample) | decision latency |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"{ASSUMED_MARK} rests on assumed figures; [low, high]: every figure at the low and the "
        "high end of its range. Decision latency: the window, or window x "
        "real-time factor on a chip slower than real time; the readout is apart (below, "
        "without --readout-classes 0). A network that does not fit is costed on the placement "
        "it would need."
        + (
            " Separate clocks (--group-steps): each clock's groups on chips of their own, "
            "one row per clock and their sum (in bold); no readout is placed on them."
            if steps
            else ""
        ),
        "",
        "Why not, per profile:",
        "",
        describe_fit(places),
    ]
    if readout_rows:
        head += ["", *_readout_table(classes, config.n_spll, readout_rows)]
    if skipped:
        head += ["", f"Skipped (no [resources] table): {', '.join(skipped)}."]
    payload = {
        "multichannel": str(args.network),
        "channels": list(config.channels),
        "n_spll": config.n_spll,
        "window_s": args.window if samples is not None else None,
        "recordings": args.recordings if samples is not None else None,
        "readout_classes": classes or None,
        "profiles": results,
        "skipped": skipped,
    }
    return "\n".join(head + [""] + sections).rstrip(), payload


class _Part:
    """Some channels of the network on one profile: placed, costed (with ``--data``), its
    table row, its section and its JSON entry (:func:`report`)."""

    def __init__(self, label: str, profile: str, config: MultichannelConfig, classes: int):
        self.label, self.profile, self.config, self.classes = label, profile, config, classes
        self.cost: ClassificationCost | None = None
        self.cells = ["-"] * 5
        self.readout_row = ""

    def run(self, args, samples, levels) -> None:
        config, name = self.config, self.profile
        self.place = place = placement(config, name)
        self.entry = {"profile": self.label, "resources": place.fit.data, "channels_per_core": [
            {c: list(v) for c, v in core.items()} for core in place.cores]}  # fmt: skip
        self.section = [f"## {self.label}", "", place.fit.markdown, "", place.markdown()]
        readout = readout_placement(config, name, self.classes) if self.classes else None
        if samples is not None and place.fit.cores:
            costed = self.classes if readout is not None and readout.cores else 0
            self.cost = classification_cost(config, name, samples, levels, args.window,
                                            classes=costed, progress=True)  # fmt: skip
            self.cells, self.entry["classification"] = _cost_cells(self.cost)
            self.section += ["", "First sample's cost:", "", self.cost.costs[0].markdown]
        if readout is not None:
            self.readout_row = _readout_row(name, readout, self.cost)
            self.entry["readout"] = readout.data
            self.section += ["", readout.markdown]
            if self.cost is not None and self.cost.readout:
                self.entry["readout"]["classification"] = _readout_entry(self.cost)
                self.section += ["", "First sample's readout:", "",
                                 self.cost.readout[0].markdown]  # fmt: skip

    def row(self) -> str:
        fit = self.place.fit
        messages = fit.data.get("input_messages_per_spike")
        return (
            f"| {self.label} | {'yes' if fit.fits else 'no'} | {fit.cores_words()} | {fit.chips} "
            f"| {self.place.split} | {messages} | " + " | ".join(self.cells) + " |"
        )


def _clocked_row(name: str, parts: list[_Part]) -> str:
    """The sum of a profile's clocks, in bold."""
    fits = all(p.place.fit.fits for p in parts)
    cells = ["-"] * 5
    if all(p.cost is not None for p in parts):
        cells = _cost_cells(ClockedCost(tuple(p.cost for p in parts)))[0]
    ranges = [p.place.fit.cores_range or (p.place.fit.cores,) * 2 for p in parts]
    cores = sum(p.place.fit.cores for p in parts)
    low, high = (sum(r[i] for r in ranges) for i in (0, 1))
    total = [
        str(cores) if low == high else f"{cores} [{low}, {high}]",
        sum(p.place.fit.chips for p in parts),
        sum(p.place.split for p in parts),
        sum(p.place.fit.data.get("input_messages_per_spike") or 0 for p in parts),
    ]  # fmt: skip
    return (
        f"| **{name}, {len(parts)} clocks** | {'yes' if fits else 'no'} | "
        + " | ".join(str(x) for x in [*total, *cells])
        + " |"
    )


def _clocked_entry(parts: list[_Part]) -> dict | None:
    """The JSON of the sum of a profile's clocks (``None``: not costed)."""
    if any(p.cost is None for p in parts):
        return None
    return _cost_cells(ClockedCost(tuple(p.cost for p in parts)))[1]


def _cost_cells(cost) -> tuple[list[str], dict]:
    """The table cells (energy with its range, assumed share, static, real-time factor,
    latency) and the JSON entry of a :class:`.chips.ClassificationCost` or
    :class:`.chips.ClockedCost`."""
    mark = f" {ASSUMED_MARK}" if cost.assumed else ""
    span = cost.dynamic_range
    dynamic = format_joules(cost.dynamic_energy)
    dynamic += f" {ASSUMED_MARK}" if cost.assumed_dynamic_energy else ""
    if span.high > span.low:
        dynamic += f" [{format_joules(span.low)}, {format_joules(span.high)}]"
    share = (
        "-"
        if cost.dynamic_energy == 0
        else f"{100 * cost.assumed_dynamic_energy / cost.dynamic_energy:.0f} %"
    )
    static = "-" if cost.static_energy is None else format_joules(cost.static_energy)
    rtf = "-" if cost.real_time_factor is None else f"{cost.real_time_factor:.3g}{mark}"
    latency = "-" if cost.latency is None else f"{cost.latency:.3g} s{mark}"
    entry = {
        "window_s": cost.window,
        "samples": cost.samples,
        "input_spikes": cost.input_spikes,
        "dynamic_energy_j": cost.dynamic_energy,
        "dynamic_range_j": [span.low, span.high],
        "dynamic_assumed_j": cost.assumed_dynamic_energy,
        "static_energy_j": cost.static_energy,
        "real_time_factor": cost.real_time_factor,
        "latency_s": cost.latency,
        "crossing_messages": cost.crossing,
        "assumed": list(cost.assumed),
    }
    return [dynamic, share, static, rtf, latency], entry


def _readout_table(classes: int, features: int, rows: list[str]) -> list[str]:
    """The readout's section of the report, above the per-profile sections."""
    return [
        "## The spiking readout beside it",
        "",
        f"{classes} integrate-and-fire neurons (one per class), each with a synapse from every "
        f"one of the {features} TDEs, on cores of their own after the network's; every TDE "
        "spike adds one message per readout core (unicast) or extends its multicast tree; "
        "updates every step on a clocked chip; one spike, the winner's (quantize/readout.py).",
        "",
        "| profile | fits | cores | synapses (weight memory) | messages per TDE spike "
        "| readout dynamic energy / classification | network + readout | readout's share "
        "| readout's static energy, apart | why not |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
        *rows,
    ]


def _readout_row(name: str, readout, cost: ClassificationCost | None) -> str:
    """One profile's row of :func:`_readout_table`."""
    data = readout.data
    bits = data["synapse_bits"]
    memory = f"{data['synapses']}" + ("" if bits is None else f" ({bits / 8e3:.4g} kB)")
    energy = both = share = static = "-"
    if cost is not None and cost.readout:
        mine = cost.readout_energy
        assumed = any(c.assumed_dynamic_energy for c in cost.readout)
        energy = format_joules(mine) + (f" {ASSUMED_MARK}" if assumed else "")
        both = format_joules(mine + cost.dynamic_energy)
        share = f"{100 * mine / (mine + cost.dynamic_energy):.2g} %"
        apart = [c.static_energy for c in cost.readout]
        static = "-" if None in apart else format_joules(float(np.mean(apart)))
    why = "; ".join(readout.problems) or "-"
    return (
        f"| {name} | {'yes' if readout.fits else 'no'} | {readout.cores} | {memory} "
        f"| {data['messages_per_tde_spike']:.3g} | {energy} | {both} | {share} | {static} "
        f"| {why} |"
    )


def _readout_entry(cost: ClassificationCost) -> dict:
    """The JSON of the readout's share of the classifications."""
    return {
        "dynamic_energy_j": cost.readout_energy,
        "dynamic_assumed_j": float(np.mean([c.assumed_dynamic_energy for c in cost.readout])),
        "static_energy_j": None
        if any(c.static_energy is None for c in cost.readout)
        else float(np.mean([c.static_energy for c in cost.readout])),
        "first_sample": cost.readout[0].data,
    }
