"""``spll-hw fit``: what one network needs on one chip, and why it fits or not.

``--layouts grouped:auto`` picks the largest number of time-scale groups whose network fits the
profile (its circuits, cores and configurations), the layout closest to time-scaled that the
chip can hold.
"""

from __future__ import annotations

import argparse

from .arguments import add_network_argument, add_steps_argument, split_list, stepped_profiles

#: The command's line in ``spll-hw --help``.
HELP = "whether a network fits chip profiles, what it needs and why not"
#: What ``spll-hw fit --help`` says first.
DESCRIPTION = (
    "Map the network of --network onto each chip of --profiles and say whether it fits "
    "(neurons, synapses, distinct configurations, cores and chips, per-core use) and, when "
    "it does not, why. Exit status 0 when it fits (on at least one profile or step), 1 when "
    "it does not (also when no grouped layout fits for --layouts grouped:auto), 2 for bad "
    "input. --layouts grouped:auto picks the largest number of groups that fits. With a --backend "
    "that runs a construction of standard neurons (nir-numpy, standard-fixed-point), its "
    "neurons and synapses at its step are placed instead of the two-compartment sPLL. On a "
    "clocked chip it also says how far the network in the chip's own integer arithmetic is "
    "from golden on a 1-s Poisson train."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p)
    p.add_argument(
        "--profiles",
        required=True,
        metavar="PROFILES",
        help="comma-separated chip profiles (names or TOML files), each fitted in turn",
    )
    add_steps_argument(p)
    p.add_argument(
        "--backend",
        metavar="SPEC",
        help="place what this backend runs (spll-hw backends): the construction of standard "
        "neurons of nir-numpy, standard-fixed-point, ... at its dt (a stepped profile "
        "NAME@STEP: at that step) (default: the two-compartment sPLL)",
    )


def run(args: argparse.Namespace) -> int:
    from .. import chips

    names = split_list(args.profiles)
    if not names:
        raise ValueError("--profiles: give at least one chip profile (spll-hw chips lists them)")
    for name in names:
        chips.describe(name)  # unknown or broken profiles fail first
    profiles = stepped_profiles(names, args.steps)
    fits = []
    for profile in profiles:
        if len(profiles) > 1:
            print(f"\n## {profile}\n")
        fits.append(fit_one(args, profile))
    if len(profiles) > 1:
        works = [p for p, ok in zip(profiles, fits, strict=True) if ok]
        print(f"\nfits on: {', '.join(works) or 'none of them'}")
    return 0 if any(fits) else 1


def fit_one(args: argparse.Namespace, profile: str) -> bool:
    """Print whether ``--network`` (in ``--layouts``) fits chip ``profile``; whether it does."""
    from .. import chips
    from ..config import read_network_file
    from ..harness.costs import auto_groups

    config = read_network_file(args.network).config
    layout = args.layout
    if layout == "grouped:auto":
        try:
            layout = f"grouped:{auto_groups(config, profile)}"
        except ValueError as exc:  # nothing fits: an answer (exit 1), not bad input
            print(f"does not fit: {exc}")
            return False
        print(f"grouped:auto on {profile}: {layout} is the largest that fits")
    network = (config.with_layout(layout) if layout else config).build()
    if args.backend is not None:
        from ..neuron_graph import graph_resources, run_by

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
    fit = chips.resources(network, profile)
    print(fit.markdown)
    _say(chips.arithmetic_line(network, profile))
    return fit.fits


def _say(line: str) -> None:
    if line:
        print(line)
