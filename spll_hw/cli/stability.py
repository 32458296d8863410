"""``spll-hw stability``: stiff and extreme parameters through every backend, golden as truth."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import add_network_argument

#: The command's line in ``spll-hw --help``.
HELP = "sweep stiff and extreme parameters through every backend"
#: What ``spll-hw stability --help`` says first.
DESCRIPTION = (
    "Run one-sPLL networks at the edges of the parameter space (time-constant "
    "ratios 1e-3 and 1e3, equal and nearly equal constants, huge gains, input at 1/t_refr, "
    "microsecond time constants) on each backend and report where it diverges from the "
    "golden model or breaks."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--backends",
                   help="comma-separated backend specs, each judged against golden (see "
                   "spll-hw compare) (default: golden-fixed-point and brian2-cpp_standalone "
                   "where Brian2 is installed)")  # fmt: skip
    p.add_argument("--tolerance", type=float, default=0.02,
                   help="largest relative spike-count error judged ok")  # fmt: skip
    p.add_argument("--slack", type=int, default=1,
                   help="spike-count difference always judged ok (a clocked backend can move a "
                   "spike across the end of the run)")  # fmt: skip
    p.add_argument("--cases", help="only the cases whose name contains one of these "
                   "comma-separated words (default: every case)")  # fmt: skip
    p.add_argument("--duration", type=float,
                   help="seconds per case (default: each case's own, 1 s)")  # fmt: skip
    add_network_argument(p, default=None, why="; adds this network, under periodic input at "
                         "--rate, as one more case (default: none, the cases alone)")  # fmt: skip
    p.add_argument("--rate", type=float, default=300.0,
                   help="periodic input [Hz] of the --network case")  # fmt: skip
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument("--out", type=Path, default=Path("reports/stability"), help="report folder")
