"""Layout helpers shared by the report figures: point labels that never collide, legends beside
the axes (never over the data), and log axes with enough readable ticks.

Label placement works in display coordinates [pixels] and therefore needs the figure's final
size and axes position: call :func:`place_labels` after ``fig.tight_layout()`` (or after
:func:`legend_outside`, which lays the figure out) and change the layout no more before saving.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np

#: Offsets tried for a label [points], nearest first: rings of these radii ...
_RADII = (3, 9, 16, 24, 33, 43, 54, 66, 80, 95, 112, 130, 150, 172, 196, 222, 250)
#: ... in these directions [degrees], right of the point first.
_ANGLES = (0, 15, -15, 30, -30, 45, -45, 60, -60, 75, -75, 90, -90, 105, -105, 120, -120, 135,
           -135, 150, -150, 165, -165, 180)  # fmt: skip
#: Labels at least this far [points] from their point get a leader line.
_LEADER_FROM = 8.0
#: Least space [points] between two labels.
_GAP = 1.5
#: Half-size [points] of the box around every point that no label may cover.
_MARKER_HALF = 4.0


def _alignment(dx: float, dy: float) -> tuple[str, str]:
    """Text alignment that puts the label beyond its offset, away from the point."""
    ha = "left" if dx > 0.5 else "right" if dx < -0.5 else "center"
    va = "bottom" if dy > 0.5 else "top" if dy < -0.5 else "center"
    return ha, va


def label_box(annotation, renderer):
    """Display-coordinate box [pixels] of an annotation's text alone (without its leader)."""
    from matplotlib.text import Text

    annotation.get_window_extent(renderer)  # updates the text position
    return Text.get_window_extent(annotation, renderer)


