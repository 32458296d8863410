"""``spll-hw chips``: the chip profiles as resources and costs (its parser; the job, which
lists, fits and costs them, is :mod:`spll_hw.cli.jobs.chips`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import add_network_argument, add_steps_argument

#: Marks a value that rests on at least one assumed figure.
ASSUMED_MARK = "*"


#: The command's line in ``spll-hw --help``.
HELP = "chip profiles as resources and costs: fit, cores, energy per sample, latency"
#: What ``spll-hw chips --help`` says first.
DESCRIPTION = (
    "List the chip profiles with their resources, timing and energy figures "
    "and sources; with --network, map the network onto each chip and report whether it "
    "fits, the cores and chips it needs, how far its TDE rates are from golden in a clocked "
    "chip's own integer arithmetic (a 1-s Poisson train), the energy of one Poisson sample "
    "by category, the step latency and the real-time factor. With --export, cost an export "
    "folder as its cost.json does. Figures no public source gives are marked "
    f"'{ASSUMED_MARK} assumed'."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p, default=None, why=" (default: none; list the profiles); a "
                         "multichannel network (spll-hw slide's, [[channel]] tables) is costed "
                         "per classification, see the options below")  # fmt: skip
    p.add_argument(
        "--profiles",
        help="comma-separated profiles (names or TOML files) (default: every bundled profile)",
    )
    add_steps_argument(p)
    p.add_argument(
        "--backend",
        metavar="SPEC",
        help="simulator of the sample (spll-hw backends lists them); one that runs a "
        "construction of standard neurons (nir-numpy, standard-fixed-point) has that "
        "construction costed, its neurons and synapses at its dt (a stepped profile: at that "
        "step) (default: golden:profile=NAME, the exact model of the network as each chip "
        "realises it)",
    )
    p.add_argument(
        "--export",
        type=Path,
        metavar="FOLDER",
        help="cost an export folder (spll-hw export) from its files instead of a network: what "
        "it writes (network.nir, params.npz, lava.json) at its step, run again on its check's "
        "inputs (check_inputs.npz); energy per second of input, as its cost.json states it "
        "(default profile: the folder's own, else loihi2)",
    )
    p.add_argument("--rate", type=float, default=300.0, help="input rate [Hz]")
    p.add_argument("--duration", type=float, default=2.0, help="seconds per sample")
    p.add_argument("--seed", type=int, default=0, help="seed of the Poisson sample")
    p.add_argument("--out", type=Path, default=Path("reports/chips"), help="report folder")
    m = p.add_argument_group("a multichannel --network (spll-hw slide's, e.g. "
                             "biotac-multichannel-lif)")  # fmt: skip
    m.add_argument("--data", help="BioTac_slide_20_50 folder whose recordings are costed")
    m.add_argument(
        "--recordings",
        default="1",
        metavar="A-B",
        help="recording numbers costed, every material (default 1: 20 classifications)",
    )
    m.add_argument(
        "--windows",
        dest="window",
        type=float,
        default=4.0,
        metavar="SECONDS",
        help="seconds of the slide per classification (one window here; spll-hw slide "
        "compares several)",
    )
    m.add_argument(
        "--group-steps",
        metavar="CHANNEL=STEP,...",
        help="separate clocks: the [[channel]] table holding CHANNEL on chips of its own, each "
        "clocked profile stepped every STEP there (e.g. pac=80us,ele1=640us); one row per "
        "clock and their sum (default: the whole network on one clock)",
    )
    m.add_argument(
        "--readout-classes",
        type=int,
        default=20,
        metavar="K",
        help="place and cost the spiking readout (K neurons, one per class, a synapse from "
        "every TDE) beside the network (default 20: the materials; 0: leave it out)",
    )
