"""The clock's own floor: exact integration between steps checked as the export is
(:func:`floor_check`), and the gate's own error exact in time (:func:`gate_error`), which a
refusal measures to say whether the clock or the construction is the cause."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from spll_hw import simulate_batch
from spll_hw.backends import get
from spll_hw.backends.standard_exact import StandardExact
from spll_hw.construction.gate import Gate
from spll_hw.construction.reference import simulate_reference
from spll_hw.exporters import FolderRun, check
from spll_hw.exporters.check_inputs import DURATION, reference_inputs
from spll_hw.network import Network


def count_error(network: Network, spll: np.ndarray, run, duration: float = DURATION) -> float:
    """The largest TDE-count error among sPLLs ``spll`` of ``network`` over the check's
    reference inputs of ``duration`` [s] (all inputs' counts summed per sPLL, as the check
    counts them) of ``run(part, trains, duration) -> results`` against golden."""
    inputs = reference_inputs(network, duration)
    part = Network(tuple(network.spll[int(i)] for i in spll))
    trains = [x.spikes for x in inputs]
    duration = inputs[0].duration
    golden = np.array([g.tde_counts for g in simulate_batch(part, trains, duration)])
    counts = np.array([r.tde_counts for r in run(part, trains, duration)])
    return float(np.max(np.abs(counts - golden).sum(0) / np.maximum(golden.sum(0), 1)))


#: The refractory hold of the floor's exact integration (:data:`spll_hw.model.holds.HOLDS`):
#: both targets' (:func:`~spll_hw.model.holds.compensated_hold`), the better of the
#: whole-step holds (docs/backends.md), so that a floor above the limit is the clock's and not a
#: hold rule's.
FLOOR_HOLD = "compensated"


@dataclass(frozen=True)
class Floor:
    """Exact integration between steps of ``dt`` [s] checked as the export is: ``error``, the
    total TDE-rate error on the whole network (the check's verdict metric, against golden, on
    the check's reference inputs); ``spll_error``, the check's per-sPLL TDE-count error,
    shape ``(N,)``."""

    dt: float
    error: float
    spll_error: np.ndarray


def floor_check(
    network: Network,
    dt: float,
    hold: str = FLOOR_HOLD,
    duration: float = DURATION,
    gate: Gate | None = None,
    integrated: Network | None = None,
) -> Floor:
    """The export check (:func:`spll_hw.exporters.check.check_run`, its inputs of ``duration``
    [s] and metrics) of exact integration between steps of ``dt`` [s] with the golden product
    as gate (or ``gate``'s staircase) and refractory holds of rule ``hold``
    (:func:`spll_hw.construction.reference.simulate_reference`) on all of ``network``: like with
    like with the export's own check. ``integrated``: the network integrated instead, judged
    against golden of ``network`` (the same sPLLs with some parameter rounded, say)."""
    ran = network if integrated is None else integrated
    run = FolderRun(
        f"exact integration between steps of {dt:g} s", get("golden"),
        lambda trains, T: simulate_reference(ran, trains, T, (gate,), dt=dt, hold=hold)[0],
    )  # fmt: skip
    report = check.check_run(run, "standard-reference", network, max_error=1.0, duration=duration)
    return Floor(dt, float(report.tde_error), report.spll_tde_error)


def floor_errors(
    floor_of: Callable[[float], Floor], steps, tolerance: Callable[[float], float]
) -> list[Floor]:
    """``floor_of(dt)`` (:func:`floor_check` of a network) at each of ``steps`` [s], stopping
    at the first whose total error is within ``tolerance(dt)``."""
    out = []
    for dt in steps:
        out.append(floor_of(dt))
        if out[-1].error <= tolerance(dt):
            break
    return out


def gate_error(
    network: Network, spll: np.ndarray, levels: int, placement: str, duration: float = DURATION
) -> float:
    """The TDE-count error (:func:`count_error`, inputs of ``duration`` [s]) on sPLLs ``spll``
    of the export's gate of ``levels`` levels placed by ``placement`` alone:
    ``standard-exact``, exact in time."""
    gate = StandardExact(levels=levels, placement=placement)
    return count_error(network, spll, gate.simulate_batch, duration)
