"""Decide runs of the multichannel readout from the output spikes of its standard-node NIR graph.

This file needs numpy only (no spll-hw, no nir): it is copied as ``decide.py`` into the export
folders of :mod:`mappings.nir.readout_graph`, beside ``readout.npz`` (:func:`save_readout`), and
run wherever the graph runs (Norse, snnTorch, spll-hw's executor).

The readout (spll-hw's ``Readout`` / ``StagedReadout``): ``S`` stages (1 for a single readout)
of ``k`` classes over ``d`` TDEs. Class ``j`` of stage ``s`` has the membrane
``v_sj(t) = sum_i w_sji N_i(t) + beta_sj t`` [score x s] (``N_i(t)``: spikes of TDE ``i``
so far; ``w`` [score x s per spike], ``beta`` [score = 1/s x score x s]). Stage ``s`` is on over
``[max(starts[s], not_before), starts[s + 1]]`` (the last to the run's end); the first membrane
of the stage on to reach ``threshold`` decides (one already above it at switch-on decides then);
none: the last stage's largest membrane at the end (``fired=False``). Ties at one instant: the
larger membrane, then the lower class.

The graph is clocked at ``dt`` [s]: a TDE spike at ``t`` counts in step ``max(1, ceil(t/dt))``
(:func:`grid_step`), at the end of the step, ``n dt``; the graph's input in step ``n`` is the
vector of the ``d`` counts of that step. Its first ``S k`` output rows are the *decision rows*,
stage-major (row ``s k + j``): one spikes in a step in which its stage is on, once its membrane
has reached the threshold (in that step or before). :func:`decide` takes the first step in which
a decision row spikes and settles that step from the counts: the earlier stage first (at a stage
switch both stages are on in the step of the switch), the earlier crossing within the step (a
membrane rises along ``beta`` between step ends and jumps at them), then the larger membrane at
that instant, then the lower class. A stage switched off in the middle of that step counts only
where its crossing came before its end.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np

#: Relative tolerance within which ``t / dt`` counts as a whole number of steps (spll-hw's grid
#: rule, ``spll_hw.model.grid.GRID_RTOL``).
GRID_RTOL = 1e-12
#: Seconds into a run before which the readout does not decide (spll-hw's ``START``).
START = 0.1
#: The readout's arrays in an export folder (:func:`save_readout`).
READOUT_FILE = "readout.npz"


class Decision(NamedTuple):
    """One run's decision: ``label`` (class index), ``step`` (1-based step of the decision:
    ``ceil(t / dt)`` of the decision time ``t`` [s]; the last step where none fired) and
    ``fired`` (False: no membrane reached the threshold, the end decided)."""

    label: int
    step: int
    fired: bool


class Windows(NamedTuple):
    """When each stage is on, shapes ``(S,)``: ``on`` and ``off`` [s] (``off`` of the last
    stage ``inf``), ``first`` and ``last`` its first and last step (1-based, inclusive; the
    last stage's ``last`` is ``2**62``), ``empty`` where a stage is never on (it is switched
    off before ``not_before``)."""

    on: np.ndarray
    off: np.ndarray
    first: np.ndarray
    last: np.ndarray
    empty: np.ndarray


def grid_step(t: float, dt: float) -> int:
    """The step ``max(1, ceil(t / dt))`` [1-based] whose end is the first not before ``t`` [s],
    with ``t / dt`` within a relative :data:`GRID_RTOL` of a whole number read as it."""
    x = float(t) / float(dt)
    return max(1, math.ceil(x - x * GRID_RTOL))


def on_grid(t: float, dt: float) -> float:
    """``t`` [s], or ``n dt`` where ``t`` is a step's end ``n dt`` within :data:`GRID_RTOL`."""
    n = grid_step(t, dt)
    return n * dt if abs(float(t) / dt - n) <= GRID_RTOL * n else float(t)


def stage_windows(starts, not_before: float, dt: float) -> Windows:
    """:class:`Windows` of stages switched on at ``starts`` [s] (shape ``(S,)``, increasing),
    none before ``not_before`` [s], on a clock of ``dt`` [s]. Stage ``s`` is on in the steps
    ``grid_step(max(starts[s], not_before))`` to ``grid_step(starts[s + 1])``: two stages share
    the step of a switch."""
    starts = np.asarray(starts, dtype=float).reshape(-1)
    on = np.array([on_grid(max(s, not_before), dt) for s in starts])
    off = np.array([on_grid(s, dt) for s in starts[1:]] + [math.inf])
    first = np.array([grid_step(t, dt) for t in on], dtype=np.int64)
    last = np.array([grid_step(t, dt) for t in off[:-1]] + [2**62], dtype=np.int64)
    return Windows(on, off, first, last, on > off)


