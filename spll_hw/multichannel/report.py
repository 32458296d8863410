"""The accuracy-over-time report: a Markdown table, one PNG (one panel per class set, the
published curves beside) and the published numbers themselves."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..files import save_figure
from ..report.figure_layout import fit_layout
from ..report.plots import _pyplot
from .anytime import AnytimePoint
from .timecourse import Point

#: Taunyazov et al., "Fast texture classification using tactile neural coding and spiking
#: neural network", IROS 2020: held-out accuracy [fraction] on the 20 BioTac_slide_20_50
#: materials from the 19 electrodes, after 1 s and 4 s of the slide, read from their figure
#: (as quoted in spll-hw issue 35; chance 5 %).
PUBLISHED = {
    "SNN": {1.0: 0.87, 4.0: 0.95},
    "LSTM": {1.0: 0.78, 4.0: 0.94},
    "SVM on spikes": {1.0: 0.87, 4.0: 0.94},
}
#: The class set the published curves are for.
PUBLISHED_CLASSES = "all 20"
PUBLISHED_SOURCE = (
    "Taunyazov et al., IROS 2020 (electrodes; 20 materials; read from their figure at 1 s and "
    "4 s, joined by a straight line)"
)


def markdown_table(points: Sequence[Point]) -> str:
    """One row per network × class set, one column per window: accuracy % [95 % CI]."""
    windows = sorted({p.window for p in points})
    lines = [
        "| network | classes | " + " | ".join(f"{w:g} s" for w in windows) + " |",
        "| --- | --- |" + " --- |" * len(windows),
    ]
    rows = dict.fromkeys((p.network, p.classes) for p in points)
    for network, classes in rows:
        cells = []
        for w in windows:
            p = next(q for q in points if (q.network, q.classes, q.window) == (network, classes, w))
            ci = p.result.accuracy_ci()
            cells.append(f"{100 * p.result.accuracy:.1f} [{100 * ci.low:.1f}, {100 * ci.high:.1f}]")
        lines.append(f"| {network} | {classes} | " + " | ".join(cells) + " |")
    for name, curve in PUBLISHED.items():
        cells = [f"{100 * curve[w]:.0f}" if w in curve else "" for w in windows]
        if any(cells):
            lines.append(f"| published {name} | {PUBLISHED_CLASSES} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def change_table(points: Sequence[Point], network: str, reference: str) -> str:
    """``network`` minus ``reference`` in accuracy points [95 % CI, paired bootstrap over test
    recordings], one row per class set, one column per window; ``""`` when either is absent."""
    by_key = {(p.network, p.classes, p.window): p for p in points}
    windows = sorted({p.window for p in points})
    class_sets = list(dict.fromkeys(p.classes for p in points))
    if not any(k[0] == reference for k in by_key) or not any(k[0] == network for k in by_key):
        return ""
    lines = [
        "| classes | " + " | ".join(f"{w:g} s" for w in windows) + " |",
        "| --- |" + " --- |" * len(windows),
    ]
    for classes in class_sets:
        cells = []
        for w in windows:
            change = by_key[network, classes, w].result.change_against(
                by_key[reference, classes, w].result
            )
            cells.append(
                f"{100 * change.mean:+.1f} [{100 * change.low:+.1f}, {100 * change.high:+.1f}]"
            )
        lines.append(f"| {classes} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot_over_time(points: Sequence[Point], path: Path) -> None:
    """Accuracy [%] against window [s] (log axis), one panel per class set, one line per network
    with its 95 % interval (bootstrap over the held-out recordings) as error bars and, over
    several windows, a band; the published curves (dashed, no interval: read off a figure) on
    their class set's panel, every window drawn a labelled tick."""
    plt = _pyplot()
    class_sets = list(dict.fromkeys(p.classes for p in points))
    networks = list(dict.fromkeys(p.network for p in points))
    fig, axes = plt.subplots(1, len(class_sets), figsize=(5.5 * len(class_sets), 4.2), sharey=True)
    axes = [axes] if len(class_sets) == 1 else list(axes)
    for ax, classes in zip(axes, class_sets, strict=True):
        windows = {p.window for p in points}
        drawn = []  # legend entries in the order drawn (matplotlib lists error bars last)
        for k, network in enumerate(networks):
            mine = sorted((p for p in points if (p.network, p.classes) == (network, classes)),
                          key=lambda p: p.window)  # fmt: skip
            if not mine:
                continue
            w = np.array([p.window for p in mine])
            acc = np.array([100 * p.result.accuracy for p in mine])
            cis = [p.result.accuracy_ci() for p in mine]
            low, high = np.array([100 * c.low for c in cis]), np.array([100 * c.high for c in cis])
            color = f"C{k}"
            drawn.append(ax.errorbar(w, acc, yerr=np.clip([acc - low, high - acc], 0, None),
                                     fmt="o-", color=color, capsize=3,
                                     label=f"{network} (bars: 95 % CI)"))  # fmt: skip
            if w.size > 1:
                ax.fill_between(w, low, high, color=color, alpha=0.15, linewidth=0)
        if classes == PUBLISHED_CLASSES:
            for k, (name, curve) in enumerate(PUBLISHED.items(), start=len(networks)):
                drawn += ax.plot(list(curve), [100 * a for a in curve.values()], "s--",
                                 color=f"C{k}", label=f"published {name} (no CI)")  # fmt: skip
                windows |= set(curve)
        chance = 100 / next(p.result.confusion.shape[0] for p in points if p.classes == classes)
        drawn.append(ax.axhline(chance, color="0.5", ls=":", label="chance"))
        ax.set_xscale("log")
        ax.minorticks_off()
        ax.set_xticks(sorted(windows))
        ax.set_xticklabels([f"{w:g}" for w in sorted(windows)])
        ax.set_ylim(0, 100)
        ax.set_xlabel("time into the slide [s]")
        ax.set_title(f"{classes} classes, held-out recordings")
        ax.legend(handles=drawn, fontsize=7, loc="lower right")
    axes[0].set_ylabel("accuracy [%]")
    fig.text(0.5, 0.005, "bars and bands: 95 % CI, bootstrap over the held-out recordings; "
             f"dashed: {PUBLISHED_SOURCE}, no interval given", ha="center", va="bottom",
             fontsize=7)  # fmt: skip
    fit_layout(fig)
    # Room below the axes for the note (its lines, after fit_layout wrapped it).
    note = fig.texts[-1].get_window_extent(fig.canvas.get_renderer())
    fig.tight_layout(rect=(0, (note.height + 4) / fig.bbox.height, 1, 1))
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def readout_table(points: Sequence[AnytimePoint]) -> str:
    """One row per threshold, one column pair per readout (float, n-bit): accuracy % [95 % CI]
    and mean time to decision [s] (with the share of runs a readout neuron fired in)."""
    readouts = list(dict.fromkeys(p.readout for p in points))
    thresholds = list(dict.fromkeys(p.threshold for p in points))
    heads = " | ".join(f"{r}: accuracy | {r}: time (fired)" for r in readouts)
    lines = [
        f"| threshold | {heads} |",
        "| --- |" + " --- | --- |" * len(readouts),
    ]
    by_key = {(p.readout, p.threshold): p for p in points}
    for t in thresholds:
        cells = []
        for r in readouts:
            p = by_key[r, t]
            ci = p.result.accuracy_ci()
            cells.append(f"{100 * p.result.accuracy:.1f} [{100 * ci.low:.1f}, {100 * ci.high:.1f}]")
            cells.append(f"{p.mean_time:.2f} s ({100 * p.fired:.0f} %)")
        name = f"{t:g}" if t != float("inf") else "none (at the end)"
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot_readout(
    readout: dict[str, Sequence[AnytimePoint]], points: Sequence[Point], network: str, path: Path
) -> None:
    """Accuracy [%] against mean time to decision [s], one panel per class set: each readout's
    thresholds (a line), ``network``'s fixed-window decisions of ``points`` and, on their class
    set, the published curves."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(readout), figsize=(5.5 * len(readout), 4.2), sharey=True)
    axes = [axes] if len(readout) == 1 else list(axes)
    for ax, (classes, anytime) in zip(axes, readout.items(), strict=True):
        for name in dict.fromkeys(p.readout for p in anytime):
            mine = [p for p in anytime if p.readout == name]
            ax.plot([p.mean_time for p in mine], [100 * p.result.accuracy for p in mine], "o-",
                    label=f"spiking readout, {name}")  # fmt: skip
        fixed = sorted((p for p in points if (p.network, p.classes) == (network, classes)),
                       key=lambda p: p.window)  # fmt: skip
        ax.plot([p.window for p in fixed], [100 * p.result.accuracy for p in fixed], "s:",
                color="0.3", label=f"{network}, one decision at T")  # fmt: skip
        if classes == PUBLISHED_CLASSES:
            for name, curve in PUBLISHED.items():
                ax.plot(list(curve), [100 * a for a in curve.values()], "^--",
                        label=f"published {name}")  # fmt: skip
        ax.set_xscale("log")
        ax.set_ylim(0, 100)
        ax.set_xlabel("mean time to decision [s]")
        ax.set_title(f"{classes} classes, held-out recordings")
        ax.legend(fontsize=7, loc="lower right")
    axes[0].set_ylabel("accuracy [%]")
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
