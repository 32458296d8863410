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

from ... import chips
from ...backends import parse_specs
from ...encoders import make_encoder
from ...files import atomic_folder
from ...harness.accuracy import columns
from ...harness.costs import auto_groups
from ...report.constraints import clamped_lines
from ...report.constraints_folder import write_report
from ...report.constraints_score import ReportPlan, score
from ...report.results import Scoring
from ..arguments import split_list
from ..inputs import (
    command_line,
    expand_specs,
    jobs,
    load_split,
    read_network,
    stepped_profiles,
    tuned_encoder_settings,
    tuned_input_level,
)

#: Time steps [s] of the work-precision curves of clocked backends.
REPORT_DTS = ("1e-4", "3e-5", "1e-5")


def run(args: argparse.Namespace) -> int:
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
