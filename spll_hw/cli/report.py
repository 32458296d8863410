"""``spll-hw report``: the main job — accuracy lost per layout × chip constraint, and how far each
backend is from the golden model for its run time, as one report folder.

:func:`run` only reads and checks: every name and file of the command line becomes one
:class:`~spll_hw.report.constraints_score.ReportPlan` (:func:`checked_plan`) before any work;
the job itself is :func:`~spll_hw.report.constraints_score.score`, which measures everything
into one plain results object, and :func:`~spll_hw.report.constraints_folder.write_report`,
which writes the folder from it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

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
    split_list,
)
from .inputs import (
    command_line,
    expand_specs,
    jobs,
    load_split,
    read_network,
    stepped_profiles,
    tuned_encoder_settings,
    tuned_input_level,
)

if TYPE_CHECKING:  # the report package imports the pipeline (scipy): not for --help
    from ..report.constraints_score import ReportPlan

#: The report's network: the base sPLL tuned for the time-scaled layout, its reference.
DEFAULT_NETWORK = "vibtac-time-scaled-lif"
#: The step ladder of every clocked chip profile (the largest lever on a chip's energy).
DEFAULT_STEPS = "10,40,160us"
#: Time steps [s] of the work-precision curves of clocked backends.
REPORT_DTS = ("1e-4", "3e-5", "1e-5")


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
    from .. import chips

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


def run(args: argparse.Namespace) -> int:
    from ..files import atomic_folder
    from ..report.constraints_folder import write_report
    from ..report.constraints_score import score

    say = (lambda *a: None) if args.quiet else print
    plan = checked_plan(args, say)
    for line in plan.notes:
        print(f"note: {line}", file=sys.stderr)
    samples, test = load_split(args)
    say(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes, encoder "
        f"{plan.encoder.name}, {len(plan.layouts)} layouts x {len(plan.profiles)} "
        "profiles")  # fmt: skip
    results = score(plan, samples, test, say)
    with atomic_folder(plan.out) as stage:  # a full disk or Ctrl-C leaves no half a folder
        answer = write_report(results, stage)
    say(answer)
    say(f"report: {plan.out / 'summary.md'}")
    return 0


def checked_plan(args: argparse.Namespace, say) -> ReportPlan:
    """The :class:`~spll_hw.report.constraints_score.ReportPlan` of ``args``, resolved before
    any work: unknown layouts, profiles, backends, constructions and a bad network file fail
    here (``ValueError``); the network file is read once, for its network and its encoder
    table, and what each chip profile clamps is noted."""
    from ..backends import parse_specs
    from ..encoders import make_encoder
    from ..harness.accuracy import columns
    from ..report.constraints_score import ReportPlan
    from ..report.results import Scoring

    profiles = stepped_profiles(split_list(args.profiles), args.steps)
    layouts = split_list(args.layouts)
    constructions = split_list(args.constructions)
    scoring = Scoring(
        phase_noise=args.phase_noise, repeats=args.repeats, seed=args.seed, folds=args.folds,
        cv_repeats=args.cv_repeats, cv=args.cv, chip_draws=args.chip_draws,
        test_recordings=args.holdout_recordings, jobs=jobs(args),
    )  # fmt: skip
    command = command_line()
    cols = columns(profiles, args.backend, chip_draws=args.chip_draws)
    for spec in constructions:
        columns(profiles, spec, chip=False, chip_draws=args.chip_draws)
    specs = expand_specs(parse_specs(args.compare_backends), [float(x) for x in REPORT_DTS])
    network = read_network(args)
    files = {args.encoder: network}
    tuned = tuned_encoder_settings(files, [args.encoder])
    level = tuned_input_level(files, [args.encoder])
    encoder = make_encoder(args.encoder, **tuned.get(args.encoder, {}))
    layouts = resolved_layouts(layouts, profiles, network.config, say)
    notes = clamp_warnings(layouts, profiles, network.config)
    return ReportPlan(layouts, profiles, cols, args.backend, constructions, specs, network,
                      encoder, scoring, notes, args.out, command,
                      level)  # fmt: skip


def resolved_layouts(layouts: list[str], profiles: list[str], config, say) -> list[str]:
    """``layouts`` with ``grouped:auto`` replaced by the largest grouped layout the first chip
    profile of ``profiles`` holds."""
    from ..harness.costs import auto_groups

    if "grouped:auto" not in layouts:
        return layouts
    chip = next((p for p in profiles if p != "none"), None)
    if chip is None:
        raise ValueError("--layouts grouped:auto needs a chip profile in --profiles")
    auto = f"grouped:{auto_groups(config, chip)}"
    say(f"grouped:auto on {chip}: {auto}")
    return [auto if layout == "grouped:auto" else layout for layout in layouts]


def clamp_warnings(layouts: list[str], profiles: list[str], config) -> list[str]:
    """One line per parameter a chip profile of ``profiles`` clamps in the network of each
    layout of ``layouts`` (built from ``config``, which checks the layout's name), summarised
    over its sPLLs (:func:`spll_hw.report.constraints.clamped_lines`); a layout a chip cannot
    hold is reported by its accuracy cell instead."""
    from .. import chips
    from ..report.constraints import clamped_lines

    lines = []
    for layout in layouts:
        network = config.with_layout(layout).build()
        for profile in profiles:
            if profile == "none":
                continue
            try:
                realisation = chips.realise(network, profile)
            except ValueError:
                continue
            lines += clamped_lines(layout, profile, realisation)
    return lines
