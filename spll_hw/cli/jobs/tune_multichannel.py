"""``spll-hw tune --network FILE`` of a multichannel file: the ``[[channel]]`` tables of the
file tuned on BioTac (:mod:`spll_hw.tune.multichannel`), e.g. the electrodes' table alone::

    spll-hw tune --network biotac-multichannel-lif --groups ele1 \\
        --data ../shared/datasets/biotac_slide_20_50 --classes all --recordings 1-32 \\
        --holdout-recordings 25-32 --duration 2 --trials 12 --workers 2 --out reports/tune/mc

tunes on recordings 1-24 (one sample per recording, its first 2 s), writes the whole file with
the tuned table as ``best.toml`` and scores it and the file as given on 25-32.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ... import presets
from ...datasets import DEFAULT_SAMPLE_DURATION
from ...datasets.biotac import BIOTAC_ENV
from ...datasets.biotac_channels import CHANNELS, load_biotac_channels
from ...datasets.recordings import parse_ranges, split_recordings
from ...multichannel.config import MultichannelConfig
from ...tune import import_optuna
from ...tune.holdout import check_split
from ...tune.multichannel import (
    MultichannelObjective,
    check_exact,
    first_params,
    table_numbers,
    table_space,
)
from ...tune.multichannel_report import multichannel_final, write_multichannel_report
from ...tune.per_channel import tune_each
from ...tune.space import SearchSpace
from ...tune.storage import open_storage, storage_failures
from ...tune.study import finished, run_study
from ..arguments import split_list
from ..inputs import command_line, is_multichannel
from ..tune import add_arguments
from .tune_settings import interrupted, objective_settings, study_settings

#: Options of a single-network study a multichannel one refuses: the tables say the network
#: and encoder, every recording counts once, and it runs on the exact model.
SINGLE_NETWORK_ONLY = (
    "encoder", "set", "layout", "n_spll", "reference_frequency", "space", "spread", "profile",
    "chip_draws", "compare", "compare_profile", "attribute", "enqueue", "rescore", "per_class",
    "fs",
)  # fmt: skip


def check_options(args: argparse.Namespace) -> None:
    """``ValueError`` naming every given option a multichannel study does not take."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    defaults = vars(parser.parse_args([]))
    flags = {a.dest: a.option_strings[0] for a in parser._actions if a.option_strings}
    given = [flags[name] for name in SINGLE_NETWORK_ONLY if getattr(args, name) != defaults[name]]
    if given:
        raise ValueError(
            f"{', '.join(given)}: not with a multichannel --network (its [[channel]] tables give "
            "each table's network, encoder and search space ([channel.space]); every recording "
            "counts once; it tunes on the exact model)"
        )
    if args.dataset == "folder":
        raise ValueError("a multichannel --network tunes BioTac channels: drop --dataset folder")


def run_multichannel(args: argparse.Namespace) -> int:
    refuse_single_network(args.multichannel)
    check_options(args)
    optuna = import_optuna()
    config = MultichannelConfig.load(args.multichannel)
    config.check_channels(CHANNELS)
    every = [str(k) for k in range(1, len(config.groups) + 1)]
    tables = table_numbers(config, split_list(args.groups) if args.groups else every, "--groups")
    if args.per_channel:
        config, tables = config.split(tables)
    given = config  # the reference: its tables as the objective numbers them
    for k in tables:
        table_space(config, k)  # a bad [channel.space] fails before the data is read
    scoring = objective_settings(args, SearchSpace.table5())
    check_exact(scoring)
    root = args.data or os.environ.get(BIOTAC_ENV)
    if not root:
        raise ValueError(
            f"a multichannel --network needs --data PATH (BioTac_slide_20_50, or ${BIOTAC_ENV})"
        )
    recordings = parse_ranges(args.recordings) if args.recordings else None
    held_numbers = parse_ranges(args.holdout_recordings) if args.holdout_recordings else None
    duration = args.duration or DEFAULT_SAMPLE_DURATION
    label = "per-channel" if args.per_channel else "-".join(map(str, tables))
    settings, out = study_settings(args, f"multichannel-{Path(args.multichannel).stem}-{label}")
    loaded = load_biotac_channels(
        root, config.channels, args.classes or "thesis11", recordings, duration, not args.quiet
    ).openings()
    tuning, held = loaded, None
    if held_numbers is not None:
        flag = f"--holdout-recordings {args.holdout_recordings}"
        tuning, held = split_recordings(loaded, held_numbers, flag)
        check_split(tuning, scoring.folds, flag)
    # a database that fails: one line, and no new database file left empty
    with storage_failures(settings.storage):
        open_storage(settings.storage)  # unreachable storage: fail before encoding
        cores = os.cpu_count() or 1
        threads = args.threads or max(1, cores // args.workers)
        jobs = threads * args.workers
        first = tables[:1] if args.per_channel else tables
        objective = MultichannelObjective(
            config, first, tuning, scoring, threads, jobs, progress=not args.quiet, retunable=tables
        )
        optuna.logging.set_verbosity(optuna.logging.WARNING if args.quiet else optuna.logging.INFO)
        channels, chosen = [], None
        try:
            if args.per_channel:
                file, accuracy, study, channels = tune_each(
                    settings, objective, tables, args.workers, args.resume, not args.quiet
                )
                chosen = (file, accuracy) if accuracy is not None else None
            else:
                study = run_study(
                    settings, objective, args.workers, args.resume, first_params(objective)[0]
                )
        except KeyboardInterrupt:
            return interrupted(settings.storage)
        objective.threads = jobs  # one process now: the cores all workers had
        final = multichannel_final(
            study, objective, tuning, held, scoring.backend, jobs, not args.quiet, given, chosen
        )
        summary = write_multichannel_report(
            study, objective, out, settings.storage, command_line(), final, channels
        )
    print(
        f"study {settings.name}: {finished(study)} finished trials of {args.trials}; "
        f"report: {summary}"
    )
    return 0


def refuse_single_network(source: str) -> None:
    """``ValueError`` when ``--network`` names one sPLL network (a preset or a file without
    ``[[channel]]`` tables): tune tunes a single network from ``--layouts`` and ``--n-spll``."""
    if not is_multichannel(source) and (Path(source).is_file() or source in presets.names()):
        raise ValueError(
            f"--network {source}: one sPLL network; tune's --network is a multichannel file "
            "([[channel]] tables). A single network is tuned from --layouts and --n-spll; "
            "--enqueue FILE tries this one first"
        )
