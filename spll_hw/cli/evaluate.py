"""``spll-hw evaluate``: run the texture pipeline on a dataset and write a report folder.

Examples::

    spll-hw evaluate                                   # embedded synthetic textures
    spll-hw evaluate --dataset biotac --data ../shared/datasets/biotac_slide_20_50 \\
        --encoders lif,pacinian,peak --features spectrum,sfft,isi --out reports/biotac
    spll-hw evaluate --dataset folder --data vibtac/ --fs 8000 --set lif.gain=3000
    spll-hw evaluate --dataset folder --data vibtac/ --fs 8000 --cv recordings
    spll-hw evaluate --dataset folder --data vibtac/ --fs 8000 --holdout-recordings 4-5
"""

from __future__ import annotations

import argparse

from .arguments import (
    DEFAULT_NETWORK,
    THESIS_REPEATS,
    add_backend_argument,
    add_cv_argument,
    add_dataset_arguments,
    add_encoder_settings_argument,
    add_jobs_argument,
    add_network_argument,
    add_noise_arguments,
)

#: The command's line in ``spll-hw --help``.
HELP = "texture pipeline: encoders, features, ridge classifier, report folder"
#: What ``spll-hw evaluate --help`` says first.
DESCRIPTION = (
    "Encode a tactile dataset into spikes, extract features (pressure spectrum, "
    "sFFT, ISI histogram, sPLL network), cross-validate a ridge classifier and write a report "
    "folder (summary.md, results.json, PNG plots)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_dataset_arguments(p)
    e = p.add_argument_group("encoders and features")
    e.add_argument(
        "--encoders",
        default="lif,pacinian,peak",
        help="comma list of lif, pacinian, peak",
    )
    e.add_argument(
        "--features", default="spectrum,sfft,isi", help="comma list of spectrum, sfft, isi, spll"
    )
    add_encoder_settings_argument(
        e, "encoder parameter, e.g. lif.gain=3000, pacinian.model=2, pacinian.rms_um=none, "
        "peak.cutoff=none, peak.spectrum=pressure (repeatable)",
    )  # fmt: skip
    e.add_argument(
        "--isi-spacing",
        choices=("linear", "geometric"),
        default="linear",
        help="ISI histogram bins over 1-100 ms",
    )
    add_network_argument(
        e, DEFAULT_NETWORK, layout=False, why="; {encoder} in it is replaced by each encoder's "
        "name (biotac-vary-offset-{encoder}: each encoder's own thesis network); a file's "
        "[encoder] table sets the encoder it was tuned on (--set overrides it)",
    )  # fmt: skip
    add_backend_argument(e)
    add_noise_arguments(e, phase_noise=0.0, repeats=THESIS_REPEATS)
    c = p.add_argument_group("classifier and run")
    c.add_argument("--alpha", type=float, default=1.0, help="ridge L2 penalty")
    c.add_argument("--folds", type=int, default=5, help="stratified CV folds")
    add_cv_argument(c)
    c.add_argument("--seed", type=int, default=0, help="seed for noise, subsets and folds")
    add_jobs_argument(c)
    c.add_argument("--out", help="report folder (default reports/<dataset>)")
    c.add_argument("--quiet", action="store_true", help="no progress bars")
