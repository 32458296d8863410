"""``spll-hw simulate``: run one input spike train through an sPLL network on one backend (the
golden model by default)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import add_backend_argument, add_network_argument

#: The command's line in ``spll-hw --help``.
HELP = "simulate one spike train through an sPLL network (golden model or --backend)"
#: What ``spll-hw simulate --help`` says first.
DESCRIPTION = (
    "Simulate one input spike train through a network of sPLLs (by default "
    "with the exact, event-driven golden model) and write rates, spikes and plots to a "
    "report folder. The activity plot needs a backend with probes (golden)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p)
    add_backend_argument(p)
    source = p.add_mutually_exclusive_group()
    source.add_argument("--input", type=Path, help="spike times [s]: .npy, .csv or text file")
    source.add_argument("--rate", type=float, default=300.0, metavar="HZ",
                        help="Poisson input at this rate [Hz]")  # fmt: skip
    source.add_argument("--periodic", type=float, metavar="HZ", help="periodic input [Hz]")
    p.add_argument("--duration", type=float, default=2.0, help="seconds")
    p.add_argument("--phase-noise", type=float, default=0.0, metavar="SECONDS",
                   help="spike-time jitter sd [s] of the sPLL inputs (0: none)")  # fmt: skip
    p.add_argument("--seed", type=int, default=0, help="seed of input and noise")
    p.add_argument("--show", type=int, help="sPLL whose activity is plotted (default: middle)")
    p.add_argument("--out", type=Path, default=Path("reports/simulate"), help="report folder")
