"""``spll-hw export``: write a network for another toolchain and check it (its parser; the job is
:mod:`spll_hw.cli.jobs.export`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import exporters
from .arguments import add_network_argument, add_one_value_argument

#: The command's line in ``spll-hw --help``.
HELP = "export a network for another toolchain (Lava processes, a NIR graph) and check it"
#: What ``spll-hw export --help`` says first (the registered targets follow).
DESCRIPTION = (
    "Write the network of --network for another toolchain into a folder (which also gets the "
    "network as params.toml), simulate what was written by the rules its target runs against "
    "the golden model (a Poisson and a periodic train at the network's lowest, middle and "
    "highest free-running frequency, 1 s each, and the --check-input trains) and record it in "
    "check.json and the folder's README. An export whose total TDE-rate error exceeds "
    "--max-error fails (exit status 2) and writes nothing, unless --allow-error."
)
#: Where an export goes without ``--out`` (``--check FOLDER`` writes nowhere without it).
DEFAULT_OUT = Path("reports/export")


def add_arguments(p: argparse.ArgumentParser) -> None:
    targets = exporters.names()
    head = p.description
    # each target described by its exporter's docstring, loaded only for ``export --help``
    p.description = lambda: (
        head + " Targets: " + "; ".join(f"{t}: {exporters.describe(t)}" for t in targets)
    )
    p.usage = "%(prog)s (--to TARGET | --check FOLDER [--to TARGET]) [options]"
    p.add_argument(
        "--to", choices=targets, help="export target (with --check: if no check.json says it)"
    )
    add_network_argument(p, why="; a multichannel network (spll-hw slide's, [[channel]] tables) "
                         "exports to --to nir, nir-standard or lava-standard")  # fmt: skip
    add_one_value_argument(
        p, "--profiles", "chip profile of exports with integer parameters (lava: default loihi2)"
    )
    p.add_argument("--dt", type=float, help="time step [s] of clocked exports (default: the "
                   "profile's; nir-standard and lava-standard: the coarsest of their steps whose "
                   "check passes, each step's result on stderr; where none does, lava-standard "
                   "tries a clock per sPLL, then with graded CCO currents, for offline "
                   "runs)")  # fmt: skip
    p.add_argument("--out", type=Path,
                   help=f"output folder (default: {DEFAULT_OUT}): new, empty or one that holds "
                   "an export, which is "
                   "replaced as a whole (a folder that holds other files is refused); with "
                   "--check, where the check's record goes")  # fmt: skip
    p.add_argument("--check", type=Path, metavar="FOLDER",
                   help="check an exported folder again (its params.toml, its check.json's "
                   "target and inputs, their length) instead of exporting; prints the verdict "
                   "and writes nothing into FOLDER (its own check stays as exported): --out "
                   "DIR writes this check's check.json, README.md, check_inputs.npz and "
                   "cost.json there; a --max-error below golden's own resolution on its inputs "
                   "is refused before the check runs")  # fmt: skip
    p.add_argument("--check-input", type=Path, action="append", default=[], metavar="FILE",
                   help="also check on these input spike times [s] (.npy, .csv or text, as "
                   "simulate --input; run 1 s or up to the last spike); repeatable")  # fmt: skip
    p.add_argument("--check-duration", type=float, default=None, metavar="SECONDS",
                   help="length of the check's reference inputs (default 1 s, and for --check "
                   "FOLDER the folder's own); the check states how far golden is from itself "
                   "on them (its resolution) and says where that exceeds half the limit: longer "
                   "inputs resolve finer. nir-standard and lava-standard choose their step and "
                   "gate on them (each check as much longer); without this flag they check "
                   "a step again on 10 s where 1 s cannot resolve its verdict and 10 s "
                   "can")  # fmt: skip
    p.add_argument("--max-error", type=float, metavar="FRACTION",
                   help="largest total TDE-rate error against golden (0.1 is 10 %%; default: "
                   "the target's declared tolerance, spll-hw backends); without --dt, "
                   "nir-standard and lava-standard choose their step by it")  # fmt: skip
    p.add_argument("--allow-error", action="store_true",
                   help="write the export although its check fails (its README says so at the "
                   "top); without --dt, nir-standard and lava-standard write the step whose "
                   "check came closest where none passes")  # fmt: skip
    g = p.add_argument_group("the check on the network's own signal and sPLL by sPLL")
    g.add_argument("--data", metavar="DIR", help="BioTac_slide_20_50 folder: a network that "
                   "carries an encoder (an [encoder] table, or a preset "
                   "<dataset>-<layout>-<encoder>) is also checked on windows of 4 held-out "
                   "recordings (33-40) encoded by it (default: $SPLL_HW_BIOTAC_DIR for a biotac "
                   "preset; else synthetic textures through the same encoder); check.json names "
                   "each input")  # fmt: skip
    g.add_argument("--max-failed-splls", type=int, metavar="N", help="how many sPLLs may fail "
                   "the check's per-sPLL verdict (an open-loop CCO, a TDE that falls silent or "
                   "runs away; default 0)")  # fmt: skip
    _add_multichannel_arguments(p)


def _add_multichannel_arguments(p: argparse.ArgumentParser) -> None:
    """The flags of a multichannel export (:func:`_export_multichannel`)."""
    g = p.add_argument_group("a multichannel --network: --to nir, one NIR graph of one input "
                             "per channel; --to nir-standard (lava-standard), one checked export "
                             "per channel group (on its channels' encoded signals with --data) "
                             "and the readout as standard nodes (nir-standard only)")  # fmt: skip
    g.add_argument(
        "--readout",
        metavar="FILE",
        help="with a multichannel --network: the trained spiking readout to export after the "
        "TDEs (a .npz that spll-hw slide --readout saves in OUT/readouts/); an integer readout "
        "that decides its training recordings more than 2 points below its float weights is "
        "refused unless --allow-error",
    )
    g.add_argument(
        "--threshold",
        type=float,
        metavar="THETA",
        help="with --readout: the decision threshold [score x s] (spll-hw slide's readout "
        "table lists them; inf: the largest membrane at the end decides)",
    )
