"""``spll-hw backends``: every registered simulator, what it can do and whether it runs here."""

from __future__ import annotations

import argparse

#: The command's line in ``spll-hw --help``.
HELP = "list the backends (simulators), their capabilities and availability"
#: What ``spll-hw backends --help`` says first.
DESCRIPTION = (
    "List every backend registered in the spll_hw.backends entry-point group "
    "with its capabilities (exact or its time step, float or fixed point, resume, probes, "
    "threads, board), its declared rate tolerance against golden, the extra that installs "
    "it and, when it cannot run here, why. Use a name (with options) wherever a command "
    "takes --backend or --backends."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--options", action="store_true", help="also list every backend's options")
