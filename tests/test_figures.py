"""The layout helpers of the report figures: labels that never collide, legends beside the
data, labels and titles inside the figure, log axes with enough ticks."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.report.figure_layout import label_box, legend_outside, place_labels, readable_log_axis
from spll_hw.report.plots import _pyplot, plot_confusion

from .figure_checks import (
    capture_figures,
    clipped_texts,
    colliding_labels,
    crossing_leaders,
    key_texts,
    labelled_ticks,
    shared_area,
)


def assert_inside_and_off_the_points(fig, ax, notes, points) -> None:
    """Every label lies wholly inside the axes and covers none of the points."""
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    shown = ax.transData.transform(points)
    for note in notes:
        box = label_box(note, renderer)
        assert shared_area(box, frame) == pytest.approx(box.width * box.height)  # inside
        assert not any(box.contains(x, y) for x, y in shown)


def test_labels_of_coincident_points_never_overlap_nor_cover_a_point():
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    points = [(2780.0, 50.0)] * 14 + [(1800.0, 60.0), (1800.0, 55.0), (2790.0, 50.5)]
    ax.plot(*zip(*points, strict=True), "o", label="cells")
    ax.set_xscale("log")
    legend_outside(ax)
    notes = place_labels(ax, points, [f"grouped:{k}, loihi2 (chip)" for k in range(len(points))])
    assert len(notes) == len(points) == len(ax.texts)
    assert colliding_labels(ax) == []
    assert_inside_and_off_the_points(fig, ax, notes, points)
    # Far labels are tied to their point by a leader line, near ones are not.
    assert any(n.arrow_patch.get_visible() for n in notes)
    plt.close(fig)


def test_labels_need_one_text_per_point():
    plt = _pyplot()
    fig, ax = plt.subplots()
    with pytest.raises(ValueError, match="3 points but 2 labels"):
        place_labels(ax, [(1, 1)] * 3, ["a", "b"])
    plt.close(fig)


@pytest.mark.parametrize(
    "limits",
    [(1780.0, 2790.0), (0.9, 1.3), (1e-3, 1e3), (2.0, 30.0),
     # A narrow view straddling a decade: 1..9 per decade leaves two ticks (9 and 10; 10 and
     # 20 out of view), evenly spaced ones with a coarse step two as well (10, 12).
     (8.36, 12.54), (0.8034, 1.0643), (92535.0, 114403.0), (8.7, 12.9),
     # So narrow that six significant digits would write two ticks alike.
     (1.00001, 1.00003)],
)  # fmt: skip
def test_a_log_axis_gets_at_least_three_plain_tick_labels(limits):
    plt = _pyplot()
    fig, ax = plt.subplots()
    ax.set_xscale("log")
    ax.set_xlim(*limits)
    readable_log_axis(ax.xaxis)
    labels = labelled_ticks(ax.xaxis)
    assert len(labels) >= 3, labels
    assert len(set(labels)) == len(labels), labels  # every tick told apart
    assert not any("times" in t or "^" in t or "e+" in t for t in labels)  # "2000", not 2e+03
    plt.close(fig)


def _stacked_cells(ax):
    """Two columns of eight cells at one energy each, vertical 95 % bars: the crowded
    accuracy-energy figure of the report; and one cell alone."""
    points, texts, lines = [], [], []
    for x, chip in ((630.0, "loihi1"), (1800.0, "loihi2")):
        for y, layout in zip((64.3, 59.0, 55.0, 52.4, 52.6, 48.3, 44.4, 31.7),
                             ("time-scaled", "grouped:4", "grouped:2", "grouped:2", "time-scaled",
                              "grouped:4", "vary-offset", "vary-offset"), strict=True):  # fmt: skip
            column = chip if y in (64.3, 59.0, 55.0, 31.7) else f"{chip} (chip)"
            points.append((x, y))
            texts.append(f"{layout}, {column}")
            lines.append(((x, y - 25.0), (x, y + 28.0)))
    ax.errorbar(*zip(*points, strict=True), yerr=26.0, fmt="o", capsize=2, label="cells")
    ax.plot([1000.0], [15.0], "o", label="alone")
    return [*points, (1000.0, 15.0)], [*texts, "alone"], lines


def test_crowded_labels_keep_apart_their_leaders_uncrossed_and_the_labels_inside_the_figure():
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    points, texts, lines = _stacked_cells(ax)
    ax.set_xscale("log")
    readable_log_axis(ax.xaxis)
    ax.margins(x=0.25, y=0.08)
    # Longer than the figure is wide: legend_outside's layout must break them, not clip them.
    ax.set_xlabel("dynamic energy per sample [µJ]: events x per-event costs (static power "
                  "apart; assumed shares: see the cost table)")  # fmt: skip
    ax.set_title("Accuracy against dynamic energy per sample (each point: layout, chip column)")
    ax.set_ylabel("accuracy [%] (bars: 95 % CI)")
    legend_outside(ax)
    notes = place_labels(ax, points, texts, lines=lines)
    assert clipped_texts(fig) == []
    assert "95 % CI" in ax.get_ylabel() and "\n" in ax.get_xlabel()
    assert "static power apart" in " ".join(ax.get_xlabel().split())  # only broken at spaces
    assert colliding_labels(ax) == [] and crossing_leaders(ax) == []
    assert_inside_and_off_the_points(fig, ax, notes, points)
    # A point with room around it is labelled right beside it, without a leader line.
    assert not notes[-1].arrow_patch.get_visible()
    plt.close(fig)


def test_labels_too_many_for_the_axes_become_numbers_with_a_key_beside():
    # Six chip columns of eight cells, as the accuracy-energy figure with time steps per chip:
    # 48 long labels do not fit 8 x 4.5 inches without covering each other or crossing leaders.
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    rng = np.random.default_rng(3)
    points, texts, lines = [], [], []
    for x in (40.0, 110.0, 155.0, 440.0, 620.0, 1750.0):
        for k, y in enumerate(np.sort(rng.uniform(20, 66, 8))):
            points.append((x, float(y)))
            texts.append(f"grouped:{k}, loihi2@{int(x)}us (chip)")
            lines.append(((x, y - 25.0), (x, y + 28.0)))
    ax.errorbar(*zip(*points, strict=True), yerr=26.0, fmt="o", capsize=2, label="cells")
    ax.set_xscale("log")
    readable_log_axis(ax.xaxis)
    ax.margins(x=0.25, y=0.08)
    ax.set_xlabel("dynamic energy per sample [µJ]")
    legend_outside(ax)
    width = ax.get_window_extent(fig.canvas.get_renderer()).width
    notes = place_labels(ax, points, texts, lines=lines)
    assert [n.get_text() for n in notes] == [str(k) for k in range(1, 49)]
    assert key_texts(ax) == [f"{k}  {t}" for k, t in enumerate(texts, start=1)]
    assert colliding_labels(ax) == [] and crossing_leaders(ax) == []
    assert clipped_texts(fig) == []
    # The figure grew by the key: the axes keep (about) their width.
    assert ax.get_window_extent(fig.canvas.get_renderer()).width > 0.9 * width
    plt.close(fig)


def test_a_long_title_and_labels_are_broken_to_fit_without_a_legend():
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([1, 2], [3, 4])
    ax.set_xlabel("a label much longer than this small figure is wide, with 95 % of its words")
    ax.set_ylabel("a y label much longer than this small figure is high [%]")
    fig.suptitle("a figure title much longer than this small figure is wide, too")
    assert legend_outside(ax) is None
    assert clipped_texts(fig) == []
    assert "95 % of" in ax.get_xlabel()  # a number keeps its unit
    plt.close(fig)


def test_a_confusion_matrix_of_few_classes_keeps_its_long_title_inside(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    title = "time-scaled, fixed16@160us (chip): 68.9 %"
    names = [f"texture {k} ({f} Hz)" for k, f in ((1, 65), (2, 101), (3, 207))]
    plot_confusion(np.eye(3), names, title, tmp_path / "confusion.png")
    fig = figures["confusion.png"]
    assert clipped_texts(fig) == []
    assert " ".join(fig.axes[0].get_title().split()) == title  # broken at a space, all there
