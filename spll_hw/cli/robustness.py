"""``spll-hw robustness``: a tuned network's held-out figure with the training recordings, the
test recordings and the input scale varied (:mod:`spll_hw.harness.robustness`).

Example::

    spll-hw robustness --dataset biotac --data ../shared/datasets/biotac_slide_20_50 \\
        --recordings 1-40 --holdout-recordings 33-40 --train-recordings 1-24 \\
        --test-blocks 25-32 --encoders pacinian --network biotac-tuned-vary-offset-pacinian \\
        --reference biotac-vary-offset-pacinian --out reports/robust-pacinian
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import (
    THESIS_PHASE_NOISE,
    THESIS_REPEATS,
    add_backend_argument,
    add_dataset_arguments,
    add_jobs_argument,
    add_network_argument,
    add_noise_arguments,
    add_one_value_argument,
)

#: The command's line in ``spll-hw --help``.
HELP = "a tuned network's held-out figure and gain with recordings and input scale varied"
#: What ``spll-hw robustness --help`` says first.
DESCRIPTION = (
    "Score a tuned network and a reference network (same spike trains, ridge classifier "
    "trained on some recordings and tested once on others) with the training recordings, the "
    "test recordings and the input level varied, and report each accuracy and the paired "
    "tuned - reference change with 95 % CIs (bootstrap over the test recordings): whether the "
    "gain survives. Needs numbered recordings (--dataset biotac or folder) and "
    "--holdout-recordings, the baseline's test block."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_dataset_arguments(p)
    add_network_argument(
        p, "biotac-tuned-vary-offset-lif", layout=False,
        why="; the tuned network: its [encoder] table and input_level set the encoding",
    )  # fmt: skip
    r = p.add_argument_group("robustness")
    r.add_argument("--reference", default="biotac-vary-offset-lif", metavar="FILE|PRESET",
                   help="the network the tuned one is compared with (e.g. the thesis preset), "
                   "on the same spike trains")  # fmt: skip
    add_one_value_argument(r, "--encoders", "lif, pacinian or peak", default="lif")
    r.add_argument(
        "--train-recordings", action="append", default=[], metavar="A-B",
        help="a variation trained on these recordings only, tested on --holdout-recordings "
        "(repeatable, e.g. 1-24); the baseline trains on every loaded recording outside it",
    )  # fmt: skip
    r.add_argument(
        "--test-blocks", action="append", default=[], metavar="A-B",
        help="a variation tested on this block instead (repeatable, e.g. 25-32), trained on "
        "every other loaded recording",
    )  # fmt: skip
    r.add_argument("--level-factors", default="0.75,0.9,1.1,1.25",
                   help="the baseline again with the input level times each factor (comma "
                   "list; empty: none)")  # fmt: skip
    add_backend_argument(r)
    add_noise_arguments(r, THESIS_PHASE_NOISE, repeats=THESIS_REPEATS)
    r.add_argument("--seed", type=int, default=0, help="seed of the noise and the bootstrap")
    add_jobs_argument(r, "cores")
    r.add_argument("--quiet", action="store_true", help="no progress output")
    r.add_argument("--out", type=Path, default=Path("reports/robustness"), help="report folder")
