"""The layout helpers of the report figures: labels that never collide, legends beside the
data, log axes with enough ticks."""

from __future__ import annotations

import pytest

from spll_hw.report.figure_layout import label_box, legend_outside, place_labels, readable_log_axis
from spll_hw.report.plots import _pyplot

from .figure_checks import colliding_labels, labelled_ticks, shared_area


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
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    shown = ax.transData.transform(points)
    for note in notes:
        box = label_box(note, renderer)
        assert shared_area(box, frame) == pytest.approx(box.width * box.height)  # inside
        assert not any(box.contains(x, y) for x, y in shown)
    # Far labels are tied to their point by a leader line, near ones are not.
    assert any(n.arrow_patch.get_visible() for n in notes)
    plt.close(fig)


def test_labels_need_one_text_per_point():
    plt = _pyplot()
    fig, ax = plt.subplots()
    with pytest.raises(ValueError, match="3 points but 2 labels"):
        place_labels(ax, [(1, 1)] * 3, ["a", "b"])
    plt.close(fig)


@pytest.mark.parametrize("limits", [(1780.0, 2790.0), (0.9, 1.3), (1e-3, 1e3), (2.0, 30.0)])
def test_a_log_axis_gets_at_least_three_plain_tick_labels(limits):
    plt = _pyplot()
    fig, ax = plt.subplots()
    ax.set_xscale("log")
    ax.set_xlim(*limits)
    readable_log_axis(ax.xaxis)
    labels = labelled_ticks(ax.xaxis)
    assert len(labels) >= 3, labels
    assert not any("times" in t or "^" in t for t in labels)  # "2000", not "2 x 10^3"
    plt.close(fig)
