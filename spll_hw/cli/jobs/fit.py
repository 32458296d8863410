"""``spll-hw fit``: what one network needs on one chip, and why it fits or not."""

from __future__ import annotations

import argparse

from ... import chips
from ...config import read_network_file
from ...harness.costs import auto_groups
from ...network import Network
from ...neuron_graph import graph_resources, run_by
from ..arguments import split_list
from ..inputs import stepped_profiles


def run(args: argparse.Namespace) -> int:
    names = split_list(args.profiles)
    if not names:
        raise ValueError("--profiles: give at least one chip profile (spll-hw chips lists them)")
    for name in names:
        chips.describe(name)  # unknown or broken profiles fail first
    profiles = stepped_profiles(names, args.steps)
    fits = []
    built: dict[str | None, Network] = {}  # by layout: a grouped one takes seconds to build
    for profile in profiles:
        if len(profiles) > 1:
            print(f"\n## {profile}\n")
        fits.append(fit_one(args, profile, built))
    if len(profiles) > 1:
        works = [p for p, ok in zip(profiles, fits, strict=True) if ok]
        print(f"\nfits on: {', '.join(works) or 'none of them'}")
    return 0 if any(fits) else 1


def fit_one(args: argparse.Namespace, profile: str, built: dict[str | None, Network]) -> bool:
    """Print whether ``--network`` (in ``--layouts``) fits chip ``profile``; whether it does.
    ``built``: the networks built so far by layout, which it adds to."""
    config = read_network_file(args.network).config
    layout = args.layout
    if layout == "grouped:auto":
        try:
            layout = f"grouped:{auto_groups(config, profile)}"
        except ValueError as exc:  # nothing fits: an answer (exit 1), not bad input
            print(f"does not fit: {exc}")
            return False
        print(f"grouped:auto on {profile}: {layout} is the largest that fits")
    if layout not in built:
        built[layout] = (config.with_layout(layout) if layout else config).build()
    network = built[layout]
    if args.backend is not None:
        try:
            _, graph = run_by(args.backend, network, profile)
        except ValueError as exc:
            print(f"does not fit: {exc}")
            return False
        if graph is not None:
            fit = graph_resources(graph, profile)
            print(f"Placed in place of the two-compartment sPLL: the {graph.target} construction "
                  f"that `{args.backend}` runs ({graph.description}), {graph.neurons} neurons "
                  f"and {graph.n_synapses} synapses at {graph.step_words()}.\n")  # fmt: skip
            print(fit.markdown)
            return fit.fits
    if not chips.figures(profile) or "@" in profile:  # formats, budgets, a step's decays
        try:
            chips.realise(network, profile)
        except ValueError as exc:
            print(f"does not fit: {exc}")
            return False
    if not chips.figures(profile):
        print(f"fits {profile!r}'s circuit budget and number formats (the profile has no "
              "chip tables: cores, energy and latency are not modelled)")  # fmt: skip
        _say(chips.arithmetic_line(network, profile))
        return True
    fit = chips.resources(chips.OnChip(network, profile))
    print(fit.markdown)
    _say(chips.arithmetic_line(network, profile))
    return fit.fits


def _say(line: str) -> None:
    if line:
        print(line)
