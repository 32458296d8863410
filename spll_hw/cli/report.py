"""``spll-hw report``: the main job — accuracy lost per layout × chip constraint, and how far each
backend is from the golden model for its run time, as one report folder (its parser; the job is
:mod:`spll_hw.cli.jobs.report`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import chips
from .arguments import (
    REPORT_CHIP_DRAWS,
    THESIS_PHASE_NOISE,
    TUNE_CHIP_DRAWS,
    add_backend_argument,
    add_cv_argument,
    add_dataset_arguments,
    add_jobs_argument,
    add_network_argument,
    add_noise_arguments,
    add_one_value_argument,
    add_steps_argument,
)

#: The report's network: the base sPLL tuned for the time-scaled layout, its reference.
DEFAULT_NETWORK = "vibtac-time-scaled-lif"
#: The step ladder of every clocked chip profile (the largest lever on a chip's energy).
DEFAULT_STEPS = "10,40,160us"


#: The command's line in ``spll-hw --help``.
HELP = "accuracy loss per layout x constraint profile and error vs run time per backend"
#: What ``spll-hw report --help`` says first.
DESCRIPTION = (
    "Encode a dataset once, then classify it with the sPLL network built in every layout "
    "(time-scaled, vary-offset, grouped G) under every chip constraint profile, and report the "
    "accuracy change against the unconstrained time-scaled network, plus an "
    "error-against-run-time table of the backends. Runs on the embedded synthetic data without "
    "arguments."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_dataset_arguments(p)
    add_network_argument(
        p, DEFAULT_NETWORK, layout=False, why="; the default is tuned for the time-scaled "
        "layout, the report's reference; every layout of --layouts is built from the file's "
        "base sPLL",
    )  # fmt: skip
    h = p.add_argument_group("harness")
    add_one_value_argument(
        h, "--encoders", "lif, pacinian or peak, with the settings of the --network file's "
        "[encoder] table when it was tuned on this encoder", default="lif",
    )  # fmt: skip
    h.add_argument("--layouts", default="time-scaled,vary-offset,grouped:2,grouped:4,grouped:8",
                   help="comma-separated layouts (grouped:auto: the most groups the first chip "
                   "profile holds)")  # fmt: skip
    h.add_argument(
        "--profiles",
        default="none,loihi2,analog",
        help="comma-separated chip profiles (names or TOML paths; none = exact): "
        f"{', '.join(chips.names())}",
    )
    add_steps_argument(h, DEFAULT_STEPS)
    add_backend_argument(h)
    h.add_argument(
        "--compare-backends",
        default="golden,golden-fixed-point",
        help="backends for the error-vs-run-time table (see spll-hw compare)",
    )
    add_noise_arguments(
        h, THESIS_PHASE_NOISE, repeats=1, why="; 1 here to keep the grid of every layout x "
        "profile cell fast: the cells share their draws, so their changes stay paired",
    )  # fmt: skip
    h.add_argument("--folds", type=int, default=5, help="CV folds")
    h.add_argument(
        "--cv-repeats",
        type=int,
        default=10,
        help="CV repeats with fresh fold shuffles, the same for every cell",
    )
    add_cv_argument(h)
    h.add_argument(
        "--constructions", metavar="SPECS",
        help="backends that approximate the exact sPLL on purpose, comma-separated (e.g. "
        "standard-exact:levels=4,standard-exact:levels=8: the standard-neuron gate with K "
        "levels): each scores every layout x profile again, paired with the exact cell; one "
        "that runs standard neurons (nir-numpy, standard-fixed-point) is also costed there "
        "at its step, against the two-compartment sPLL",
    )  # fmt: skip
    h.add_argument(
        "--chip-draws", type=int, default=REPORT_CHIP_DRAWS, metavar="K",
        help="mismatch draws pooled per analog-profile cell (more than tune's "
        f"{TUNE_CHIP_DRAWS}: the report is the final measure, tune pays for each draw per trial)",
    )  # fmt: skip
    h.add_argument("--seed", type=int, default=0, help="seed of noise, folds and inputs")
    add_jobs_argument(h, "cores")
    h.add_argument("--quiet", action="store_true", help="no progress output")
    h.add_argument("--out", type=Path, default=Path("reports/harness"), help="report folder")