def _overlaps(boxes: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Area [pixels²] each of ``boxes`` ``(n, 4)`` (x0, y0, x1, y1) shares with the boxes
    ``others`` ``(m, 4)``, summed: shape ``(n,)``."""
    if not len(others):
        return np.zeros(len(boxes))
    w = np.minimum(boxes[:, None, 2], others[None, :, 2]) - np.maximum(
        boxes[:, None, 0], others[None, :, 0])  # fmt: skip
    h = np.minimum(boxes[:, None, 3], others[None, :, 3]) - np.maximum(
        boxes[:, None, 1], others[None, :, 1])  # fmt: skip
    return np.sum(np.clip(w, 0, None) * np.clip(h, 0, None), axis=1)


def _crossings(starts: np.ndarray, ends: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Whether each segment from ``starts`` to ``ends`` ``(n, 2)`` passes through each of the
    boxes ``(m, 4)``: shape ``(n, m)`` (Liang-Barsky clipping, all pairs at once)."""
    x0, y0 = starts[:, :1], starts[:, 1:]
    dx, dy = ends[:, :1] - x0, ends[:, 1:] - y0
    bx0, by0, bx1, by1 = (boxes[None, :, k] for k in range(4))
    shape = (len(starts), len(boxes))
    lo, hi = np.zeros(shape), np.ones(shape)
    missed = np.zeros(shape, dtype=bool)  # parallel to a side and outside it
    with np.errstate(divide="ignore", invalid="ignore"):
        for p, q in ((-dx, x0 - bx0), (dx, bx1 - x0), (-dy, y0 - by0), (dy, by1 - y0)):
            p = np.broadcast_to(p, shape)
            ratio = q / p
            lo = np.where(p < 0, np.maximum(lo, ratio), lo)
            hi = np.where(p > 0, np.minimum(hi, ratio), hi)
            missed |= (p == 0) & (q < 0)
    return (lo < hi) & ~missed


def _candidates(anchor: np.ndarray, size, dpi: float):
    """Every offset tried for a label of ``size`` (width, height) [pixels] at the display point
    ``anchor``, nearest first: ``(offsets (n, 2) [points], text boxes (n, 4) [pixels], leader
    (n,) whether it gets a leader line)``."""
    radius, angle = np.array(list(itertools.product(_RADII, _ANGLES)), dtype=float).T
    offsets = np.column_stack([radius * np.cos(np.deg2rad(angle)),
                               radius * np.sin(np.deg2rad(angle))])  # fmt: skip
    # Fraction of the box left / below the offset point, as _alignment aligns the text.
    fx = np.where(offsets[:, 0] > 0.5, 0.0, np.where(offsets[:, 0] < -0.5, 1.0, 0.5))
    fy = np.where(offsets[:, 1] > 0.5, 0.0, np.where(offsets[:, 1] < -0.5, 1.0, 0.5))
    x = anchor[0] + offsets[:, 0] * dpi / 72 - fx * size[0]
    y = anchor[1] + offsets[:, 1] * dpi / 72 - fy * size[1]
    boxes = np.column_stack([x, y, x + size[0], y + size[1]])
    return offsets, boxes, radius >= _LEADER_FROM


def place_labels(ax, points: Sequence[tuple[float, float]], texts: Sequence[str], fontsize=6,
                 color="k", avoid: Sequence[tuple[float, float]] = (),
                 lines: Sequence[tuple[tuple[float, float], tuple[float, float]]] = ()
                 ) -> list:  # fmt: skip
    """Annotate every point ``(x, y)`` [data coordinates] with its text so that no two labels
    overlap, no label covers a point (of ``points`` or of the unlabelled ``avoid``) and every
    label stays inside the axes; labels keep off the segments ``lines`` (``((x0, y0), (x1,
    y1))`` [data coordinates]: the curves and error bars drawn) where they can.

    Greedy, in display coordinates: each label in turn takes the nearest free offset of rings of
    growing radius around its point (right of the point first), checked against the text boxes
    of the labels already placed, the points and the ``lines``; among the free ones, the fewest
    leader lines crossing labels. A label far from its point gets a thin leader line. When no
    offset is free (more labels than the axes can hold) it takes the offset of least overlap.
    Returns the annotations in the order of ``points``.
    """
    if len(points) != len(texts):
        raise ValueError(f"{len(points)} points but {len(texts)} labels")
    ax.figure.draw_without_rendering()  # settles the autoscaled limits that place the points
    renderer = ax.figure.canvas.get_renderer()
    dpi = ax.figure.dpi
    f = ax.get_window_extent(renderer)
    frame = np.array([[f.x0, f.y0, f.x1, f.y1]])
    shown = ax.transData.transform(np.asarray(points, dtype=float).reshape(-1, 2))
    half = _MARKER_HALF * dpi / 72
    clear = np.vstack([shown, ax.transData.transform(np.asarray(avoid, float).reshape(-1, 2))])
    markers = np.column_stack([clear - half, clear + half])
    drawn = ax.transData.transform(np.asarray(lines, dtype=float).reshape(-1, 2)).reshape(-1, 4)
    placed = np.empty((0, 4))
    leaders = np.empty((0, 4))  # from (x, y) to (x, y) [pixels], the leader lines drawn so far
    out = []
    for xy, anchor, text in zip(points, shown, texts, strict=True):
        note = ax.annotate(text, xy, xytext=(0, 0), textcoords="offset points",
                           fontsize=fontsize, color=color, annotation_clip=False,
                           arrowprops={"arrowstyle": "-", "color": "0.55", "linewidth": 0.5,
                                       "shrinkA": 0, "shrinkB": 2})  # fmt: skip
        probe = label_box(note, renderer)
        offsets, boxes, leader = _candidates(anchor, (probe.width, probe.height), dpi)
        # Covering a label or point, or leaving the axes, is ruled out whenever an offset that
        # does neither exists; leaders crossing labels are avoided where possible.
        area = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
        gap = _GAP * dpi / 72
        covered = _overlaps(boxes + [-gap, -gap, gap, gap], placed) + _overlaps(boxes, markers)
        covered += area - _overlaps(boxes, frame)
        covered += area * _crossings(drawn[:, :2], drawn[:, 2:], boxes).sum(axis=0)
        centres = (boxes[:, :2] + boxes[:, 2:]) / 2
        crossed = _crossings(leaders[:, :2], leaders[:, 2:], boxes).sum(axis=0)
        crossed += leader * _crossings(centres, np.broadcast_to(anchor, centres.shape),
                                       placed).sum(axis=1)  # fmt: skip
        best = np.lexsort((np.arange(len(boxes)), crossed, np.round(covered, 6)))[0]
        dx, dy = offsets[best]
        note.set_position((dx, dy))
        note.set_horizontalalignment(_alignment(dx, dy)[0])
        note.set_verticalalignment(_alignment(dx, dy)[1])
        note.arrow_patch.set_visible(bool(leader[best]))
        placed = np.vstack([placed, boxes[best]])
        if leader[best]:
            leaders = np.vstack([leaders, [*centres[best], *anchor]])
        out.append(note)
    return out


def legend_outside(ax, fontsize=7, **options):
    """A legend to the right of the axes, top-aligned, so it covers no data; lays the figure out
    (``tight_layout``) so that the legend stays inside the figure. Returns the legend (None when
    nothing is labelled)."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        ax.figure.tight_layout()
        return None
    legend = ax.legend(handles, labels, fontsize=fontsize, loc="upper left",
                       bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **options)  # fmt: skip
    ax.figure.tight_layout()
    return legend


def _log_ticks(vmin: float, vmax: float, min_ticks: int) -> np.ndarray:
    """Major tick positions for a log axis viewing ``[vmin, vmax]``: the sparsest of decades,
    1-2-5 and 1..9 per decade that puts ``min_ticks`` in view, else evenly spaced values."""
    from matplotlib import ticker

    lo, hi = sorted((vmin, vmax))
    if not (lo > 0 and np.isfinite(hi)):
        return np.array([])
    for subs in ((1.0,), (1.0, 2.0, 5.0), tuple(range(1, 10))):
        ticks = ticker.LogLocator(base=10.0, subs=subs, numticks=12).tick_values(lo, hi)
        inside = ticks[(ticks >= lo * (1 - 1e-9)) & (ticks <= hi * (1 + 1e-9))]
        if inside.size >= min_ticks:
            return inside
    # Less than a factor ~2 between the ends: the scale is nearly linear there.
    ticks = ticker.MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    return ticks[(ticks > 0) & (ticks >= lo) & (ticks <= hi)]


def _plain_number(value: float, _pos=None) -> str:
    return f"{value:g}"


def readable_log_axis(axis, min_ticks: int = 3) -> None:
    """Give a log-scaled ``axis`` (``ax.xaxis`` or ``ax.yaxis``) at least ``min_ticks`` labelled
    major ticks in view: decades when the view spans enough of them, else 1-2-5 or 1..9 per
    decade, else evenly spaced values; labelled as plain numbers (``0.3``, ``2000``), the minor
    ticks unlabelled. Chosen when the figure is drawn, so later limit changes are followed."""
    from matplotlib import ticker

    class EnoughLogTicks(ticker.Locator):
        def __call__(self):
            return self.tick_values(*self.axis.get_view_interval())

        def tick_values(self, vmin, vmax):
            return _log_ticks(vmin, vmax, min_ticks)

    axis.set_major_locator(EnoughLogTicks())
    axis.set_major_formatter(ticker.FuncFormatter(_plain_number))
    axis.set_minor_locator(ticker.LogLocator(base=10.0, subs=tuple(range(2, 10)), numticks=12))
    axis.set_minor_formatter(ticker.NullFormatter())
