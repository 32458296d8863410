"""Report folder of a pipeline run: ``summary.md``, ``results.json`` and PNG figures.

Layout of ``out_dir``::

    summary.md                  dataset, accuracy table (mean ± 95 % CI), timings, encoders
    results.json                the same plus fold accuracies and confusion matrices
    class_spectra.png           mean spectrum of every class with its spread
    spike_rasters.png           100 ms of spikes per encoder, one sample per class
    accuracy.png                accuracies as grouped bars with their 95 % CIs
    confusion_<enc>_<feat>.png  row-normalised confusion matrix per result
"""

from __future__ import annotations

from pathlib import Path

from ..files import write_results, write_text
from ..pipeline import PipelineResult
from .markdown import _SPECTRUM_LABEL, render_summary
from .plots import plot_accuracies, plot_class_spectra, plot_confusion, plot_rasters


def write_report(result: PipelineResult, out_dir: str | Path, command: str | None = None) -> Path:
    """Write the report folder (module docstring) and return the path of ``summary.md``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    s = result.samples
    figures: dict[str, str] = {}

    plot_class_spectra(s.signals, s.fs, s.labels, s.class_names, out / "class_spectra.png")
    figures["class spectra"] = "class_spectra.png"
    if result.trains:
        plot_rasters(result.trains, s.labels, s.class_names, out / "spike_rasters.png")
        figures["spike rasters"] = "spike_rasters.png"
    intervals: dict[str, dict] = {}
    for r in result.results:
        intervals.setdefault(r.feature, {})[r.encoder or _SPECTRUM_LABEL] = r.cv.accuracy_ci()
    plot_accuracies(intervals, 1.0 / s.n_classes, out / "accuracy.png")
    figures["accuracies"] = "accuracy.png"
    for r in result.results:
        name = f"confusion_{r.encoder or 'pressure'}_{r.feature}.png"
        title = f"{r.feature} ({r.encoder or 'pressure'}): {100 * r.cv.accuracy:.1f} %"
        plot_confusion(r.cv.confusion_normalized(), s.class_names, title, out / name)
        figures[f"confusion {r.encoder or 'pressure'} {r.feature}"] = name

    payload = result.to_dict() | {"command": command, "figures": figures}
    write_results(out / "results.json", payload)
    summary = out / "summary.md"
    write_text(summary, render_summary(result, figures, command))
    return summary


__all__ = ["write_report"]
