"""The measuring step of ``spll-hw report``: :func:`score` turns a checked :class:`ReportPlan`
and its samples into one :class:`~spll_hw.report.results.ReportResults` of plain numbers:
every layout × chip profile cell and every construction against it, what each layout costs,
and how far each backend is from the golden model for its run time.
:mod:`spll_hw.report.constraints_folder` then writes the report folder from that object alone.

A :class:`ReportPlan` carries every setting of the run, checked and converted once by the
command line (:mod:`spll_hw.cli.jobs.report`), so nothing below it reads command-line arguments.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import NetworkFile
from ..encoders import Encoder, settings_table, train_duration
from ..harness.accuracy import columns, layout_accuracy
from ..harness.construction import construction_cost, priced
from ..harness.costs import layout_costs
from ..harness.workprecision import work_precision
from ..pipeline import encode_samples
from ..simulate import poisson_trains
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
        backend: the backend spec that scores the cells, as typed (``columns`` checked it).
        constructions: specs of constructions scored against the exact cells, as typed.
        work_precision: backend specs of the error-against-run-time table.
        network: the network file, read once.
        encoder: the encoder, with the file's tuned settings where they apply.
        scoring: noise, folds and draws.
        notes: what each chip profile clamps in each layout's network, one line each.
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
    notes: list[str]
    out: Path
    command: str | None = None
    input_level: float | None = None


def score(plan: ReportPlan, samples, test, say: Callable[[str], None]) -> ReportResults:
    """Everything the report shows of ``samples`` (tested on ``test`` where recordings are
    held out), measured in one pass: every layout × column cell and every construction
    against it, what each layout costs on :data:`COSTED_SAMPLES` of the samples, and the
    error-against-run-time rows of ``plan.work_precision`` on :data:`WORK_PRECISION_SAMPLES`
    Poisson trains of :data:`WORK_PRECISION_RATE`."""

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
    cells = table.scored()
    params_toml = config.to_toml() + "\n" + settings_table(plan.encoder, plan.input_level)
    # What each layout costs, on the first samples encoded as the cells encode them.
    trains, window = costed_trains(plan.encoder, samples, plan.input_level)
    scale = samples.input_scale(plan.input_level)  # (level, source)
    costs = layout_costs(config, plan.layouts, plan.columns, trains, window)
    # What each construction costs there, the way its target realises it.
    constructions = priced(
        constructions,
        lambda spec: layout_costs(config, plan.layouts, columns(plan.profiles, spec, chip=False,
                                  chip_draws=s.chip_draws), trains, window),
        costs,
    )  # fmt: skip
    for row in constructions:
        if row.against is not None:
            graph = row.cost.graph
            say(f"  {row.construction} {row.layout:12s} {row.profile:14s} {graph.neurons} "
                f"neurons at {graph.step_words()}, {row.cost.fit.cores} core(s), "
                f"{row.cost.energy.dynamic_range} per sample: {row.against.words()}")  # fmt: skip
    # Error against run time, on Poisson trains.
    say("error against run time:")
    poisson = poisson_trains(WORK_PRECISION_RATE, samples.duration, WORK_PRECISION_SAMPLES, s.seed)
    rows = work_precision(
        plan.work_precision, config.build(), poisson, samples.duration,
        on_row=lambda row: say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample"),
    )  # fmt: skip
    return ReportResults(
        plan.command, samples.name, len(samples), tuple(samples.class_names),
        None if test is None else len(test), str(plan.encoder), plan.encoder.name,
        dataclasses.asdict(plan.encoder), plan.network.source, config.n, scale, s,
        tuple(plan.columns), tuple(cells), tuple(constructions), tuple(costs),
        COSTED_SAMPLES, tuple(rows), params_toml, *sample_size(samples, test),
    )  # fmt: skip


def costed_trains(encoder: Encoder, samples, input_level: float | None) -> tuple[list, float]:
    """``(trains, window)``: the first :data:`COSTED_SAMPLES` of ``samples``, scaled and
    encoded as the accuracy cells encode them (spike times [s]), and their length [s]: what
    each layout and construction is costed on."""
    scale = samples.input_scale(input_level)
    costed = samples.normalized(*scale).subset(np.arange(min(COSTED_SAMPLES, len(samples))))
    return encode_samples(encoder, costed), train_duration(encoder, samples.duration)


def sample_size(samples, test) -> tuple[int, int | None]:
    """``(per class, held-out recordings)``: the fewest samples of one class the intervals come
    from (``test``'s where recordings are held out, else every sample of ``samples``, each
    tested once per CV repeat) and the number of test recordings (``None`` without)."""
    scored = samples if test is None else test
    counts = np.bincount(np.asarray(scored.labels), minlength=len(scored.class_names))
    held = None if test is None else int(np.unique(test.recordings).size)
    return int(counts.min()), held