def _stacked(weights, bias, starts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``weights`` ``(S, k, d)``, ``bias`` ``(S, k)`` and ``starts`` ``(S,)`` as float arrays (a
    single readout's ``(k, d)`` and ``(k,)`` become one stage); ``ValueError`` on mismatch."""
    w = np.asarray(weights, dtype=float)
    b = np.asarray(bias, dtype=float)
    w, b = (w[None], b[None]) if w.ndim == 2 else (w, b)
    s = np.asarray(starts, dtype=float).reshape(-1)
    if w.ndim != 3 or b.shape != w.shape[:2] or s.shape != (w.shape[0],):
        raise ValueError(
            f"readout arrays must be weights (S, k, d), bias (S, k) and starts (S,); got "
            f"{np.shape(weights)}, {np.shape(bias)} and {np.shape(starts)}"
        )
    return w, b, s


def decide(
    output_spikes,
    tde_counts,
    weights,
    bias,
    threshold: float,
    starts,
    dt: float,
    not_before: float = START,
) -> list[Decision]:
    """Every sample's decision (module docstring).

    Args:
        output_spikes: the graph's output per step, shape ``(steps, batch, rows)``; its first
            ``S k`` rows are the decision rows.
        tde_counts: the graph's input, TDE spikes per step, shape ``(steps, batch, d)``.
        weights: ``w`` [score x s per spike], shape ``(S, k, d)`` (or ``(k, d)``: one stage).
        bias: ``beta`` [score], shape ``(S, k)`` (or ``(k,)``).
        threshold: ``theta`` [score x s], ``> 0`` (``inf``: the end decides).
        starts: the stages' switch-on times [s], shape ``(S,)`` (one stage: ``(0.0,)``).
        dt: the graph's time step [s].
        not_before: no decision before it [s].

    Returns:
        One :class:`Decision` per sample.
    """
    w, b, starts = _stacked(weights, bias, starts)
    spikes = np.asarray(output_spikes)
    counts = np.asarray(tde_counts, dtype=float)
    n_stages, k, d = w.shape
    if spikes.ndim != 3 or spikes.shape[2] < n_stages * k:
        raise ValueError(
            f"output_spikes must have shape (steps, batch, rows >= {n_stages * k}), "
            f"got {spikes.shape}"
        )
    if counts.shape != (*spikes.shape[:2], d):
        raise ValueError(
            f"tde_counts must have shape {(*spikes.shape[:2], d)} (steps, batch, TDEs), "
            f"got {counts.shape}"
        )
    if not threshold > 0:
        raise ValueError(f"threshold must be > 0 (score x s), got {threshold!r}")
    windows = stage_windows(starts, not_before, dt)
    steps = np.arange(1, spikes.shape[0] + 1)
    on = (steps[:, None] >= windows.first) & (steps[:, None] <= windows.last) & ~windows.empty
    rows = spikes[:, :, : n_stages * k].reshape(spikes.shape[0], spikes.shape[1], n_stages, k)
    hits = (rows > 0) & on[:, None, :, None]  # (steps, batch, S, k)
    return [
        _one(hits[:, sample], counts[:, sample], w, b, float(threshold), windows, dt)
        for sample in range(spikes.shape[1])
    ]


def _one(hits, counts, w, b, theta, windows: Windows, dt) -> Decision:
    """One sample: ``hits`` ``(steps, S, k)`` decision spikes of stages on, ``counts``
    ``(steps, d)``."""
    for index in np.flatnonzero(hits.any(axis=(1, 2))):
        n = int(index) + 1
        for s in np.flatnonzero(hits[index].any(axis=1)):
            made = _settle(np.flatnonzero(hits[index, s]), counts[:n], w[s], b[s], theta,
                           windows.on[s], windows.off[s], dt)  # fmt: skip
            if made is not None:
                return Decision(made, n, True)
    steps = counts.shape[0]
    end = counts.sum(axis=0) @ w[-1].T + b[-1] * (steps * dt)
    return Decision(int(np.argmax(end)), steps, False)


def _settle(classes, counts, w, b, theta, on, off, dt) -> int | None:
    """Which of ``classes`` (whose decision rows spiked in step ``n = len(counts)``) decides,
    or ``None`` where each crossed after its stage's end ``off`` [s]: the earliest decision time
    ``max(crossing, on)``, then the larger membrane then, then the lower class. The spike is the
    graph's word that the membrane crossed: one that by the counts has not reached theta by the
    step's end (a float32 consumer rounds a membrane that creeps up to theta across it a few
    steps early) crosses at the step's end."""
    n = counts.shape[0]
    post = np.vstack([np.zeros((1, w.shape[1])), np.cumsum(counts, axis=0)]) @ w[classes].T
    post += np.arange(n + 1)[:, None] * dt * b[classes]  # after the jumps at 0, dt, .., n dt
    beta = b[classes]
    times = np.array([_crossing(post[:, c], beta[c], theta, dt) for c in range(len(classes))])
    times = np.maximum(np.minimum(times, n * dt), on)
    valid = times <= off
    if not valid.any():
        return None
    first = times[valid].min()
    tied = np.flatnonzero(valid & (times == first))
    level = [_membrane_at(post[:, c], beta[c], first, dt) for c in tied]
    return int(classes[tied[int(np.argmax(level))]])


def _crossing(post, beta: float, theta: float, dt: float) -> float:
    """First time [s] the membrane reaches ``theta``: ``post`` ``(n + 1,)`` its values after
    the jumps at the step ends ``0..n``; between them it rises by ``beta`` [1/s]."""
    pre = post[:-1] + beta * dt  # just before the jumps at steps 1..n
    hit = np.flatnonzero((pre >= theta) | (post[1:] >= theta))
    if hit.size == 0:
        return math.inf
    m = int(hit[0]) + 1
    if pre[m - 1] >= theta and beta > 0:  # on the stretch from (m - 1) dt
        return (m - 1) * dt + (theta - post[m - 1]) / beta
    return m * dt


def _membrane_at(post, beta: float, t: float, dt: float) -> float:
    """The membrane at ``t`` [s], after the jumps of a step end at ``t``."""
    m = grid_step(t, dt)
    if on_grid(t, dt) == m * dt:
        return float(post[m])
    return float(post[m - 1] + beta * (t - (m - 1) * dt))


def save_readout(
    path,
    weights,
    bias,
    starts,
    threshold: float,
    dt: float,
    not_before: float = START,
    class_names=(),
) -> Path:
    """Write the readout's arrays to ``path`` (``readout.npz``): ``weights`` ``(S, k, d)``,
    ``bias`` ``(S, k)``, ``starts`` ``(S,)`` [s], ``threshold`` [score x s], ``dt`` [s],
    ``not_before`` [s] and the ``k`` ``class_names`` (a JSON list). Returns the path."""
    w, b, s = _stacked(weights, bias, starts)
    names = [str(c) for c in class_names]
    if names and len(names) != w.shape[1]:
        raise ValueError(f"{len(names)} class names for {w.shape[1]} classes")
    path = Path(path)
    with open(path, "wb") as f:
        np.savez(
            f, weights=w, bias=b, starts=s, threshold=np.float64(threshold),
            dt=np.float64(dt), not_before=np.float64(not_before),
            class_names=np.array(json.dumps(names)),
        )  # fmt: skip
    return path


def load_readout(path) -> dict:
    """:func:`save_readout`'s file as a dict: ``weights``, ``bias``, ``starts`` (arrays),
    ``threshold``, ``dt``, ``not_before`` (floats), ``class_names`` (a list). Pass it on as
    ``decide(spikes, counts, **{k: r[k] for k in DECIDE_KEYS})``."""
    with np.load(Path(path), allow_pickle=False) as f:
        out = {key: f[key] for key in ("weights", "bias", "starts")}
        out.update({key: float(f[key]) for key in ("threshold", "dt", "not_before")})
        out["class_names"] = json.loads(str(f["class_names"]))
    return out


#: The keys of :func:`load_readout`'s dict that :func:`decide` takes.
DECIDE_KEYS = ("weights", "bias", "threshold", "starts", "dt", "not_before")
