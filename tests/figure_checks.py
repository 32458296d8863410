"""What a reader of a saved figure would notice: labels on top of each other, a legend over the
data, a log axis with too few ticks. :func:`capture_figures` keeps every figure the code saves,
so a test can inspect the very figure a command wrote."""

from __future__ import annotations

import itertools
import re
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.text import Annotation, Text

_TEMPORARY = re.compile(r"^\.(?P<stem>.+)\.\d+\.tmp(?P<suffix>\.\w+)$")


def capture_figures(monkeypatch) -> dict[str, Figure]:
    """From now on, every figure saved is also kept here under its file name (``accuracy.png``;
    the temporary name of an atomic write is mapped back to the final one)."""
    saved: dict[str, Figure] = {}
    savefig = Figure.savefig

    def keep(fig, fname, *args, **kwargs):
        name = Path(str(fname)).name
        match = _TEMPORARY.match(name)
        saved[f"{match['stem']}{match['suffix']}" if match else name] = fig
        return savefig(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    return saved


def _renderer(fig):
    """The figure's Agg renderer, after a layout pass (a closed figure gets a canvas again)."""
    if not hasattr(fig.canvas, "get_renderer"):
        FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    return fig.canvas.get_renderer()


def label_boxes(ax) -> list:
    """Display boxes [pixels] of the text of every annotation of ``ax`` (leader lines left out)."""
    renderer = _renderer(ax.figure)
    notes = [t for t in ax.texts if isinstance(t, Annotation)]
    return [Text.get_window_extent(n, renderer) for n in notes]


def shared_area(a, b) -> float:
    """Area [pixels²] two boxes have in common."""
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return max(w, 0.0) * max(h, 0.0)


def colliding_labels(ax) -> list[tuple[int, int]]:
    """Pairs of annotations of ``ax`` whose texts overlap (by more than 1 pixel²)."""
    boxes = label_boxes(ax)
    return [
        (i, j)
        for (i, a), (j, b) in itertools.combinations(enumerate(boxes), 2)
        if shared_area(a, b) > 1.0
    ]


def legend_over_axes(ax) -> float:
    """Area [pixels²] of the axes' legend inside the data area (0: beside it)."""
    legend = ax.get_legend()
    assert legend is not None, "the axes have no legend"
    renderer = _renderer(ax.figure)
    return shared_area(legend.get_window_extent(renderer), ax.get_window_extent(renderer))


def labelled_ticks(axis) -> list[str]:
    """The labels of the major ticks of ``axis`` inside its view (empty labels dropped)."""
    _renderer(axis.axes.figure)
    lo, hi = sorted(axis.get_view_interval())
    return [
        t.label1.get_text()
        for t, loc in zip(axis.get_major_ticks(), axis.get_majorticklocs(), strict=False)
        if lo <= loc <= hi and t.label1.get_text()
    ]


def ticks_in_view(axis) -> np.ndarray:
    """The major tick positions of ``axis`` inside its view."""
    _renderer(axis.axes.figure)
    lo, hi = sorted(axis.get_view_interval())
    locs = np.asarray(axis.get_majorticklocs())
    return locs[(locs >= lo) & (locs <= hi)]
