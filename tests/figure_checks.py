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
from matplotlib.offsetbox import AnchoredOffsetbox, TextArea
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


def leader_lines(ax) -> list[tuple[int, np.ndarray]]:
    """The visible leader lines of the annotations of ``ax``: (index of the annotation among
    them, segment ``[x0, y0, x1, y1]`` [pixels] from the text's centre to its point)."""
    renderer = _renderer(ax.figure)
    notes = [t for t in ax.texts if isinstance(t, Annotation)]
    out = []
    for k, note in enumerate(notes):
        if note.arrow_patch is not None and note.arrow_patch.get_visible():
            box = Text.get_window_extent(note, renderer)
            x, y = ax.transData.transform(note.xy)
            out.append((k, np.array([(box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2, x, y])))
    return out


def crossing_leaders(ax) -> list[tuple[int, int]]:
    """Pairs of annotations of ``ax`` whose leader lines cross (touching at a shared point
    does not count)."""

    def side(p, q, r):
        return np.sign((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    def cross(a, b):
        return (side(a[:2], a[2:], b[:2]) * side(a[:2], a[2:], b[2:]) < 0
                and side(b[:2], b[2:], a[:2]) * side(b[:2], b[2:], a[2:]) < 0)  # fmt: skip

    return [(i, j) for (i, a), (j, b) in itertools.combinations(leader_lines(ax), 2) if cross(a, b)]


def key_texts(ax) -> list[str]:
    """The lines of the keys (:class:`~matplotlib.offsetbox.AnchoredOffsetbox` artists) of
    ``ax``: what :func:`spll_hw.report.figure_layout.place_labels` writes beside crowded axes."""
    return [
        line
        for artist in ax.artists
        if isinstance(artist, AnchoredOffsetbox)
        for area in artist.findobj(TextArea)
        for line in area.get_text().splitlines()
    ]


def clipped_texts(fig) -> list[str]:
    """The axis labels, titles, figure texts, annotations and keys of ``fig`` that reach past
    the figure's edge (more than half a pixel): what a reader of the saved file would miss."""
    renderer = _renderer(fig)
    edge = fig.bbox
    texts = [*fig.texts, fig._suptitle]
    for ax in fig.axes:
        texts += [ax.xaxis.label, ax.yaxis.label, ax.title, *ax.texts]
        texts += [a for a in ax.artists if isinstance(a, AnchoredOffsetbox)]
    out = []
    for text in texts:
        if text is None or not text.get_visible():
            continue
        if isinstance(text, Text):
            if not text.get_text():
                continue
            box, name = Text.get_window_extent(text, renderer), text.get_text()
        else:
            box, name = text.get_window_extent(renderer), f"key of {len(text.get_children())}"
        if (box.x0 < edge.x0 - 0.5 or box.x1 > edge.x1 + 0.5 or box.y0 < edge.y0 - 0.5
                or box.y1 > edge.y1 + 0.5):  # fmt: skip
            out.append(name)
    return out
