"""Figures of a scored accuracy table (:class:`~.accuracy.ScoredCell`): what a layout loses on
a chip, with its uncertainty.

* :func:`plot_accuracy`: accuracy per layout (groups) × profile column (bars) with 95 % CI error
  bars; the reference cell's interval as a grey band.
* :func:`plot_change_heatmap`: the paired accuracy change against the reference per layout ×
  column, annotated ``-7.9 [-11.9, -3.9]``; changes whose interval contains zero (ties) are
  hatched and drawn pale.
* :func:`plot_confusions`: one row-normalised confusion matrix per scored cell.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..report.figure_layout import legend_outside
from ..report.plots import _pyplot, accuracy_bars, plot_confusion
from .accuracy import REFERENCE, ScoredCell


def _grid(cells: Sequence[ScoredCell]) -> tuple[list[str], list[str], dict]:
    """The layouts, the columns (in order of appearance) and ``{(layout, column): cell}``."""
    layouts = list(dict.fromkeys(c.layout for c in cells))
    columns = list(dict.fromkeys(c.column for c in cells))
    return layouts, columns, {(c.layout, c.column): c for c in cells}


def plot_accuracy(cells: Sequence[ScoredCell], path: Path, chance: float | None = None) -> None:
    """Grouped bars of accuracy [%] with 95 % CI error bars (module docstring); ``chance``
    [fraction] is drawn as a dotted line. Layouts that do not fit a column have no bar and an
    ``x`` at the axis."""
    plt = _pyplot()
    layouts, profiles, by_key = _grid(cells)
    width = 0.8 / len(profiles)
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(layouts) * max(1, len(profiles)) / 2), 4))
    ref = by_key[REFERENCE].accuracy if REFERENCE in by_key else None
    if ref is not None:
        ax.axhspan(100 * ref.low, 100 * ref.high, color="0.9", zorder=0,
                   label=f"95 % CI of {REFERENCE[0]}, {REFERENCE[1]}")  # fmt: skip
    for k, profile in enumerate(profiles):
        xs, intervals, missing = [], [], []
        for i, layout in enumerate(layouts):
            x = i + (k - (len(profiles) - 1) / 2) * width
            ci = by_key[layout, profile].accuracy
            if ci is None:
                missing.append(x)
            else:
                xs.append(x)
                intervals.append(ci)
        means, errors = accuracy_bars(intervals)
        ax.bar(xs, means, width, label=profile, zorder=2)
        if xs:
            ax.errorbar(xs, means, yerr=errors.tolist(), fmt="none", ecolor="k", capsize=2,
                        linewidth=0.8, zorder=3)  # fmt: skip
        ax.plot(missing, [1.0] * len(missing), "x", color="k", zorder=3)
    ax.plot([], [], "x", color="k", label="does not fit")
    if chance is not None:
        ax.axhline(100 * chance, linestyle=":", color="0.4", label="chance")
    ax.set_xticks(range(len(layouts)), layouts)
    ax.set_ylabel("accuracy [%]\n(bars: 95 % CI)")
    ax.set_title("Accuracy per layout and chip profile")
    ax.set_ylim(0, 102)  # room for the caps of intervals that reach 100 %
    legend_outside(ax)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_change_heatmap(cells: Sequence[ScoredCell], path: Path) -> None:
    """Heat map of the paired accuracy change [points] against the reference (module
    docstring); needs the reference cell among ``cells``."""
    layouts, profiles, by_key = _grid(cells)
    if REFERENCE not in by_key or by_key[REFERENCE].accuracy is None:
        raise ValueError("the table has no reference cell (time-scaled, none) to compare with")
    plt = _pyplot()
    change = np.full((len(layouts), len(profiles)), np.nan)
    text = np.full(change.shape, "does not fit", dtype=object)
    ties = np.zeros(change.shape, dtype=bool)
    for i, layout in enumerate(layouts):
        for j, profile in enumerate(profiles):
            ci = by_key[layout, profile].change
            if ci is None:
                continue
            change[i, j] = 100 * ci.mean
            text[i, j] = f"{100 * ci.mean:+.1f}\n[{100 * ci.low:+.1f}, {100 * ci.high:+.1f}]"
            ties[i, j] = not ci.distinct and (layout, profile) != REFERENCE
    text[layouts.index(REFERENCE[0]), profiles.index(REFERENCE[1])] = "reference"
    limit = max(1.0, float(np.nanmax(np.abs(change))) if np.isfinite(change).any() else 1.0)
    fig, ax = plt.subplots(figsize=(1.7 * len(profiles) + 2, 0.7 * len(layouts) + 1.5))
    image = ax.imshow(change, cmap="RdBu", vmin=-limit, vmax=limit, aspect="auto")
    for i in range(len(layouts)):
        for j in range(len(profiles)):
            if ties[i, j]:
                ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///",
                                           edgecolor="0.6", linewidth=0))  # fmt: skip
            strong = abs(change[i, j]) > 0.6 * limit
            ax.text(j, i, text[i, j], ha="center", va="center", fontsize=7,
                    color="w" if strong else "0.45" if ties[i, j] else "k")  # fmt: skip
    ax.set_xticks(range(len(profiles)), profiles, fontsize=8)
    ax.set_yticks(range(len(layouts)), layouts, fontsize=8)
    fig.colorbar(image, ax=ax, label="change against reference [points]")
    ax.set_title("Paired accuracy change, 95 % CI (hatched: a tie, CI contains 0)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_confusions(cells: Sequence[ScoredCell], class_names, out: Path) -> list[str]:
    """One row-normalised confusion matrix per scored cell, ``confusion_<layout>_<column>.png``
    in folder ``out``: their PNG names."""
    names = []
    for cell in cells:
        if cell.accuracy is None:
            continue
        label = re.sub(r"[^A-Za-z0-9_-]+", "", f"{cell.layout}_{Path(cell.column).stem}")
        name = f"confusion_{label}.png"
        plot_confusion(cell.confusion, class_names,
                       f"{cell.layout}, {cell.column}: {100 * cell.mean:.1f} %",
                       out / name)  # fmt: skip
        names.append(name)
    return names
