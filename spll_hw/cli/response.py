"""``spll-hw response``: TDE rate of one sPLL against the frequency of a periodic input."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import add_network_argument

#: The command's line in ``spll-hw --help``.
HELP = "frequency response of one sPLL (thesis Figures 8-9)"
#: What ``spll-hw response --help`` says first.
DESCRIPTION = (
    "Run the base sPLL of a network file, tuned to a free-running frequency, "
    "against periodic inputs and plot its TDE rate against the input frequency."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p, default="vibtac-time-scaled-peak", why="; the default is the "
                         "network of the thesis's Figure 8a")  # fmt: skip
    p.add_argument("--free-freq", type=float, default=50.0, help="free-running frequency [Hz]")
    p.add_argument("--f-min", type=float, default=0.0, help="lowest input frequency [Hz]")
    p.add_argument("--f-max", type=float, default=100.0, help="highest input frequency [Hz]")
    p.add_argument("--points", type=int, default=2000, help="number of input frequencies")
    p.add_argument("--duration", type=float, default=2.0, help="seconds per input")
    p.add_argument("--out", type=Path, default=Path("reports/response"), help="report folder")
