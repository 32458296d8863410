"""``spll-hw tune``: an Optuna study of one sPLL network (its parser and examples:
:mod:`spll_hw.cli.tune`); a multichannel ``--network`` is :mod:`.tune_multichannel`'s."""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys

from ...config import read_network_file
from ...datasets.recordings import recording_numbers, split_recordings
from ...encoders import make_encoder, train_duration
from ...pipeline import encode_samples
from ...tune import import_optuna
from ...tune.final import final_networks
from ...tune.holdout import HoldoutData, check_split
from ...tune.objective import Encoding, Objective
from ...tune.report import candidate_trials, ranked_trials, write_tune_report
from ...tune.rescore import rescore
from ...tune.space import ENCODER_SEP, SearchSpace, network_values
from ...tune.storage import open_storage, storage_failures
from ...tune.study import finished, run_study
from ..inputs import command_line, encoder_overrides, held_out_numbers, load_samples
from .tune_multichannel import run_multichannel
from .tune_settings import interrupted, objective_settings, study_settings


def spread_spec(text: str) -> float | dict[str, float]:
    """``--spread`` as a search-space entry: ``"0.5"`` (fixed) or ``"0:1"`` (a linear range)."""
    try:
        values = [float(v) for v in text.split(":")]
    except ValueError:
        values = []
    if len(values) == 1:
        return values[0]
    if len(values) == 2:
        return {"low": values[0], "high": values[1]}
    raise ValueError(f"--spread {text!r}: give a sigma (0.5) or a range LOW:HIGH (0:1)")


def enqueue_params(source: str, space, encoder) -> dict[str, float]:
    """The tuned parameters of a network to try first: a thesis preset (Tables 6-7) or a TOML
    file such as a previous study's ``best.toml``; ``ValueError`` if outside the search space.

    A tuned ``<encoder>.<param>`` dimension starts at the file's ``[encoder]`` setting when the
    file was tuned on the study's encoder, else at ``encoder``'s own value (its default or
    ``--set``), when the dimension can take it; else Optuna samples it. Fixed settings of the
    file that differ from the study's encoder are noted on stderr (the study keeps its own).
    """
    network = read_network_file(source)
    values = network_values(network.config)
    start = dataclasses.asdict(encoder)
    table = network.encoder
    if table is not None and table[0] != encoder.name:
        print(f"note: --enqueue {source} was tuned on {table[0]} spike trains", file=sys.stderr)
    elif table is not None:
        start |= table[1]
        differ = [
            f"{encoder.name}.{param}={value!r} (this study: {getattr(encoder, param)!r})"
            for param, value in table[1].items()
            if f"{encoder.name}{ENCODER_SEP}{param}" not in space.tuned
            and value != getattr(encoder, param)
        ]
        if differ:
            print(
                f"note: --enqueue {source} was tuned with " + ", ".join(differ) + "; this study "
                "keeps its own settings (--set them to match)",
                file=sys.stderr,
            )
    out = {}
    for name in space.tuned:
        dim = space.dims[name]
        if name not in values:  # an encoder dimension (another encoder's: Objective rejects it)
            owner, _, param = name.partition(ENCODER_SEP)
            own = start.get(param) if owner == encoder.name else None
            if isinstance(own, int | float) and dim.contains(own):
                out[name] = own
            continue
        if not dim.contains(values[name]):
            raise ValueError(
                f"--enqueue {source}: {name} = {values[name]} is outside the search space "
                f"{dim.describe()}"
            )
        out[name] = values[name]
    return out


def study_samples(args: argparse.Namespace, folds: int):
    """``(the study's samples, every sample of the study's recordings, held-out samples or
    None)``: the dataset ``args`` select, ``--holdout-recordings`` split off (refused when a
    class would keep fewer recordings than ``folds``), ``--per-class`` applied to the first."""
    held_numbers = held_out_numbers(args)
    everything = load_samples(argparse.Namespace(**vars(args) | {"per_class": None}))
    held = None
    tuning = everything
    if held_numbers is not None:
        flag = f"--holdout-recordings {args.holdout_recordings}"
        tuning, held = split_recordings(everything, held_numbers, flag)
        check_split(tuning, folds, flag)
    study = tuning.per_class(args.per_class, args.seed) if args.per_class else tuning
    return study, tuning, held


