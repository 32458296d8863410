"""``spll-hw fit``: what one network needs on one chip, and why it fits or not.

``--layouts grouped:auto`` picks the largest number of time-scale groups whose network fits the
profile (its circuits, cores and configurations), the layout closest to time-scaled that the
chip can hold.
"""

from __future__ import annotations

import argparse

from .arguments import add_network_argument, add_steps_argument

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
