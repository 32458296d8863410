"""Layout helpers shared by the report figures: point labels that never collide, legends beside
the axes (never over the data), axis labels and titles that fit the figure, and log axes with
enough readable ticks.

Label placement works in display coordinates [pixels] and therefore needs the figure's final
size and axes position: call :func:`place_labels` after ``fig.tight_layout()`` (or after
:func:`legend_outside`, which lays the figure out) and change the layout no more before saving.

It loads matplotlib's text, ticker and offsetbox (about 0.35 s), not pyplot:
:func:`spll_hw.report.plots._pyplot` chooses the headless backend before pyplot loads.
"""

from __future__ import annotations

import itertools
import re
import textwrap
from collections.abc import Sequence

import numpy as np
from matplotlib import ticker
from matplotlib.offsetbox import AnchoredOffsetbox, HPacker, TextArea
from matplotlib.text import Text

#: Offsets tried for a label [points], nearest first: rings of these radii (the first clears
#: the point's own marker, :data:`_MARKER_HALF`, so a label beside a free point needs no
#: leader) ...
_RADII = (6, 9, 16, 24, 33, 43, 54, 66, 80, 95, 112, 130, 150, 172, 196, 222, 250)
#: ... in these directions [degrees], right of the point first.
_ANGLES = (0, 15, -15, 30, -30, 45, -45, 60, -60, 75, -75, 90, -90, 105, -105, 120, -120, 135,
           -135, 150, -150, 165, -165, 180)  # fmt: skip
#: Labels at least this far [points] from their point get a leader line.
_LEADER_FROM = 8.0
#: Least space [points] between a label and another label, a point or a line.
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


