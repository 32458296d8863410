"""``spll-hw chips --multichannel``: a multichannel network on every chip profile, as Markdown
and JSON (:mod:`.chips` does the work)."""

from __future__ import annotations

import argparse
import os

from .. import chips
from .chips import Placement, classification_cost, describe_fit, placement
from .config import MultichannelConfig

#: Marks a value that rests on at least one assumed figure.
ASSUMED_MARK = "*"


def _joules(x: float) -> str:
    """``x`` [J] in uJ, mJ or J."""
    if x < 1e-3:
        return f"{x * 1e6:.4g} uJ"
    return f"{x * 1e3:.4g} mJ" if x < 1 else f"{x:.4g} J"


def _samples(args: argparse.Namespace, config: MultichannelConfig):
    """The opening samples of ``--recordings`` (every material), ``--window`` s long, and
    each channel's input level (their own median RMS); ``(None, None)`` without ``--data``."""
    from ..cli.inputs import BIOTAC_ENV, parse_ranges
    from ..datasets.biotac_channels import load_biotac_channels
    from .features import input_levels

    root = args.data or os.environ.get(BIOTAC_ENV)
    if not root:
        return None, None
    if not args.window > 0:
        raise ValueError(f"--window must be > 0 s, got {args.window!r}")
    numbers = parse_ranges(args.recordings)
    samples = load_biotac_channels(root, config.channels, "all", numbers, args.window).openings()
    return samples, input_levels(config, samples)


def report(args: argparse.Namespace, names: list[str]) -> tuple[str, dict]:
    """The Markdown report and JSON payload of ``--multichannel`` on every profile of
    ``names`` that has a ``[resources]`` table."""
    from ..datasets.biotac_channels import CHANNELS

    config = MultichannelConfig.load(args.multichannel)
    config.check_channels(CHANNELS)
    samples, levels = _samples(args, config)
    places: list[Placement] = []
    rows, sections, results, skipped = [], [], [], []
    for name in names:
        if not any(f.table == "resources" for f in chips.figures(name)):
            skipped.append(name)
            continue
        place = placement(config, name)
        places.append(place)
        entry = {"profile": name, "resources": place.fit.data, "channels_per_core": [
            {c: list(v) for c, v in core.items()} for core in place.cores]}  # fmt: skip
        cells = ["-"] * 5
        section = [f"## {name}", "", place.fit.markdown, "", place.markdown()]
        if samples is not None and place.fit.cores:
            cost = classification_cost(config, name, samples, levels, args.window)
            cells, entry["classification"] = _cost_cells(cost)
            section += ["", "First sample's cost:", "", cost.costs[0].markdown]
        messages = place.fit.data.get("input_messages_per_spike")
        rows.append(
            f"| {name} | {'yes' if place.fit.fits else 'no'} | {place.fit.cores} "
            f"| {place.fit.chips} | {place.split} | {messages} | " + " | ".join(cells) + " |"
        )
        sections += section + [""]
        results.append(entry)
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
        f"`{args.multichannel}`: {len(config.channels)} channels, {config.n_spll} sPLLs, each "
        "channel's spikes sent only to the cores holding its TDEs; " + costed + ".",
        "",
        "| profile | fits | cores | chips | sPLLs split over 2 cores | input messages per "
        "spike, all channels | dynamic energy / classification | of it on assumed figures "
        "| static energy, apart | real-time factor (worst sample) | decision latency |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
        f"{ASSUMED_MARK} rests on assumed figures. Decision latency: the window, or window x "
        "real-time factor on a chip slower than real time; the ridge readout (on the host) "
        "is not costed. A network that does not fit is costed on the placement it would need.",
        "",
        "Why not, per profile:",
        "",
        describe_fit(places),
    ]
    if skipped:
        head += ["", f"Skipped (no [resources] table): {', '.join(skipped)}."]
    payload = {
        "multichannel": str(args.multichannel),
        "channels": list(config.channels),
        "n_spll": config.n_spll,
        "window_s": args.window if samples is not None else None,
        "recordings": args.recordings if samples is not None else None,
        "profiles": results,
        "skipped": skipped,
    }
    return "\n".join(head + [""] + sections).rstrip(), payload


def _cost_cells(cost) -> tuple[list[str], dict]:
    """The table cells (energy, assumed share, static, real-time factor, latency) and the
    JSON entry of a :class:`.chips.ClassificationCost`."""
    first = cost.costs[0]
    mark = f" {ASSUMED_MARK}" if first.assumed else ""
    dynamic = _joules(cost.dynamic_energy)
    dynamic += f" {ASSUMED_MARK}" if cost.assumed_dynamic_energy else ""
    share = (
        "-"
        if cost.dynamic_energy == 0
        else f"{100 * cost.assumed_dynamic_energy / cost.dynamic_energy:.0f} %"
    )
    static = "-" if cost.static_energy is None else _joules(cost.static_energy)
    rtf = "-" if cost.real_time_factor is None else f"{cost.real_time_factor:.3g}{mark}"
    latency = "-" if cost.latency is None else f"{cost.latency:.3g} s{mark}"
    entry = {
        "window_s": cost.window,
        "samples": len(cost.costs),
        "input_spikes": cost.input_spikes,
        "dynamic_energy_j": cost.dynamic_energy,
        "dynamic_assumed_j": cost.assumed_dynamic_energy,
        "static_energy_j": cost.static_energy,
        "real_time_factor": cost.real_time_factor,
        "latency_s": cost.latency,
        "crossing_messages": cost.crossing,
        "assumed": list(first.assumed),
    }
    return [dynamic, share, static, rtf, latency], entry
