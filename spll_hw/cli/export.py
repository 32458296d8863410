"""``spll-hw export``: write a network for another toolchain (the targets registered in
:mod:`spll_hw.exporters`: Lava processes, a NIR graph)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import add_network_argument
from .inputs import read_network


def register(sub: argparse._SubParsersAction) -> None:
    from .. import exporters

    targets = exporters.names()
    p = sub.add_parser(
        "export",
        help="export a network for another toolchain (" + ", ".join(targets) + ")",
        description="Write the network of --network for another toolchain into a folder (which "
        "also gets the network as params.toml). Targets: "
        + "; ".join(f"{t}: {exporters.describe(t)}" for t in targets),
    )
    p.add_argument("--to", required=True, choices=targets, help="export target")
    add_network_argument(p)
    p.add_argument(
        "--profile", help="chip profile of exports with integer parameters (lava: default loihi2)"
    )
    p.add_argument("--dt", type=float, help="time step [s] of clocked exports (default: the "
                   "profile's)")  # fmt: skip
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from .. import exporters
    from ..files import write_text

    export = exporters.get(args.to)
    config = read_network(args).config
    network = config.build()
    files = export(network, args.out, profile=args.profile, dt=args.dt)
    files.append(args.out / "params.toml")
    write_text(files[-1], config.to_toml())
    print(f"{network.n_spll} sPLLs ({config.layout}) exported to {args.to}:")
    for path in files:
        print(f"  {path}")
    return 0
