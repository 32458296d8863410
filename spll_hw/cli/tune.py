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
import dataclasses
import os
import sys
from pathlib import Path

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
from .inputs import checked_backend, command_line, encoder_overrides, held_out_numbers, load_samples

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
    from ..config import read_network_file
    from ..tune.space import ENCODER_SEP, network_values

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
    from ..datasets.recordings import split_recordings
    from ..tune.holdout import check_split

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
    from ..datasets.recordings import recording_numbers
    from ..tune.holdout import HoldoutData

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
    from ..encoders import train_duration
    from ..pipeline import encode_samples
    from ..tune.objective import Encoding, Objective

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


def chip_settings(args: argparse.Namespace) -> tuple[str, int]:
    """``(backend spec, chip draws)`` of ``--backend``, ``--profiles`` and ``--chip-draws``,
    checked (``ValueError`` before any work)."""
    from ..tune.chip import backend_profile, has_mismatch, study_backend

    backend = study_backend(checked_backend(args.backend), args.profile)
    profile = backend_profile(backend)
    draws = args.chip_draws
    if draws is None:
        draws = TUNE_CHIP_DRAWS if has_mismatch(profile) else 1
    elif profile is None:
        raise ValueError("--chip-draws needs a chip profile to draw: give --profiles (analog)")
    return backend, draws


def objective_settings(args: argparse.Namespace, space):
    """The :class:`~spll_hw.tune.objective.ObjectiveSettings` of ``args``, checked with the
    flags that depend on them (``ValueError`` before any work)."""
    from ..tune.chip import baseline_specs, check_spread
    from ..tune.objective import ObjectiveSettings

    backend, chip_draws = chip_settings(args)
    settings = ObjectiveSettings(
        layout=args.layout, n_spll=args.n_spll, reference_frequency=args.reference_frequency,
        repeats=args.repeats, phase_noise=args.phase_noise, folds=args.folds, alpha=args.alpha,
        seed=args.seed, prune_fraction=args.prune_fraction, constraints=args.constraints,
        backend=backend, chip_draws=chip_draws, objectives=args.objectives,
    )  # fmt: skip
    check_spread(space, settings)
    held_out_reference = args.compare and args.holdout_recordings and settings.profile
    for flag, given, does in (
        ("--attribute", args.attribute, "on the chip with one parameter kept exact at a time"),
        ("--compare-profile", args.compare_profile is not None, "on another chip profile"),
    ):
        if given and not held_out_reference:
            raise ValueError(
                f"{flag} scores the reference (--compare) {does} at the end: it needs --profiles "
                "(or a backend naming one), --compare and --holdout-recordings"
            )
    if args.compare_profile is not None:
        baseline_specs(settings.specs, args.compare_profile)  # fails before work
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    if args.rescore < 0 or (args.rescore and not args.per_class):
        raise ValueError(
            f"--rescore {args.rescore}: give K >= 1 trials to re-score on every sample of a study "
            "tuned on --per-class samples (0: off)"
        )
    if args.rescore and settings.multi_objective:
        raise ValueError("--rescore ranks by one objective; a multi-objective study has a front")
    return settings


def study_encoder(args: argparse.Namespace, space):
    """The study's encoder: ``--encoders`` with its ``--set`` settings, none of which the search
    space also tunes."""
    from ..encoders import make_encoder

    fixed = encoder_overrides(args.set, [args.encoder])
    both = sorted(
        f"{e}.{p}" for e, values in fixed.items() for p in values if f"{e}.{p}" in space.dims
    )
    if both:
        raise ValueError(f"{both} set with --set and tuned by the search space: keep one")
    return make_encoder(args.encoder, **fixed[args.encoder])


def study_settings(args: argparse.Namespace, name: str):
    """``(StudySettings, report folder)`` of the study options, ``name`` the default study
    name (``--study`` replaces it)."""
    from ..tune.storage import storage_url
    from ..tune.study import StudySettings

    name = args.study or name
    out = args.out or os.path.join("reports", "tune", name)
    url = storage_url(args.storage, out)
    settings = StudySettings(
        url, name, args.trials, args.seed, args.pruner, args.startup_trials, args.sampler
    )
    return settings, out


def interrupted(url: str) -> int:
    """Say where a stopped study's trials are and how to continue; the exit status (130)."""
    from ..tune.storage import mask_url

    print(
        f"interrupted: finished trials are stored in {mask_url(url)}; continue with the "
        "same command and --resume (--trials 0 --resume only writes the report)",
        file=sys.stderr,
    )
    return 130


def refuse_single_network(source: str) -> None:
    """``ValueError`` when ``--network`` names one sPLL network (a preset or a file without
    ``[[channel]]`` tables): tune tunes a single network from ``--layouts`` and ``--n-spll``."""
    from .. import presets
    from .inputs import is_multichannel

    if not is_multichannel(source) and (Path(source).is_file() or source in presets.names()):
        raise ValueError(
            f"--network {source}: one sPLL network; tune's --network is a multichannel file "
            "([[channel]] tables). A single network is tuned from --layouts and --n-spll; "
            "--enqueue FILE tries this one first"
        )


def run(args: argparse.Namespace) -> int:
    from ..config import read_network_file
    from ..tune import import_optuna
    from ..tune.final import final_networks
    from ..tune.report import candidate_trials, ranked_trials, write_tune_report
    from ..tune.rescore import rescore
    from ..tune.space import SearchSpace
    from ..tune.storage import open_storage, storage_failures
    from ..tune.study import finished, run_study

    if args.multichannel:
        from .tune_multichannel import run_multichannel

        refuse_single_network(args.multichannel)
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
