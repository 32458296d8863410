"""``spll-hw report``: the main job — accuracy lost per layout × chip constraint, and how far each
backend is from the golden model for its run time, as one report folder.

:func:`run` only orchestrates: check everything (:func:`checked_plan`), say what each chip
clamps, score the cells (:func:`score`), write the folder (:func:`write_report`); the summary's
text is :mod:`spll_hw.report.constraints`.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from ..config import NetworkFile
from ..encoders import Encoder
from ..files import write_results, write_text
from ..harness.costs import plot_accuracy_energy
from ..report.constraints import ConstraintsRun, clamped_lines, headline, summary
from .arguments import (
    REPORT_CHIP_DRAWS,
    THESIS_PHASE_NOISE,
    TUNE_CHIP_DRAWS,
    add_backend_argument,
    add_dataset_arguments,
    add_jobs_argument,
    add_network_argument,
    add_noise_arguments,
    checked_backend,
    command_line,
    jobs,
    split_list,
)
from .inputs import expand_specs, load_split, poisson_trains, read_network, tuned_encoder_settings

#: The report's network: the base sPLL tuned for the time-scaled layout, its reference.
DEFAULT_NETWORK = "vibtac-time-scaled-lif"
#: Samples of the dataset whose cost on each chip is averaged.
COSTED_SAMPLES = 3
#: Time steps [s] of the work-precision curves of clocked backends.
REPORT_DTS = ("1e-4", "3e-5", "1e-5")
#: Poisson input [Hz] and samples of the error-against-run-time table.
WORK_PRECISION_RATE = 300.0
WORK_PRECISION_SAMPLES = 3


def register(sub: argparse._SubParsersAction) -> None:
    from .. import chips

    p = sub.add_parser(
        "report",
        help="accuracy loss per layout x constraint profile and error vs run time per backend",
        description="Encode a dataset once, then classify it with the sPLL network built in "
        "every layout (time-scaled, vary-offset, grouped G) under every chip constraint profile, "
        "and report the accuracy change against the unconstrained time-scaled network, plus an "
        "error-against-run-time table of the backends. Runs on the embedded synthetic data "
        "without arguments.",
    )
    add_dataset_arguments(p)
    add_network_argument(
        p, DEFAULT_NETWORK, why="; the default is tuned for the time-scaled layout, the "
        "report's reference; every layout of --layouts is built from the file's base sPLL",
    )  # fmt: skip
    h = p.add_argument_group("harness")
    h.add_argument(
        "--encoder",
        default="lif",
        help="lif, pacinian or peak, with the settings of the --network file's [encoder] table "
        "when it was tuned on this encoder",
    )
    h.add_argument("--layouts", default="time-scaled,vary-offset,grouped:2,grouped:4,grouped:8",
                   help="comma-separated layouts (grouped:auto: the most groups the first chip "
                   "profile holds)")  # fmt: skip
    h.add_argument(
        "--profiles",
        "--profile",
        default="none,loihi2,analog",
        help="comma-separated chip profiles (names or TOML paths; none = exact): "
        f"{', '.join(chips.names())}",
    )
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
    h.add_argument(
        "--cv",
        choices=("samples", "recordings"),
        default="samples",
        help="folds of samples or of whole recordings (no recording in both the training and "
        "the test fold)",
    )
    h.add_argument(
        "--constructions", metavar="SPECS",
        help="backends that approximate the exact sPLL on purpose, comma-separated (e.g. "
        "standard-exact:levels=4,standard-exact:levels=8: the standard-neuron gate with K "
        "levels): each scores every layout x profile again, paired with the exact cell",
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
    p.set_defaults(func=run)


@dataclass(frozen=True)
class Plan:
    """What a report run measures, every name in it checked before any work."""

    layouts: list[str]
    profiles: list[str]
    columns: list  # spll_hw.harness.accuracy.Column
    backend: str
    constructions: list[str]  # labelled as typed (a canonical spec drops default options)
    work_precision: list[str]  # backend specs of the error-against-run-time table
    network: NetworkFile
    encoder: Encoder


def run(args: argparse.Namespace) -> int:
    say = (lambda *a: None) if args.quiet else print
    plan = checked_plan(args, say)
    for line in clamp_warnings(plan):
        print(f"note: {line}", file=sys.stderr)
    samples, test = load_split(args)
    say(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes, encoder "
        f"{plan.encoder.name}, {len(plan.layouts)} layouts x {len(plan.profiles)} "
        "profiles")  # fmt: skip
    table, constructions = score(args, plan, samples, test, say)
    summary = write_report(args, plan, samples, test, table, constructions, say)
    say(headline(table))
    say(f"report: {summary}")
    return 0


def checked_plan(args: argparse.Namespace, say) -> Plan:
    """The :class:`Plan` of ``args``: unknown layouts, profiles, backends, constructions and a
    bad network file fail here (``ValueError``), before any work; the network file is read
    once, for its network and its encoder table."""
    from ..backends import parse_specs
    from ..encoders import make_encoder
    from ..harness.accuracy import columns

    profiles = split_list(args.profiles)
    specs = expand_specs(parse_specs(args.compare_backends), [float(x) for x in REPORT_DTS])
    backend = checked_backend(args.backend)
    constructions = split_list(args.constructions)
    cols = columns(profiles, backend, chip_draws=args.chip_draws)
    for spec in constructions:
        columns(profiles, spec, chip=False, chip_draws=args.chip_draws)
    network = read_network(args)
    layouts = resolved_layouts(split_list(args.layouts), profiles, network.config, say)
    for layout in layouts:
        network.config.with_layout(layout)
    tuned = tuned_encoder_settings({args.encoder: network}, [args.encoder])
    encoder = make_encoder(args.encoder, **tuned.get(args.encoder, {}))
    return Plan(layouts, profiles, cols, backend, constructions, specs, network, encoder)


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


def clamp_warnings(plan: Plan) -> list[str]:
    """One line per parameter a chip profile clamps in a layout's network, summarised over its
    sPLLs (:func:`spll_hw.report.constraints.clamped_lines`); a layout a chip cannot hold is
    reported by its accuracy cell instead."""
    from .. import chips

    lines = []
    for layout in plan.layouts:
        network = plan.network.config.with_layout(layout).build()
        for profile in plan.profiles:
            if profile == "none":
                continue
            try:
                realisation = chips.realise(network, profile)
            except ValueError:
                continue
            lines += clamped_lines(layout, profile, realisation)
    return lines


def score(args: argparse.Namespace, plan: Plan, samples, test, say):
    """``(the accuracy table, the constructions scored against it)``."""
    from ..harness import construction
    from ..harness.accuracy import layout_accuracy

    def on_cell(cell):
        result = f"{100 * cell.cv.accuracy:5.1f} %" if cell.cv else cell.report
        say(f"  {cell.layout:12s} {cell.profile:14s} {result}")

    scored = functools.partial(
        layout_accuracy, samples, plan.encoder, plan.network.config, plan.layouts, plan.profiles,
        phase_noise=args.phase_noise, repeats=args.repeats, seed=args.seed, n_splits=args.folds,
        cv_repeats=args.cv_repeats, by_recording=args.cv == "recordings", test=test,
        chip_draws=args.chip_draws, jobs=jobs(args),
    )  # fmt: skip
    table = scored(backend=plan.backend, on_cell=on_cell)
    if not plan.constructions:
        return table, []
    say("constructions against exact:")

    def on_construction(row):
        change = f"{100 * row.change.mean:+5.1f} points" if row.change else "does not fit"
        say(f"  {row.construction} {row.cell.layout:12s} {row.cell.profile:14s} {change}")

    return table, construction.construction_cost(
        table, plan.constructions, lambda spec: scored(backend=spec, chip=False), on_construction
    )


def write_report(args, plan: Plan, samples, test, table, constructions, say) -> Path:
    """Write the report folder (figures, ``params.toml``, ``results.json``, ``summary.md``) and
    return the path of ``summary.md``."""
    from ..encoders import settings_table
    from ..harness import construction
    from ..harness.workprecision import plot, work_precision

    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    if constructions:
        construction.plot_cost(constructions, out / "construction.png")
    pictures = accuracy_figures(table, samples.n_classes, out)
    costs = chip_costs(plan, samples)
    if plot_accuracy_energy(table, costs, out / "accuracy_energy.png"):
        pictures.append("accuracy_energy.png")
    say("error against run time:")
    trains = poisson_trains(
        WORK_PRECISION_RATE, samples.duration, WORK_PRECISION_SAMPLES, args.seed
    )
    rows = work_precision(
        plan.work_precision, plan.network.config.build(), trains, samples.duration,
        on_row=lambda row: say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample"),
    )  # fmt: skip
    plot(rows, out / "work_precision.png")
    write_text(
        out / "params.toml", plan.network.config.to_toml() + "\n" + settings_table(plan.encoder)
    )
    write_results(
        out / "results.json", results(args, plan, samples, table, rows, costs, constructions)
    )
    harness_run = ConstraintsRun(
        command_line(), setting(args, plan, samples, test), table, plan.columns,
        args.chip_draws, pictures, constructions, costs, COSTED_SAMPLES, rows,
        confusion_figures(table, samples.class_names, out),
    )  # fmt: skip
    write_text(out / "summary.md", summary(harness_run))
    return out / "summary.md"


def accuracy_figures(table, n_classes: int, out: Path) -> list[str]:
    """The accuracy bars and, with a reference cell, the change heat map: their PNG names."""
    from ..harness.accuracy_plots import plot_accuracy, plot_change_heatmap

    plot_accuracy(table, out / "accuracy.png", chance=1 / n_classes)
    if not table.has_reference:
        return ["accuracy.png"]
    plot_change_heatmap(table, out / "change.png")
    return ["accuracy.png", "change.png"]


def chip_costs(plan: Plan, samples) -> list:
    """What each layout costs on each chip with tables, on :data:`COSTED_SAMPLES` of the
    dataset's own samples."""
    import numpy as np

    from ..encoders import train_duration
    from ..harness.costs import layout_costs
    from ..pipeline import encode_samples

    costed = samples.normalized().subset(np.arange(min(COSTED_SAMPLES, len(samples))))
    window = train_duration(plan.encoder, samples.duration)
    trains = encode_samples(plan.encoder, costed)
    return layout_costs(plan.network.config, plan.layouts, plan.columns, trains, window)


