"""The ``spll-hw report`` job after its inputs are read: score every layout × chip profile cell,
then write the report folder (figures, ``params.toml``, ``results.json``, ``summary.md``).

A :class:`ReportPlan` carries every setting of the run, checked and converted once by the
command line (:mod:`spll_hw.cli.report`), so nothing below it reads command-line arguments.
The summary's text is :mod:`spll_hw.report.constraints`.
"""

from __future__ import annotations

import dataclasses
import functools
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..config import NetworkFile
from ..encoders import Encoder
from ..files import write_results, write_text
from .constraints import ConstraintsRun, summary

#: Samples of the dataset whose cost on each chip is averaged.
COSTED_SAMPLES = 3
#: Poisson input [Hz] and samples of the error-against-run-time table.
WORK_PRECISION_RATE = 300.0
WORK_PRECISION_SAMPLES = 3


@dataclass(frozen=True)
class Scoring:
    """How each cell is scored: noise, folds and draws (the same for every cell, so that the
    cells' changes are paired).

    Attributes:
        phase_noise: Gaussian jitter of input spikes [s] (0: none).
        repeats: noise draws per sample.
        seed: seed of noise, folds and inputs.
        folds: CV folds.
        cv_repeats: CV repeats with fresh fold shuffles.
        cv: ``"samples"`` or ``"recordings"`` (folds of whole recordings).
        chip_draws: mismatch draws pooled per cell of a profile that draws mismatch.
        test_recordings: the held-out recordings as typed (``None``: cross-validation).
        jobs: worker processes.
    """

    phase_noise: float
    repeats: int
    seed: int
    folds: int
    cv_repeats: int
    cv: str
    chip_draws: int
    test_recordings: str | None
    jobs: int


@dataclass(frozen=True)
class ReportPlan:
    """What a report run measures, every name in it checked before any work.

    Attributes:
        layouts: layouts to build from the network file's base sPLL.
        profiles: chip profiles (``"none"``: exact).
        columns: the accuracy table's columns (:class:`spll_hw.harness.accuracy.Column`).
        backend: the backend spec that scores the cells.
        constructions: specs of constructions scored against the exact cells, as typed.
        work_precision: backend specs of the error-against-run-time table.
        network: the network file, read once.
        encoder: the encoder, with the file's tuned settings where they apply.
        scoring: noise, folds and draws.
        out: the report folder.
        command: the command as typed (``None`` from Python).
        input_level: the signal level the network file's encoder was tuned at [the dataset's
            raw unit], when the run uses that encoder (``None``: the training samples' median
            RMS, :meth:`~spll_hw.datasets.SampleSet.input_scale`).
    """

    layouts: list[str]
    profiles: list[str]
    columns: list
    backend: str
    constructions: list[str]
    work_precision: list[str]
    network: NetworkFile
    encoder: Encoder
    scoring: Scoring
    out: Path
    command: str | None = None
    input_level: float | None = None