def _segments_cross(
    starts: np.ndarray, ends: np.ndarray, others_start: np.ndarray, others_end: np.ndarray
) -> np.ndarray:
    """Whether each segment ``starts`` to ``ends`` ``(n, 2)`` properly crosses each segment
    ``others_start`` to ``others_end`` ``(m, 2)``: shape ``(n, m)`` (segments that only touch,
    e.g. two leaders to one point, do not cross)."""
    a, b = starts[:, None, :], ends[:, None, :]
    c, d = others_start[None, :, :], others_end[None, :, :]

    def side(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))  # fmt: skip

    return (side(a, b, c) * side(a, b, d) < 0) & (side(c, d, a) * side(c, d, b) < 0)


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
    leader lines crossing labels, other leader lines or other points. A label far from its point
    gets a thin leader line; one right beside it gets none. When the labels do not fit (some
    label would cover another or a point, or leave the axes, or a leader line would cross
    another or a label: more text than the axes hold), every point gets its number instead (1,
    2, ...: small, placed the same way) and a key beside the axes, below the legend and in as
    many columns as the axes' height needs, says which number is which text; the figure grows
    by the key's width and is laid out again (:func:`fit_layout`). Returns the annotations
    (labels or numbers) in the order of ``points``.
    """
    if len(points) != len(texts):
        raise ValueError(f"{len(points)} points but {len(texts)} labels")
    notes, fits = _place(ax, points, texts, fontsize, color, avoid, lines)
    if fits:
        return notes
    for note in notes:
        note.remove()
    numbers = [str(k) for k in range(1, len(points) + 1)]
    _add_key(ax, [f"{n}  {t}" for n, t in zip(numbers, texts, strict=True)], fontsize)
    return _place(ax, points, numbers, fontsize, color, avoid, lines)[0]


def _place(ax, points, texts, fontsize, color, avoid, lines) -> tuple[list, bool]:
    """The labels of :func:`place_labels`, placed greedily: ``(annotations, whether every one
    found an offset that covers no label or point, stays inside the axes and has its leader, if
    any, cross no label or leader)``."""
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
    fits = True
    for k, (xy, anchor, text) in enumerate(zip(points, shown, texts, strict=True)):
        note = ax.annotate(text, xy, xytext=(0, 0), textcoords="offset points",
                           fontsize=fontsize, color=color, annotation_clip=False,
                           arrowprops={"arrowstyle": "-", "color": "0.55", "linewidth": 0.5,
                                       "shrinkA": 0, "shrinkB": 2})  # fmt: skip
        probe = label_box(note, renderer)
        offsets, boxes, leader = _candidates(anchor, (probe.width, probe.height), dpi)
        # Covering a label or point, or leaving the axes, is ruled out whenever an offset that
        # does neither exists; then crossing a line drawn; leaders crossing labels, leaders or
        # points are avoided where possible.
        area = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
        gap = _GAP * dpi / 72
        padded = boxes + [-gap, -gap, gap, gap]
        covered = _overlaps(padded, placed) + _overlaps(padded, markers)
        covered += area - _overlaps(boxes, frame)
        across = area * _crossings(drawn[:, :2], drawn[:, 2:], padded).sum(axis=0)
        centres = (boxes[:, :2] + boxes[:, 2:]) / 2
        ends = np.broadcast_to(anchor, centres.shape)
        tangled = _crossings(leaders[:, :2], leaders[:, 2:], boxes).sum(axis=0)
        tangled += leader * (_crossings(centres, ends, placed).sum(axis=1)
                             + _segments_cross(centres, ends, leaders[:, :2],
                                               leaders[:, 2:]).sum(axis=1))  # fmt: skip
        others = np.delete(markers, k, axis=0)  # the leader ends on its own point
        crossed = tangled + leader * _crossings(centres, ends, others).sum(axis=1)
        best = np.lexsort((np.arange(len(boxes)), crossed, np.round(across, 6),
                           np.round(covered, 6)))[0]  # fmt: skip
        # A label on another or a point, off the axes, or a leader through another label or
        # leader: the reader can no longer tell which text is which point's.
        fits &= bool(np.round(covered[best], 6) == 0 and tangled[best] == 0)
        dx, dy = offsets[best]
        note.set_position((dx, dy))
        note.set_horizontalalignment(_alignment(dx, dy)[0])
        note.set_verticalalignment(_alignment(dx, dy)[1])
        note.arrow_patch.set_visible(bool(leader[best]))
        placed = np.vstack([placed, boxes[best]])
        if leader[best]:
            leaders = np.vstack([leaders, [*centres[best], *anchor]])
        out.append(note)
    return out, fits


def _add_key(ax, entries: Sequence[str], fontsize) -> None:
    """A key of ``entries`` (one a line) to the right of the axes, under their legend, in as
    many columns as keep it beside the axes (not beside their tick labels); the figure is made
    wider by the key's width, so the axes keep theirs, and laid out again."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()

    def top() -> float:
        """Where the key starts [axes fraction]: under the legend, else at the axes' top."""
        legend = ax.get_legend()
        if legend is None:
            return 1.0
        below = legend.get_window_extent(renderer).y0 - 4 * fig.dpi / 72
        return float(ax.transAxes.inverted().transform((0.0, below))[1])

    room = top() * ax.get_window_extent(renderer).height  # [pixels] from the key's top down
    line = 1.2 * fontsize * fig.dpi / 72
    rows = max(int(room / line) - 1, 1)
    columns = -(-len(entries) // rows)
    rows = -(-len(entries) // columns)
    chunks = [entries[c * rows : (c + 1) * rows] for c in range(columns)]
    key = AnchoredOffsetbox(
        loc="upper left", pad=0.0, borderpad=0.0, frameon=False,
        child=HPacker(children=[TextArea("\n".join(chunk), textprops={"fontsize": fontsize})
                                for chunk in chunks], pad=0, sep=8),
        bbox_to_anchor=(1.01, top()), bbox_transform=ax.transAxes,
    )  # fmt: skip
    ax.add_artist(key)
    fig.draw_without_rendering()
    width, height = fig.get_size_inches()
    fig.set_size_inches(width + (key.get_window_extent(renderer).width + 8) / fig.dpi, height)
    fit_layout(fig)
    fig.draw_without_rendering()
    key.set_bbox_to_anchor((1.01, top()), transform=ax.transAxes)  # the legend moved with the axes


def legend_outside(ax, fontsize=7, **options):
    """A legend to the right of the axes, top-aligned, so it covers no data; lays the figure out
    (:func:`fit_layout`: ``tight_layout``, long axis labels and titles wrapped) so that the
    legend and the labels stay inside the figure. Returns the legend (None when nothing is
    labelled)."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        fit_layout(ax.figure)
        return None
    legend = ax.legend(handles, labels, fontsize=fontsize, loc="upper left",
                       bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **options)  # fmt: skip
    fit_layout(ax.figure)
    return legend


#: A number and its unit or sign stay on one line (``95 %``, ``3 ms``, ``x 2``).
_KEEP_TOGETHER = re.compile(r"(?<=\d) (?=[%\w\[(µ])|(?<=[x×~≈<>=]) (?=\d)")
_NO_BREAK = "\u00a0"


def _length(text, renderer) -> float:
    """Extent [pixels] of a matplotlib text along its lines (its height when it is upright)."""
    box = text.get_window_extent(renderer)
    upright = abs(np.sin(np.deg2rad(text.get_rotation()))) > abs(np.cos(np.deg2rad(
        text.get_rotation())))  # fmt: skip
    return box.height if upright else box.width


def wrap_to_width(text, width: float, renderer) -> bool:
    """Break the lines of the matplotlib ``text`` (an axis label, a title, a figure text) at
    spaces until none is longer than ``width`` [pixels] (along its lines: a y-axis label's
    height); a number keeps its unit. Returns whether the text changed."""
    before = text.get_text()
    # Broken here before (and unchanged since): break the text as it was given, afresh.
    given = before
    if before == getattr(text, "_wrapped_text", None):
        given = text._given_text
    text.set_text(given)
    if width > 0 and given and _length(text, renderer) > width:
        guarded = _KEEP_TOGETHER.sub(_NO_BREAK, given)
        longest = max(len(line) for line in guarded.splitlines())
        chars = longest * width / _length(text, renderer)
        for _ in range(12):
            chars = max(int(chars * 0.92), 8)
            lines = [textwrap.fill(line, chars, break_long_words=False, break_on_hyphens=False)
                     for line in guarded.splitlines()]  # fmt: skip
            text.set_text("\n".join(lines).replace(_NO_BREAK, " "))
            if _length(text, renderer) <= width or chars == 8:
                break
        text._given_text, text._wrapped_text = given, text.get_text()
    return text.get_text() != before


def fit_layout(fig) -> None:
    """``fig.tight_layout()`` with every axis label and axes title no longer than its axes side
    and every figure title or text no wider than the figure (broken at spaces where longer, then
    laid out again), so that none is clipped by the figure's edge."""
    fig.tight_layout()
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    changed = False
    for ax in fig.axes:
        if not ax.get_visible() or not ax.axison:
            continue
        box = ax.get_window_extent(renderer)
        for text in (ax.xaxis.label, ax.title, ax._left_title, ax._right_title):
            changed |= wrap_to_width(text, box.width, renderer)
        changed |= wrap_to_width(ax.yaxis.label, box.height, renderer)
    for text in (*fig.texts, getattr(fig, "_suptitle", None), getattr(fig, "_supxlabel", None)):
        if text is not None:
            changed |= wrap_to_width(text, 0.98 * fig.bbox.width, renderer)
    if changed:
        fig.tight_layout()


def _log_ticks(vmin: float, vmax: float, min_ticks: int) -> np.ndarray:
    """Major tick positions for a log axis viewing ``[vmin, vmax]``: the sparsest of decades,
    1-2-5 and 1..9 per decade that puts ``min_ticks`` in view, else evenly spaced round values,
    as many steps as it takes to put ``min_ticks`` in view (a view straddling a decade, 8.4 to
    12.5, gets 9, 10, 11, 12, not 10 alone)."""
    lo, hi = sorted((vmin, vmax))
    if not (lo > 0 and np.isfinite(hi)):
        return np.array([])

    def in_view(ticks):
        return ticks[(ticks >= lo * (1 - 1e-9)) & (ticks <= hi * (1 + 1e-9))]

    # Decades (strided where many); never matplotlib's fallback to linear ticks, which is only
    # taken for several subs per decade.
    decades = in_view(ticker.LogLocator(base=10.0, subs=(1.0,), numticks=12).tick_values(lo, hi))
    if decades.size >= min_ticks:
        return decades
    exponents = np.arange(np.floor(np.log10(lo)) - 1, np.ceil(np.log10(hi)) + 1)
    for subs in ((1.0, 2.0, 5.0), tuple(range(1, 10))):
        ticks = in_view((np.array(subs)[None, :] * 10.0 ** exponents[:, None]).ravel())
        if ticks.size >= min_ticks:
            return ticks
    # Less than a factor ~2 between the ends: the scale is nearly linear there.
    ticks = np.array([])
    for nbins in range(max(min_ticks, 2), 4 * max(min_ticks, 2) + 1):
        locator = ticker.MaxNLocator(nbins=nbins, steps=[1, 2, 2.5, 5, 10])
        ticks = in_view(locator.tick_values(lo, hi))
        ticks = ticks[ticks > 0]
        if ticks.size >= min_ticks:
            break
    return ticks


def _digits(values) -> int:
    """The fewest significant digits that write every one of ``values`` to within 1e-9 of
    itself and no two alike, and every integer part up to 6 digits in full (``2000``, not
    ``2e+03``)."""
    values = [v for v in np.asarray(values, dtype=float).ravel() if np.isfinite(v) and v != 0]
    whole = max((int(np.floor(np.log10(abs(v)))) + 1 for v in values), default=1)
    for digits in range(min(max(whole, 1), 6), 16):
        labels = [f"{v:.{digits}g}" for v in values]
        exact = all(abs(float(t) - v) <= 1e-9 * max(abs(v), 1e-300) for t, v in
                    zip(labels, values, strict=True))  # fmt: skip
        if exact and len(set(labels)) == len(labels):
            return digits
    return 16


def _plain_number(value: float, _pos=None, digits: int = 6) -> str:
    return f"{value:.{digits}g}"


def readable_log_axis(axis, min_ticks: int = 3) -> None:
    """Give a log-scaled ``axis`` (``ax.xaxis`` or ``ax.yaxis``) at least ``min_ticks`` labelled
    major ticks in view: decades when the view spans enough of them, else 1-2-5 or 1..9 per
    decade, else evenly spaced round values; labelled as plain numbers (``0.3``, ``2000``; as
    many digits as tell the ticks apart), the minor ticks unlabelled. Chosen when the figure is
    drawn, so later limit changes are followed."""

    class EnoughLogTicks(ticker.Locator):
        def __call__(self):
            return self.tick_values(*self.axis.get_view_interval())

        def tick_values(self, vmin, vmax):
            return _log_ticks(vmin, vmax, min_ticks)

    class PlainNumbers(ticker.Formatter):
        digits = 6

        def set_locs(self, locs):
            super().set_locs(locs)
            self.digits = _digits(locs)

        def __call__(self, x, pos=None):
            return _plain_number(x, pos, self.digits)

    axis.set_major_locator(EnoughLogTicks())
    axis.set_major_formatter(PlainNumbers())
    axis.set_minor_locator(ticker.LogLocator(base=10.0, subs=tuple(range(2, 10)), numticks=12))
    axis.set_minor_formatter(ticker.NullFormatter())
