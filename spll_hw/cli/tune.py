"""``spll-hw tune``: Optuna study over the sPLL network for one dataset x encoder x layout.

Examples::

    spll-hw tune --dataset synthetic --encoders lif --trials 20 --out reports/tune-demo
    spll-hw tune --dataset biotac --data ../shared/datasets/biotac_slide_20_50 --recordings 1-40 \\
        --encoders lif --layouts vary-offset --trials 500 --workers 2 --out reports/tune-bt
    # another machine joins the same study:
    spll-hw tune ... --storage postgresql://user:pw@db-host/spll --study bt-lif --resume

Tuning for a chip (the best network *on that chip*)::

    # score every trial on the network as loihi2 realises it; keep recordings 33-40 out
    spll-hw tune --dataset biotac --recordings 1-40 --holdout-recordings 33-40 \
        --profiles loihi2 --compare reports/tune-exact/best.toml --out reports/tune-loihi2
    # the chip's integer arithmetic; an analog chip averaged over 3 mismatch draws
    spll-hw tune ... --profiles loihi2 --backend golden-fixed-point
    spll-hw tune ... --profiles analog --chip-draws 3
    # accuracy against energy per sample: a Pareto front, best-<k>.toml per chosen point
    spll-hw tune ... --profiles loihi2 --objectives accuracy,energy
    # tune for loihi2 stepped every 40 us (a profile file with base = "loihi2", dt = 4e-5)
    # and measure what it wins back against the reference quantized on loihi2 as published
    spll-hw tune ... --profiles loihi2-40us.toml --compare-profile loihi2

Tuning the tables of a multichannel network file (``spll-hw slide --network``)::

    # the row channels' table of the preset only (pac fixed, simulated once); tune on 1-24,
    # score the whole tuned file against the file as given on 25-32
    spll-hw tune --network biotac-multichannel-lif --groups ele1 --classes all \
        --data ../shared/datasets/biotac_slide_20_50 --recordings 1-32 \
        --holdout-recordings 25-32 --duration 2 --phase-noise 0 --trials 12 --workers 2

The best network is written as ``<out>/best.toml`` (``--network`` of every other command), with
the encoder it was tuned on as an ``[encoder]`` table (``spll-hw evaluate --network best.toml``
encodes with it); the report is ``<out>/summary.md``. ``--resume`` with the target already
reached (``--trials 0``) only rewrites the report. Ctrl-C stops a run; finished trials stay in
the storage. Bad input (an unknown profile or objective, an objective the profile cannot
compute, ``--chip-draws 0``, a holdout that leaves a class too few recordings) is refused before
the study starts, with nothing written to the storage.
"""

from __future__ import annotations

import argparse

from .arguments import (
    REPORT_CHIP_DRAWS,
    THESIS_PHASE_NOISE,
    THESIS_REPEATS,
    TUNE_CHIP_DRAWS,
    add_backend_argument,
    add_dataset_arguments,
    add_encoder_settings_argument,
    add_noise_arguments,
    add_one_value_argument,
)