def score(plan: ReportPlan, samples, test, say: Callable[[str], None]):
    """``(the accuracy table, the constructions scored against it)`` of ``samples`` (tested on
    ``test`` where recordings are held out)."""
    from ..harness import construction
    from ..harness.accuracy import layout_accuracy

    def on_cell(cell):
        result = f"{100 * cell.cv.accuracy:5.1f} %" if cell.cv else cell.report
        say(f"  {cell.layout:12s} {cell.profile:14s} {result}")

    s = plan.scoring
    scored = functools.partial(
        layout_accuracy, samples, plan.encoder, plan.network.config, plan.layouts, plan.profiles,
        phase_noise=s.phase_noise, repeats=s.repeats, seed=s.seed, n_splits=s.folds,
        cv_repeats=s.cv_repeats, by_recording=s.cv == "recordings", test=test,
        chip_draws=s.chip_draws, jobs=s.jobs, input_level=plan.input_level,
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


def write_report(plan: ReportPlan, samples, test, table, constructions, say) -> Path:
    """Write the report folder (figures, ``params.toml``, ``results.json``, ``summary.md``) and
    return the path of ``summary.md``."""
    from ..encoders import settings_table
    from ..harness import construction
    from ..harness.costs import plot_accuracy_energy

    out = plan.out
    out.mkdir(parents=True, exist_ok=True)
    if constructions:
        construction.plot_cost(constructions, out / "construction.png")
    pictures = accuracy_figures(table, samples.n_classes, out)
    costs = chip_costs(plan, samples)
    if plot_accuracy_energy(table, costs, out / "accuracy_energy.png"):
        pictures.append("accuracy_energy.png")
    rows = work_precision_rows(plan, samples.duration, say)
    encoder_table = settings_table(plan.encoder, plan.input_level)
    write_text(out / "params.toml", plan.network.config.to_toml() + "\n" + encoder_table)
    write_results(out / "results.json", results(plan, samples, table, rows, costs, constructions))
    harness_run = ConstraintsRun(
        plan.command, setting(plan, samples, test), table, plan.columns,
        plan.scoring.chip_draws, pictures, constructions, costs, COSTED_SAMPLES, rows,
        confusion_figures(table, samples.class_names, out),
    )  # fmt: skip
    write_text(out / "summary.md", summary(harness_run))
    return out / "summary.md"


def work_precision_rows(plan: ReportPlan, duration: float, say) -> list:
    """The error-against-run-time rows of ``plan.work_precision`` on
    :data:`WORK_PRECISION_SAMPLES` Poisson trains of :data:`WORK_PRECISION_RATE`, and their
    figure ``work_precision.png``."""
    from ..harness.workprecision import plot, work_precision
    from ..simulate import poisson_trains

    say("error against run time:")
    trains = poisson_trains(
        WORK_PRECISION_RATE, duration, WORK_PRECISION_SAMPLES, plan.scoring.seed
    )
    rows = work_precision(
        plan.work_precision, plan.network.config.build(), trains, duration,
        on_row=lambda row: say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample"),
    )  # fmt: skip
    plot(rows, plan.out / "work_precision.png")
    return rows


def accuracy_figures(table, n_classes: int, out: Path) -> list[str]:
    """The accuracy bars and, with a reference cell, the change heat map: their PNG names."""
    from ..harness.accuracy_plots import plot_accuracy, plot_change_heatmap

    plot_accuracy(table, out / "accuracy.png", chance=1 / n_classes)
    if not table.has_reference:
        return ["accuracy.png"]
    plot_change_heatmap(table, out / "change.png")
    return ["accuracy.png", "change.png"]


def chip_costs(plan: ReportPlan, samples) -> list:
    """What each layout costs on :data:`COSTED_SAMPLES` of the dataset's own samples:
    NeuroBench's metrics on every column, fit, energy and latency on each chip with tables."""
    import numpy as np

    from ..encoders import train_duration
    from ..harness.costs import layout_costs
    from ..pipeline import encode_samples

    level, source = samples.input_scale(plan.input_level)
    costed = samples.normalized(level, source).subset(np.arange(min(COSTED_SAMPLES, len(samples))))
    window = train_duration(plan.encoder, samples.duration)
    trains = encode_samples(plan.encoder, costed)
    return layout_costs(plan.network.config, plan.layouts, plan.columns, trains, window)


def confusion_figures(table, class_names, out: Path) -> list[str]:
    """One row-normalised confusion matrix per scored cell: their PNG names."""
    from .plots import plot_confusion

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


def results(plan: ReportPlan, samples, table, rows, costs, constructions) -> dict:
    """The ``results.json`` payload (:func:`spll_hw.harness.accuracy.accuracy_summary` for the
    accuracies: changes are the cell minus the reference, negative = worse)."""
    from ..harness.accuracy import accuracy_summary

    s = plan.scoring
    return {
        "dataset": samples.name, "samples": len(samples), "encoder": plan.encoder.name,
        "network": plan.network.source,
        "input_level": dict(zip(("level", "source"), samples.input_scale(plan.input_level),
                                strict=True)),
        "columns": {c.label: list(c.specs) for c in plan.columns},
        "cv": {"scheme": s.cv, "n_splits": s.folds, "repeats": s.cv_repeats,
               "noise_draws": s.repeats, "chip_draws": s.chip_draws, "seed": s.seed,
               "test_recordings": s.test_recordings},
        "encoder_params": dataclasses.asdict(plan.encoder), "accuracy": accuracy_summary(table),
        "work_precision": [r.__dict__ for r in rows],
        "costs": [{"layout": c.layout, "column": c.column} | c.to_dict() for c in costs],
        "constructions": [c.to_dict() for c in constructions],
    }  # fmt: skip


def setting(plan: ReportPlan, samples, test) -> str:
    """One paragraph: dataset, encoder, network, noise and how the cells are scored."""
    s = plan.scoring
    if test is not None:
        scheme = (
            f"trained on these samples and tested once on {len(test)} samples of the held-out "
            f"recordings {s.test_recordings} (intervals: bootstrap over test recordings)"
        )
    else:
        scheme = f"{s.cv_repeats} x {s.folds}-fold CV of {s.cv}, the same folds for every cell"
    return (
        f"Dataset `{samples.name}` ({len(samples)} samples, {samples.n_classes} classes), "
        f"encoder `{plan.encoder}`, network `{plan.network.source}` "
        f"({plan.network.config.n} sPLLs), phase noise {s.phase_noise:g} s x {s.repeats} "
        f"draw(s), {scheme}."
    )
