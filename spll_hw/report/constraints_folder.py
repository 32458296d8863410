"""The ``spll-hw report`` job after its inputs are read, in two steps: :func:`score` measures
every layout × chip profile cell, what each layout costs and how far each backend is from the
golden model, into one :class:`~spll_hw.report.results.ReportResults` of plain numbers;
:func:`write_report` writes the report folder (figures, ``params.toml``, ``results.json``,
``summary.md``) from that object alone.

A :class:`ReportPlan` carries every setting of the run, checked and converted once by the
command line (:mod:`spll_hw.cli.report`), so nothing below it reads command-line arguments.
The summary's text is :mod:`spll_hw.report.constraints`.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..config import NetworkFile
from ..encoders import Encoder
from ..files import write_results, write_text
from .constraints import summary
from .results import ReportResults, Scoring

#: Samples of the dataset whose cost on each chip is averaged.
COSTED_SAMPLES = 3
#: Poisson input [Hz] and samples of the error-against-run-time table.
WORK_PRECISION_RATE = 300.0
WORK_PRECISION_SAMPLES = 3


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


def score(plan: ReportPlan, samples, test, say: Callable[[str], None]) -> ReportResults:
    """Everything the report shows of ``samples`` (tested on ``test`` where recordings are
    held out), measured in one pass: every layout × column cell and every construction
    against it, what each layout costs on :data:`COSTED_SAMPLES` of the samples, and the
    error-against-run-time rows of ``plan.work_precision`` on :data:`WORK_PRECISION_SAMPLES`
    Poisson trains of :data:`WORK_PRECISION_RATE`."""
    import numpy as np

    from ..encoders import settings_table, train_duration
    from ..harness.accuracy import layout_accuracy
    from ..harness.construction import construction_cost
    from ..harness.costs import layout_costs
    from ..harness.workprecision import work_precision
    from ..pipeline import encode_samples
    from ..simulate import poisson_trains

    def on_cell(cell):
        result = f"{100 * cell.cv.accuracy:5.1f} %" if cell.cv else cell.report
        say(f"  {cell.layout:12s} {cell.profile:14s} {result}")

    def on_construction(row):
        change = f"{100 * row.change.mean:+5.1f} points" if row.change else "does not fit"
        say(f"  {row.construction} {row.layout:12s} {row.profile:14s} {change}")

    s, config = plan.scoring, plan.network.config
    scored = functools.partial(
        layout_accuracy, samples, plan.encoder, config, plan.layouts, plan.profiles,
        phase_noise=s.phase_noise, repeats=s.repeats, seed=s.seed, n_splits=s.folds,
        cv_repeats=s.cv_repeats, by_recording=s.cv == "recordings", test=test,
        chip_draws=s.chip_draws, jobs=s.jobs, input_level=plan.input_level,
    )  # fmt: skip
    table = scored(backend=plan.backend, on_cell=on_cell)
    if plan.constructions:
        say("constructions against exact:")
    constructions = construction_cost(
        table, plan.constructions, lambda spec: scored(backend=spec, chip=False), on_construction
    )
    scale = samples.input_scale(plan.input_level)  # (level, source)
    costed = samples.normalized(*scale).subset(np.arange(min(COSTED_SAMPLES, len(samples))))
    costs = layout_costs(config, plan.layouts, plan.columns, encode_samples(plan.encoder, costed),
                         train_duration(plan.encoder, samples.duration))  # fmt: skip
    say("error against run time:")
    rows = work_precision(
        plan.work_precision, config.build(),
        poisson_trains(WORK_PRECISION_RATE, samples.duration, WORK_PRECISION_SAMPLES, s.seed),
        samples.duration,
        on_row=lambda row: say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample"),
    )  # fmt: skip
    return ReportResults(
        plan.command, samples.name, len(samples), tuple(samples.class_names),
        None if test is None else len(test), str(plan.encoder), plan.encoder.name,
        dataclasses.asdict(plan.encoder), plan.network.source, config.n, scale, s,
        tuple(plan.columns), tuple(table.scored()), tuple(constructions), tuple(costs),
        COSTED_SAMPLES, tuple(rows),
        config.to_toml() + "\n" + settings_table(plan.encoder, plan.input_level),
    )  # fmt: skip


def write_report(results: ReportResults, out: Path) -> Path:
    """Write the report folder ``out`` (figures, ``params.toml``, ``results.json``,
    ``summary.md``) from ``results`` alone and return the path of ``summary.md``."""
    from ..harness.accuracy_plots import plot_accuracy, plot_change_heatmap, plot_confusions
    from ..harness.construction import plot_cost
    from ..harness.costs import plot_accuracy_energy
    from ..harness.workprecision import plot

    out.mkdir(parents=True, exist_ok=True)
    pictures = ["accuracy.png"]
    plot_accuracy(results.cells, out / "accuracy.png", chance=1 / len(results.class_names))
    if results.has_reference:
        plot_change_heatmap(results.cells, out / "change.png")
        pictures.append("change.png")
    confusions = plot_confusions(results.cells, results.class_names, out)
    if results.constructions:
        plot_cost(results.constructions, out / "construction.png")
    if plot_accuracy_energy(results.cells, results.costs, out / "accuracy_energy.png"):
        pictures.append("accuracy_energy.png")
    plot(results.work_precision, out / "work_precision.png")
    payload, text = results.to_dict(), summary(results, pictures, confusions)
    write_text(out / "params.toml", results.params_toml)
    write_results(out / "results.json", payload)
    write_text(out / "summary.md", text)
    return out / "summary.md"
