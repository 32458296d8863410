"""The spiking readout's decisions run by the golden engine.

:func:`engine_decisions` hands a :class:`~.readout.Readout`'s weights and bias and the TDE spike
times of many runs to the Rust engine (``_engine.readout_decisions``), which decides every run
at every threshold in parallel with the GIL released: the same winner-take-all as
:func:`.readout.decide` (the first readout neuron to reach the threshold decides at its exact
crossing, no earlier than the switch-on; ties at one instant go to the larger membrane then,
the lower class first; none: the largest membrane at the run's end), computed with the same
floating-point operations in the same order, so labels, times and flags are equal, not close.
:func:`.readout.decide` stays the Python reference (tests check the two against each other).
Bad input (a NaN weight, a train count other than the readout's TDEs, a threshold <= 0) raises
``ValueError``.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import _engine
from ..limits import check_threads
from .readout import CHUNK, Decision, Readout, StagedReadout


@dataclass(frozen=True)
class Decisions:
    """Decisions of ``n`` runs at ``m`` thresholds.

    Attributes:
        labels: winning class index, shape ``(n, m)`` int64.
        times: time of the decision [s], shape ``(n, m)``.
        fired: a readout neuron reached the threshold, shape ``(n, m)`` bool (``False``: the
            largest membrane at the run's end decided).
    """

    labels: np.ndarray
    times: np.ndarray
    fired: np.ndarray

    def at(self, run: int, column: int) -> Decision:
        """One run's decision at one threshold."""
        return Decision(
            int(self.labels[run, column]),
            float(self.times[run, column]),
            bool(self.fired[run, column]),
        )


def engine_decisions(
    readout: Readout | StagedReadout,
    runs: Sequence[Sequence[np.ndarray]],
    duration: float,
    thresholds: Sequence[float],
    not_before: float = 0.0,
    threads: int | None = 1,
) -> Decisions:
    """Every run's decision at every threshold [score x s] (module docstring): ``runs[r][i]``
    the spike times [s] of TDE ``i`` in run ``r``, each run ``duration`` s long, no decision
    before ``not_before`` [s]; ``threads`` engine threads (``None``: all cores). Runs go to the
    engine :data:`.readout.CHUNK` at a time (it copies their spike times). A
    :class:`~.readout.StagedReadout` runs stage by stage (:func:`_staged`), equal to
    :func:`.readout.decide_staged` (tested)."""
    if isinstance(readout, StagedReadout):
        return _staged(readout, lambda stage, end, start: engine_decisions(
            stage, runs, end, thresholds, start, threads), duration, not_before)  # fmt: skip
    threads = check_threads(threads)
    weights = np.ascontiguousarray(readout.weights, dtype=float)
    bias = np.ascontiguousarray(readout.bias, dtype=float)
    levels = np.ascontiguousarray(thresholds, dtype=float).reshape(-1)
    parts = []
    for first in range(0, len(runs), CHUNK):
        chunk = [[np.ascontiguousarray(t, dtype=float) for t in run]
                 for run in runs[first : first + CHUNK]]  # fmt: skip
        try:
            args = (weights, bias, chunk, float(duration), levels, float(not_before), threads)
            parts.append(_engine.readout_decisions(*args))
        except ValueError as exc:  # the engine numbers the runs of the chunk
            where = re.match(r"run (\d+): ", str(exc))
            text = str(exc)[where.end() :] if where else str(exc)
            run = f"run {first + int(where[1])}: " if where else ""
            raise ValueError(f"readout decisions: {run}{text}") from None
    if not parts:
        empty = np.zeros((0, levels.size))
        return Decisions(empty.astype(np.int64), empty, empty.astype(bool))
    return Decisions(*(np.concatenate(arrays) for arrays in zip(*parts, strict=True)))


def _staged(staged: StagedReadout, decided, duration: float, not_before: float) -> Decisions:
    """A :class:`~.readout.StagedReadout`'s decisions from ``decided(stage, end, start)``, each
    stage's :class:`Decisions` on the runs up to its end, switched on at its start (or
    ``not_before``, if later): each run and threshold takes the first stage that fired while
    on, else the last stage's end decision."""
    out = None
    for readout, start, end in zip(staged.stages, staged.starts, staged.ends(duration),
                                   strict=True):  # fmt: skip
        made = decided(readout, end, max(start, not_before))
        take = np.ones_like(made.fired) if out is None else ~out.fired
        out = made if out is None else Decisions(
            np.where(take, made.labels, out.labels),
            np.where(take, made.times, out.times),
            np.where(take, made.fired, out.fired),
        )  # fmt: skip
    return out
