"""PNG figures of a pipeline run: class spectra, spike rasters, confusion matrices, accuracies."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

from ..features.spectrum import magnitude_spectrum
from ..files import save_figure
from ..stats import Interval
from .figure_layout import fit_layout, legend_outside

#: Window of the spike raster plots [s] (thesis Figure 5 shows 100 ms).
RASTER_WINDOW = (0.5, 0.6)
_MAX_RASTER_CLASSES = 6


def _pyplot():
    """matplotlib's pyplot on the headless backend, chosen before pyplot loads (imported here,
    so that importing spll-hw changes no backend of a session that draws on its own)."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_per_class(class_names, draw, xlabel: str, title: str, path: Path) -> None:
    """One panel per class, stacked on a shared x axis and labelled with the class's name:
    ``draw(ax, c)`` draws class ``c`` into its panel (the thesis's per-class figures)."""
    plt = _pyplot()
    k = len(class_names)
    fig, axes = plt.subplots(k, 1, figsize=(7, 0.9 * k + 1), sharex=True, squeeze=False)
    for c, ax in enumerate(axes[:, 0]):
        draw(ax, c)
        ax.set_ylabel(class_names[c], rotation=0, ha="right", va="center", fontsize=8)
        ax.tick_params(axis="y", labelsize=6)
    axes[-1, 0].set_xlabel(xlabel)
    fig.suptitle(title)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_class_spectra(
    signals: np.ndarray, fs: float, labels: np.ndarray, class_names, path: Path
) -> None:
    """Mean |FFT| of each class (line) and its 10-90 % percentile band over samples (grey).

    One panel per class (log scale), up to 1 kHz (or Nyquist), like the thesis's Figure 3.
    """
    f_max = min(1000.0, fs / 2)
    spectra = magnitude_spectrum(signals, fs, f_max)[:, 1:]  # drop DC (0 after mean removal)
    freqs = np.arange(1, spectra.shape[1] + 1) * fs / signals.shape[1]

    def draw(ax, c: int) -> None:
        s = spectra[labels == c]
        lo, hi = np.percentile(s, [10, 90], axis=0)
        ax.fill_between(freqs, lo, hi, color="0.85", linewidth=0)
        ax.plot(freqs, s.mean(axis=0), linewidth=0.7)
        ax.set_yscale("log")

    title = "Class spectra: mean |FFT| and 10-90 % band over samples"
    plot_per_class(class_names, draw, "frequency [Hz]", title, path)


def plot_rasters(
    trains: dict[str, list[np.ndarray]], labels: np.ndarray, class_names, path: Path
) -> None:
    """Spikes of the first sample of up to six classes in a 100 ms window, one panel per encoder."""
    plt = _pyplot()
    classes = list(range(min(len(class_names), _MAX_RASTER_CLASSES)))
    rows = [int(np.flatnonzero(labels == c)[0]) for c in classes]
    fig, axes = plt.subplots(len(trains), 1, figsize=(7, 1.6 * len(trains) + 0.6), squeeze=False)
    lo, hi = RASTER_WINDOW
    for ax, (name, enc_trains) in zip(axes[:, 0], trains.items(), strict=True):
        events = [enc_trains[r][(enc_trains[r] >= lo) & (enc_trains[r] < hi)] * 1e3 for r in rows]
        ax.eventplot(events, linelengths=0.8, linewidths=0.8)
        ax.set_yticks(range(len(rows)), [class_names[c] for c in classes], fontsize=7)
        ax.set_xlim(lo * 1e3, hi * 1e3)
        ax.set_title(name, fontsize=9)
    axes[-1, 0].set_xlabel("time [ms]")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_confusion(matrix: np.ndarray, class_names, title: str, path: Path) -> None:
    """Row-normalised confusion matrix (rows: true class) with the fractions printed."""
    plt = _pyplot()
    k = len(class_names)
    size = 2.5 + 0.45 * k
    fig, ax = plt.subplots(figsize=(size, size))
    ax.imshow(matrix, cmap="Blues", vmin=0, vmax=1)
    ax.set_xticks(range(k), class_names, rotation=60, ha="right", fontsize=7)
    ax.set_yticks(range(k), class_names, fontsize=7)
    ax.set_xlabel("prediction")
    ax.set_ylabel("ground truth")
    for i in range(k):
        for j in range(k):
            if matrix[i, j] >= 0.005:
                color = "white" if matrix[i, j] > 0.6 else "black"
                ax.text(
                    j,
                    i,
                    f"{matrix[i, j]:.2f}".lstrip("0"),
                    ha="center",
                    va="center",
                    fontsize=6,
                    color=color,
                )
    ax.set_title(title, fontsize=9)
    fit_layout(fig)  # a long title (layout, chip column @ time step) broken, not clipped
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def accuracy_bars(intervals) -> tuple[np.ndarray, np.ndarray]:
    """Bar heights and error bars [%] of accuracy intervals (fractions, objects with ``mean``,
    ``low``, ``high`` such as :class:`~spll_hw.stats.Interval`): ``(means (n,), yerr (2, n))``,
    the intervals clipped to the possible 0-100 % (a t interval can reach past them)."""
    mean = np.array([100 * i.mean for i in intervals], dtype=float).reshape(-1)
    low = np.clip([100 * i.low for i in intervals], 0, 100).reshape(-1)
    high = np.clip([100 * i.high for i in intervals], 0, 100).reshape(-1)
    return mean, np.vstack([np.clip(mean - low, 0, None), np.clip(high - mean, 0, None)])


def plot_accuracies(table: dict[str, dict[str, Interval]], chance: float, path: Path) -> None:
    """Grouped bars: ``table[feature][encoder]`` is the accuracy's 95 % interval (fractions,
    :class:`~spll_hw.stats.Interval`), drawn as the bar (mean) and its error bar (clipped to
    0-100 %); chance level dashed, the legend beside the axes."""
    plt = _pyplot()
    features = list(table)
    encoders = list(dict.fromkeys(e for row in table.values() for e in row))
    colors = {e: f"C{i}" for i, e in enumerate(encoders)}
    width = 0.8 / max(len(row) for row in table.values())
    fig, ax = plt.subplots(figsize=(1.6 * len(features) + 3, 3.2))
    for i, feature in enumerate(features):
        row = table[feature]
        means, errors = accuracy_bars(row.values())
        for j, enc in enumerate(row):
            x = i + (j - (len(row) - 1) / 2) * width
            label = enc if enc not in ax.get_legend_handles_labels()[1] else None
            ax.bar(x, means[j], width, yerr=errors[:, j : j + 1].tolist(), color=colors[enc],
                   label=label, capsize=2)  # fmt: skip
    ax.axhline(100 * chance, color="0.5", linestyle="--", linewidth=0.8, label="chance")
    ax.set_xticks(range(len(features)), features)
    ax.set_ylabel("accuracy [%]\n(bars: 95 % CI)")
    ax.set_ylim(0, 102)  # room for the caps of intervals that reach 100 %
    legend_outside(ax)
    save_figure(fig, path, dpi=110)
    plt.close(fig)
