"""``spll-hw compare``: error against run time of every backend versus the golden model."""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import DEFAULT_DTS, add_network_argument

#: The command's line in ``spll-hw --help``.
HELP = "error against run time of backends (Brian2, Lava, fixed point, USB) vs golden"
#: What ``spll-hw compare --help`` says first.
DESCRIPTION = (
    "Simulate the same Poisson samples on each backend and report wall time per "
    "sample against TDE-rate, TDE-count and spike-time error versus the golden model "
    "(Markdown table, JSON and a work-precision plot)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p)
    p.add_argument(
        "--backends",
        help="comma-separated backend specs, e.g. golden,brian2-cpp_standalone,lava-fixed "
        "(options after ':', e.g. brian2-numpy:dt=1e-5; spll-hw backends lists them) (default: "
        "golden, golden-fixed-point and brian2-cpp_standalone where Brian2 is installed)",
    )
    p.add_argument(
        "--dt",
        default=DEFAULT_DTS,
        help="time steps [s] of the curve of every clocked backend without its own dt",
    )
    p.add_argument("--samples", type=int, default=3, help="Poisson samples")
    p.add_argument("--rate", type=float, default=300.0, help="input rate [Hz]")
    p.add_argument("--duration", type=float, default=2.0, help="seconds per sample")
    p.add_argument("--seed", type=int, default=0, help="seed of the first sample")
    p.add_argument("--out", type=Path, default=Path("reports/compare"), help="report folder")