def holdout_data(study, tuning, held, encoder, level: float):
    """The :class:`~spll_hw.tune.holdout.HoldoutData` of a split (both sides divided by
    ``level``, the study samples' input level, as the study's own samples were)."""
    source = "the study's input level"
    return HoldoutData(
        tuning.normalized(level, source), held.normalized(level, source), encoder,
        tuple(sorted(set(recording_numbers(tuning).tolist()))),
        tuple(sorted(set(recording_numbers(held).tolist()))), len(study),
    )  # fmt: skip


def study_objective(
    samples, args: argparse.Namespace, encoder, space, settings, threads: int, level: float
):
    """Encode ``samples`` divided by ``level`` (the study's input level) and build the
    :class:`~spll_hw.tune.objective.Objective` that scores trials on them."""
    samples = samples.normalized(level, "the study's input level")
    trains = encode_samples(encoder, samples, jobs=1, progress=not args.quiet)
    encoding = None
    if space.encoders:  # trials re-encode with the first encoding's noise ids
        encoding = Encoding(encoder, samples.signals, samples.fs, samples.noise_ids)
    return Objective(
        space,
        trains,
        samples.labels,
        samples.class_names,
        train_duration(encoder, samples.duration),
        settings,
        threads=threads,
        encoding=encoding,
        input_level=level,
    )


def study_encoder(args: argparse.Namespace, space):
    """The study's encoder: ``--encoders`` with its ``--set`` settings, none of which the search
    space also tunes."""
    fixed = encoder_overrides(args.set, [args.encoder])
    both = sorted(
        f"{e}.{p}" for e, values in fixed.items() for p in values if f"{e}.{p}" in space.dims
    )
    if both:
        raise ValueError(f"{both} set with --set and tuned by the search space: keep one")
    return make_encoder(args.encoder, **fixed[args.encoder])


def run(args: argparse.Namespace) -> int:
    if args.multichannel:
        return run_multichannel(args)
    if args.groups or args.per_channel:
        flag = "--groups" if args.groups else "--per-channel"
        raise ValueError(f"{flag} tunes tables of a multichannel file: give it as --network")
    held_out_numbers(args)  # a holdout of the synthetic textures fails first
    optuna = import_optuna()
    space = SearchSpace.load(args.space) if args.space else SearchSpace.table5()
    if args.spread is not None:
        space = space.with_overrides({"spread": spread_spec(args.spread)}, source="--spread")
    scoring = objective_settings(args, space)
    settings, out = study_settings(
        args, f"{args.dataset}-{args.layout.replace(':', '')}-{args.encoder}"
    )
    name = settings.name
    url = settings.storage
    encoder = study_encoder(args, space)
    enqueue = enqueue_params(args.enqueue, space, encoder) if args.enqueue else None
    reference = read_network_file(args.compare) if args.compare else None
    if reference is not None:
        reference.config.build()  # a bad file fails before any work
    # the data's checks (a holdout that leaves too few recordings) before the storage is touched
    samples, tuning, held = study_samples(args, scoring.folds)
    # a database that fails: one line, and no new database file left empty
    with storage_failures(url):
        open_storage(url)  # unreachable storage: fail before encoding
        threads = args.threads or max(1, (os.cpu_count() or 1) // args.workers)
        # one level for the study, its re-scores and its held-out test: the median RMS of the
        # study's samples, written into best.toml as the level the encoder was tuned at
        level = samples.reference_level()
        objective = study_objective(samples, args, encoder, space, scoring, threads, level)
        optuna.logging.set_verbosity(optuna.logging.WARNING if args.quiet else optuna.logging.INFO)
        try:
            study = run_study(settings, objective, args.workers, args.resume, enqueue)
        except KeyboardInterrupt:
            return interrupted(url)
        threads = threads * args.workers  # one process now: the cores all workers had
        rescored = []
        if args.rescore:
            on_all = study_objective(tuning, args, encoder, space, scoring, threads, level)
            top = ranked_trials(study, args.constraints)[: args.rescore]
            rescored = rescore(top, on_all, progress=not args.quiet)
        objective.threads = threads
        ranked = ranked_trials(study, args.constraints)
        best = rescored[0].trial if rescored else (ranked[0] if ranked else None)
        holdout = holdout_data(samples, tuning, held, encoder, level) if held is not None else None
        final = None
        if scoring.multi_objective or reference is not None or holdout is not None:
            final = final_networks(
                study, objective, best, encoder, reference, holdout,
                candidate_trials(study, args.constraints), attribute=args.attribute,
                compare_profile=args.compare_profile,
            )  # fmt: skip
        summary = write_tune_report(
            study, objective, out, url, command_line(), rescored, encoder, final
        )
    print(f"study {name}: {finished(study)} finished trials of {args.trials}; report: {summary}")
    return 0