def confusion_figures(table, class_names, out: Path) -> list[str]:
    """One row-normalised confusion matrix per scored cell: their PNG names."""
    from ..report.plots import plot_confusion

    names = []
    for cell in table.cells:
        if cell.cv is None:
            continue
        label = re.sub(r"[^A-Za-z0-9_-]+", "", f"{cell.layout}_{Path(cell.profile).stem}")
        name = f"confusion_{label}.png"
        plot_confusion(cell.cv.confusion_normalized(), class_names,
                       f"{cell.layout}, {cell.profile}: {100 * cell.cv.accuracy:.1f} %",
                       out / name)  # fmt: skip
        names.append(name)
    return names


def results(args, plan: Plan, samples, table, rows, costs, constructions) -> dict:
    """The ``results.json`` payload (:func:`spll_hw.harness.accuracy.accuracy_summary` for the
    accuracies: changes are the cell minus the reference, negative = worse)."""
    from ..harness.accuracy import accuracy_summary

    return {
        "dataset": samples.name, "samples": len(samples), "encoder": plan.encoder.name,
        "network": plan.network.source,
        "columns": {c.label: list(c.specs) for c in plan.columns},
        "cv": {"scheme": args.cv, "n_splits": args.folds, "repeats": args.cv_repeats,
               "noise_draws": args.repeats, "chip_draws": args.chip_draws, "seed": args.seed,
               "test_recordings": args.holdout_recordings},
        "encoder_params": dataclasses.asdict(plan.encoder), "accuracy": accuracy_summary(table),
        "work_precision": [r.__dict__ for r in rows],
        "costs": [{"layout": c.layout, "column": c.column} | c.to_dict() for c in costs],
        "constructions": [c.to_dict() for c in constructions],
    }  # fmt: skip


def setting(args, plan: Plan, samples, test) -> str:
    """One paragraph: dataset, encoder, network, noise and how the cells are scored."""
    if test is not None:
        scheme = (
            f"trained on these samples and tested once on {len(test)} samples of the held-out "
            f"recordings {args.holdout_recordings} (intervals: bootstrap over test recordings)"
        )
    else:
        scheme = (
            f"{args.cv_repeats} x {args.folds}-fold CV of {args.cv}, the same folds for every cell"
        )
    return (
        f"Dataset `{samples.name}` ({len(samples)} samples, {samples.n_classes} classes), "
        f"encoder `{plan.encoder}`, network `{plan.network.source}` "
        f"({plan.network.config.n} sPLLs), phase noise {args.phase_noise:g} s x {args.repeats} "
        f"draw(s), {scheme}."
    )
