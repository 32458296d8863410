"""``spll-hw export --to nir --multichannel FILE [--readout FILE --threshold THETA]``: a
multichannel network (one graph of one input per channel) and its trained spiking readout as a
NIR graph (:mod:`mappings.nir.multichannel`), read back once written: the same parameters, bit for
bit, and the same readout, or nothing is written."""

from __future__ import annotations

import argparse


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The flags of a multichannel export (beside ``spll-hw export``'s own)."""
    g = p.add_argument_group("multichannel (--to nir only)")
    g.add_argument(
        "--multichannel",
        metavar="FILE|PRESET",
        help="export this multichannel network (spll_hw/multichannel/config.py) instead of "
        "--network: one NIR graph of one input per channel",
    )
    g.add_argument(
        "--readout",
        metavar="FILE",
        help="with --multichannel: the trained spiking readout to export after the TDEs (a "
        ".npz that spll-hw slide --readout saves in OUT/readouts/)",
    )
    g.add_argument(
        "--threshold",
        type=float,
        metavar="THETA",
        help="with --readout: the decision threshold [score x s] (spll-hw slide's readout "
        "table lists them; inf: the largest membrane at the end decides)",
    )


def run(args: argparse.Namespace) -> int:
    from mappings.nir.multichannel import export_multichannel

    from ..multichannel.chips import whole_network
    from ..multichannel.config import MultichannelConfig
    from ..multichannel.readout_file import load_readout

    if args.to != "nir" or args.out is None:
        raise ValueError("--multichannel exports to NIR: give --to nir and --out")
    if args.check is not None or args.check_input or args.profile or args.dt:
        raise ValueError("--multichannel: drop --check, --check-input, --profile and --dt")
    if (args.readout is None) != (args.threshold is None):
        raise ValueError("--readout FILE and --threshold THETA go together")
    config = MultichannelConfig.load(args.multichannel)
    saved = None if args.readout is None else load_readout(args.readout)
    threshold = float("inf") if args.threshold is None else args.threshold
    files = export_multichannel(config, args.out, saved, threshold)
    network, _ = whole_network(config)
    what = "" if saved is None else f" and a {len(saved.readout.class_names)}-class readout"
    print(
        f"{network.n_spll} sPLLs of {len(config.channels)} channels{what} exported to nir "
        "(read back: same parameters and readout):"
    )
    for path in files:
        print(f"  {path}")
    return 0
