"""A clock per set of sPLLs: the standard sPLL on Loihi's integers with every sPLL at the step
that holds its refractory period in exactly ``R + 1/2`` steps (in memory; not yet an export).

One Loihi step cannot hold a time-scaled network: a step fine enough for its fast sPLLs'
refractory periods leaves its slow sPLLs' long time constants few of the 12 decay bits
(docs/backends.md, the lava-standard table). A time-scaled sPLL is its base sPLL with every
time constant scaled by one factor, so at a step scaled alike it has the base sPLL's integers.
:func:`clocked_standard` writes each set of sPLLs that share a step
(:func:`spll_steps`: ``dt_i = min(t_tde_refr, t_cco_refr)_i / (R + 1/2)``, at which the
compensated hold of ``round(t_refr/dt - 1/2) = R`` steps is exact on average) as its own
:class:`~mappings.lava.standard.LavaStandard` at that step, with its rows of the whole
network's gate; :func:`run_clocked` runs each part by :func:`~mappings.lava.loihi.run_trains`
on the input binned at its own step. A vary-offset network is one part: one step for all.

On a chip this is one network on one clock run offline: each part's input ring buffer holds the
recording binned at its own step, and its counts are its spikes in its first ``T / dt`` steps;
it is not a real-time stream. Measured on the four presets ``lava-standard`` refuses:
``benchmarks/bench_clock_per_spll.py`` and docs/backends.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from mappings.standard.construction import Gate, gate_levels
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES
from spll_hw.result import SimulationResult

from .loihi import run_trains
from .standard import HOLDS, LavaStandard, lava_standard

#: Refractory steps of every sPLL (``R``): within 7 % on ``biotac-time-scaled-pacinian`` and
#: ``-peak`` at every ``R`` from 3 to 8 (docs/backends.md); 4 is the closest on both.
DEFAULT_HOLDS = 4
#: The gate: 32 levels on the network's band (``lava-standard``'s finest export gate).
DEFAULT_LEVELS = 32
DEFAULT_PLACEMENT = "band-quantile"


def spll_steps(network: Network, holds: float = DEFAULT_HOLDS) -> np.ndarray:
    """Each sPLL's step [s], shape ``(N,)``: its shorter refractory period (TDE or CCO) in
    ``holds + 1/2`` steps.

    Raises:
        ValueError: where ``holds`` is under 2 (Loihi's refractory unit holds 2 or more steps).
    """
    if not holds >= 2:
        raise ValueError(
            f"holds = {holds!r}: the refractory unit holds 2 or more steps (use holds >= 2)"
        )
    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    return np.minimum(p["t_tde_refr"], p["t_cco_refr"]) / (holds + 0.5)


class ClockPart(NamedTuple):
    """One set of sPLLs at one step: ``spll``, their numbers in the network, shape ``(n,)``;
    ``network``, those sPLLs as a network of their own; ``params``, its integers at step
    ``params.dt`` [s] (sPLL ``k`` of both is the network's ``spll[k]``)."""

    spll: np.ndarray
    network: Network
    params: LavaStandard


@dataclass(frozen=True)
class ClockedStandard:
    """The integers of a network whose sets of sPLLs run at their own steps.

    Attributes:
        parts: the sets, in the order of their step, coarsest first.
        n_spll: N.
        holds: ``R``, every sPLL's refractory steps.
        gate: the whole network's gate (each part has its rows).
    """

    parts: tuple[ClockPart, ...]
    n_spll: int
    holds: float
    gate: Gate

    @property
    def steps(self) -> np.ndarray:
        """Each sPLL's step [s], shape ``(N,)``."""
        out = np.zeros(self.n_spll)
        for part in self.parts:
            out[part.spll] = part.params.dt
        return out


def clocked_standard(
    network: Network,
    holds: float = DEFAULT_HOLDS,
    *,
    levels: int = DEFAULT_LEVELS,
    placement: str = DEFAULT_PLACEMENT,
    hold: str = HOLDS[0],
) -> ClockedStandard:
    """``network`` on Loihi's integers, each set of sPLLs at its step of :func:`spll_steps`,
    with ``levels`` gate levels placed by ``placement`` on the whole network and Loihi's
    refractory ``hold``.

    Raises:
        ValueError: ``holds`` under 2, or :func:`~mappings.lava.standard.lava_standard`'s
            refusal of a part, prefixed with the network's numbers of its sPLLs.
    """
    steps = spll_steps(network, holds)
    gate = gate_levels(network, levels, placement)
    parts = []
    for dt in np.unique(steps)[::-1]:
        idx = np.flatnonzero(steps == dt)
        part = Network.from_matrix(network.matrix()[idx], layout=network.layout)
        rows = Gate(gate.thresholds[idx], gate.increments[idx], gate.placement, gate.input_rates)
        try:
            params = lava_standard(part, dt=float(dt), gate=rows, hold=hold)
        except ValueError as exc:
            raise ValueError(
                f"the network's sPLLs {idx.tolist()} at their step dt = {dt:g} s (numbered from 0 "
                f"among them below): {exc}"
            ) from exc
        parts.append(ClockPart(idx, part, params))
    return ClockedStandard(tuple(parts), network.n_spll, float(holds), gate)


def run_clocked(
    clocked: ClockedStandard, trains, duration: float, backend: str = "standard-fixed-point"
) -> list[SimulationResult]:
    """Every train (sorted input spike times [s]) for ``duration`` [s] through every part at
    its own step (:func:`~mappings.lava.loihi.run_trains`); one result per train, counts only,
    ``info["dt"]`` each sPLL's step [s]."""
    trains = list(trains)
    tde = np.zeros((len(trains), clocked.n_spll), np.int64)
    cco = np.zeros_like(tde)
    for part in clocked.parts:
        for b, res in enumerate(run_trains(part.params, trains, duration, backend)):
            tde[b, part.spll], cco[b, part.spll] = res.tde_counts, res.cco_counts
    steps = clocked.steps.tolist()
    return [
        SimulationResult(tde_counts=t, cco_counts=c, duration=duration, backend=backend,
                         info={"dt": steps})
        for t, c in zip(tde, cco, strict=True)
    ]  # fmt: skip
