"""The writing step of ``spll-hw report``: the report folder (figures, ``params.toml``,
``results.json``, ``summary.md``) written from one
:class:`~spll_hw.report.results.ReportResults` (:mod:`spll_hw.report.constraints_score`
measures it), and nothing else: no classifier results, chip profiles or backends are
consulted here. The summary's text is :mod:`spll_hw.report.constraints`.
"""

from __future__ import annotations

from pathlib import Path

from ..files import write_results, write_text
from ..harness.accuracy_plots import plot_accuracy, plot_change_heatmap, plot_confusions
from ..harness.breakdown import plot_breakdown
from ..harness.construction import plot_cost
from ..harness.costs import plot_accuracy_energy
from ..harness.workprecision import plot as plot_work_precision
from .constraints import headline, summary
from .results import ReportResults


def write_report(results: ReportResults, out: Path) -> str:
    """Write the report folder ``out`` (figures, ``params.toml``, ``results.json``,
    ``summary.md``) from ``results`` alone and return the report's answer in one line (the
    summary's headline, :func:`~spll_hw.report.constraints.headline`)."""
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
    plot_breakdown(results.costs, out / "energy_breakdown.png")  # shown with the cost tables
    plot_work_precision(results.work_precision, out / "work_precision.png")
    payload = results.to_dict()
    answer = headline(results.cells, results.costs, results.sample_note())
    text = summary(results, pictures, confusions)
    write_text(out / "params.toml", results.params_toml)
    write_results(out / "results.json", payload)
    write_text(out / "summary.md", text)
    return answer