#: The command's line in ``spll-hw --help``.
HELP = "Optuna study of the sPLL network (TPE, pruning, resumable, multi-worker)"
#: What ``spll-hw tune --help`` says first.
DESCRIPTION = (
    "Tune the base sPLL and the network's frequency placement for one dataset, "
    "encoder and layout (thesis 2.8-2.9, Table 5 ranges): every trial simulates every sample "
    "--repeats times with phase noise and scores the mean ridge CV accuracy. Writes best.toml, "
    "summary.md and PNG figures to --out."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_dataset_arguments(p)
    d = p.add_argument_group("encoder")
    add_one_value_argument(d, "--encoders", "lif, pacinian or peak", default="lif")
    add_encoder_settings_argument(
        d, "encoder parameter, as for evaluate (repeatable); to tune one instead, give it a "
        'range in the --space file, e.g. "pacinian.rms_um" = {low = 5, high = 80, log = true}',
    )  # fmt: skip
    n = p.add_argument_group("network and objective")
    add_one_value_argument(
        n, "--layouts", "vary-offset, time-scaled or grouped:G", default="vary-offset"
    )
    n.add_argument("--n-spll", type=int, default=50, help="sPLLs in the network")
    n.add_argument(
        "--reference-frequency",
        type=float,
        default=50.0,
        help="[Hz] where a time-scaled base sPLL runs unscaled",
    )
    n.add_argument("--space", help="TOML file whose [space] table overrides Table 5 ranges")
    n.add_argument(
        "--spread",
        metavar="SIGMA|LOW:HIGH",
        help="beyond Table 5: per-sPLL lognormal diversity of time constants and gains "
        "(calibrated offsets; Network.with_spread), fixed (0.5) or tuned in a range (0:1)",
    )
    n.add_argument(
        "--constraints",
        choices=("penalise", "enforce", "off"),
        default="penalise",
        help="thesis 2.4.2 constraints: TPE ranks infeasible trials last (penalise), prune "
        "them unsimulated (enforce), or ignore them (off)",
    )
    add_backend_argument(n)
    m = p.add_argument_group("a multichannel network file")
    m.add_argument(
        "--network",
        dest="multichannel",
        metavar="FILE|PRESET",
        help="tune the [[channel]] tables of this multichannel network (spll-hw slide's) "
        "on BioTac: every table's channels share its tuned network; objective: CV accuracy of "
        "all channels' features, one sample per recording (its first --duration s); search "
        "space: Table 5 with the table's [channel.space] on top; writes the whole file as "
        "best.toml. --layouts, --n-spll, --encoders, --set, --space and the chip options do "
        "not apply (the tables say them) (default: none, a single network tuned from --layouts "
        "and --n-spll)",
    )
    m.add_argument(
        "--groups",
        metavar="LIST",
        help="a multichannel --network: comma list of the tables to tune, each by its number "
        "(1: the file's first) or one of its channels (ele1: the preset's row channels' table); "
        "the others stay fixed and are simulated once (default: every table)",
    )
    m.add_argument(
        "--per-channel",
        action="store_true",
        help="a multichannel --network: split the --groups tables into one table per channel "
        "and tune each channel's table by a study of its own (--trials trials each, named "
        "STUDY-<channel>), one after the other, every other table as the studies before left "
        "it; best.toml holds every channel's best",
    )
    c = p.add_argument_group("tuning for a chip")
    add_one_value_argument(
        c, "--profiles", "chip profile to tune for (spll-hw chips lists them): every trial is "
        "scored on the network as the chip realises it (golden:profile=P, or --backend "
        "golden-fixed-point for its arithmetic); networks that do not fit the chip are pruned",
    )  # fmt: skip
    c.add_argument(
        "--chip-draws",
        type=int,
        metavar="K",
        help="analog profiles: score every trial on K mismatch draws (chip_seed 0..K-1) and "
        f"average (default: {TUNE_CHIP_DRAWS}, fewer than report's {REPORT_CHIP_DRAWS} as every "
        "trial pays for each draw; 1 for fixed-point profiles)",
    )
    c.add_argument(
        "--objectives",
        default="accuracy",
        help="accuracy, or accuracy with chip costs for a multi-objective study: "
        "accuracy,energy (mean energy per sample) or accuracy,cores",
    )
    c.add_argument(
        "--compare",
        metavar="PRESET|FILE",
        help="reference network (e.g. the best.toml of a study tuned on the exact model) scored "
        "on the same objectives and held-out recordings, against the study's networks",
    )
    c.add_argument(
        "--compare-profile",
        metavar="PROFILE",
        help="chip studies with --compare and --holdout-recordings: also score the reference "
        "on this chip profile (e.g. the chip as published, when --profiles is a variant of it "
        "with another time step) and measure what the chip costs it, and what the study's "
        "networks recover, against the reference quantized on it",
    )
    c.add_argument(
        "--attribute",
        action="store_true",
        help="chip studies with --compare and --holdout-recordings: also score the reference "
        "on the chip's formats (golden:profile=P) and, once per parameter the chip changes, "
        "with that parameter kept exact, paired: which format (or mismatch) costs the "
        "accuracy (one held-out scoring per parameter)",
    )
    add_noise_arguments(n, THESIS_PHASE_NOISE, THESIS_REPEATS)
    n.add_argument("--folds", type=int, default=5, help="stratified CV folds")
    n.add_argument("--alpha", type=float, default=1.0, help="ridge L2 penalty")
    n.add_argument(
        "--prune-fraction",
        type=float,
        default=0.25,
        help="fraction of every class simulated first for the pruner (1: off)",
    )
    s = p.add_argument_group("study")
    s.add_argument(
        "--trials",
        type=int,
        default=50,
        help="target of finished (complete + pruned) trials in the study",
    )
    s.add_argument("--storage", help="SQLAlchemy URL or SQLite file (default <out>/study.db)")
    s.add_argument("--study", help="study name (default <dataset>-<layout>-<encoder>)")
    s.add_argument(
        "--resume",
        action="store_true",
        help="continue an existing study (its space and objective must match)",
    )
    s.add_argument("--workers", type=int, default=1, help="processes on this machine")
    s.add_argument(
        "--threads", type=int, help="engine threads per worker (default: cores / workers)"
    )
    s.add_argument("--pruner", choices=("median", "none"), default="median",
                   help="stop trials scoring below the median part way (none: off)")  # fmt: skip
    s.add_argument(
        "--sampler",
        choices=("tpe", "nsga2"),
        default="tpe",
        help="TPE (multi-objective TPE with several objectives) or NSGA-II (its population "
        "is --startup-trials)",
    )
    s.add_argument(
        "--startup-trials",
        type=int,
        default=10,
        help="random trials before TPE; the pruner starts after half as many",
    )
    s.add_argument(
        "--enqueue",
        metavar="PRESET|FILE",
        help="try this network first: a thesis preset (biotac-vary-offset-lif, ...) "
        "or a TOML file such as a previous best.toml; tuned encoder parameters start at "
        "the file's [encoder] setting, else the encoder's (default or --set), when in range",
    )
    s.add_argument(
        "--rescore",
        type=int,
        default=0,
        metavar="K",
        help="after the study, score its K best trials again on every sample (ignoring "
        "--per-class); best.toml is then the best of them (0: off)",
    )
    s.add_argument("--seed", type=int, default=0, help="seed of noise, folds, subsets, TPE")
    s.add_argument("--out", help="report folder (default reports/tune/<study>)")
    s.add_argument("--quiet", action="store_true", help="no progress output")
