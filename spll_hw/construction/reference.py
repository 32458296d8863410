"""A fine-clocked reference of the standard sPLL: what the construction itself costs.

This is a **clocked** simulator with **exact integration between steps**, not an event-driven
one. Every step of length ``dt`` advances each state by the exact solution of its linear ODE
(thesis eqs. 1-5) over the step; threshold crossings are detected at the step's end, where the
neuron fires, is reset to 0 and held there for ``round(t_refr / dt)`` steps (``hold="grid"``,
the clocked models' and Loihi's rule) or ``round(t_refr / dt - 1/2)`` (``hold="compensated"``,
the NIR graph's :func:`~spll_hw.model.holds.compensated_hold`: a spike detected at
its step's end is on average half a step late) or ``floor(h)`` or ``floor(h) + 1`` steps,
``h = t_refr / dt - 1/2``, the extra step whenever the neuron's running sum of ``h - floor(h)``
over its spikes reaches 1 (``hold="dithered"``, :class:`DitheredHold`: error diffusion, so the
mean hold is ``h``, what a clocked neuron with an accumulator could do); its currents keep
decaying (steps, arrivals and propagators are :mod:`spll_hw.model.grid` and
:mod:`spll_hw.model.discrete`). Then the step's spikes are delivered, as in the golden model
(all states advance, then all spikes are delivered): a CCO spike adds ``g_tde_trg *
gate(I_fac)`` to its TDE's trigger current with ``I_fac`` as it stood before this step's input
spikes, a TDE spike adds ``g_cco`` to its CCO's current, and the step's input spikes (those in
``((k-1) dt, k dt]``) add ``g_tde_fac`` each to every ``I_fac``. So its only errors against
the golden model are the time grid (spikes on step ends) and, with a K-level gate, the gate's
staircase. With ``gate=None`` the gate is the golden product ``I_fac`` itself: the grid's own
error, which ``dt -> 0`` removes.

The level and AND neurons of the K-level gate (:mod:`spll_hw.construction.gate`) are
comparators that respond within one step, so at this resolution they are exactly the
staircase: on a CCO spike, level k is active iff ``I_fac > thresholds[k]``, and its AND neuron
fires in the same step. The reference evaluates the staircase directly.

All rows of a batch run in one vectorised loop (``numpy``), so many samples and many gate
variants cost little more than one: a 2 s run at ``dt = 5 µs`` (400 000 steps) takes about
20-60 s for a batch of hundreds of sPLL rows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from spll_hw.model.discrete import exact_propagator, membrane_gain
from spll_hw.model.grid import arrival_counts
from spll_hw.model.grid import n_steps as step_count
from spll_hw.model.holds import HOLDS, DitheredHold
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES
from spll_hw.result import SimulationResult

from .gate import Gate

#: Default step [s] of the reference (1/250 of the reference workload's shortest time
#: constant, tau_tde_trg = 1.25 ms).
DEFAULT_DT = 5e-6
#: Largest number of steps of one call.
MAX_STEPS = 50_000_000


def _checked_steps(
    network: Network, duration: float, gates: Sequence[Gate | None], dt: float, hold: str
) -> int:
    """The steps of a reference run (:func:`simulate_reference`'s arguments); ``ValueError``
    naming the argument that cannot be run (an unknown hold, a step or duration that is not a
    finite time > 0, too many steps, a gate of another number of sPLLs)."""
    if hold not in HOLDS:
        raise ValueError(f"reference hold must be one of {tuple(HOLDS)}, got {hold!r}")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"reference dt must be a finite time > 0 s, got {dt!r}")
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0 s, got {duration!r}")
    n_steps = step_count(duration, dt)
    if n_steps > MAX_STEPS:
        raise ValueError(f"{n_steps} steps exceed the reference's limit {MAX_STEPS}; larger dt")
    for g in gates:
        if g is not None and g.thresholds.shape[0] != network.n_spll:
            raise ValueError(
                f"gate has {g.thresholds.shape[0]} sPLLs, the network {network.n_spll}"
            )
    return n_steps


def simulate_reference(
    network: Network,
    trains: Sequence[np.ndarray],
    duration: float,
    gates: Sequence[Gate | None] = (None,),
    dt: float = DEFAULT_DT,
    hold: str = "grid",
) -> list[list[SimulationResult]]:
    """Simulate every train through ``network`` with every gate, on one fine clock.

    Args:
        network: the sPLL network (N sPLLs).
        trains: sorted input spike times [s] per sample, each 1-D; spikes after ``duration``
            are not delivered.
        duration: run length [s] (``round(duration / dt)`` steps).
        gates: the gates to compare: a :class:`Gate` of shape ``(N, K)`` (K may differ between
            gates) or ``None`` for the golden product.
        dt: time step [s].
        hold: the refractory hold, one of :data:`HOLDS` (module docstring).

    Returns:
        ``results[g][s]``: the :class:`SimulationResult` (counts only) of gate ``g`` on sample
        ``s``; ``info`` has ``dt``, ``hold`` and ``gate_levels`` (K, or 0 for the golden
        product).
    """
    n_steps = _checked_steps(network, duration, gates, dt, hold)
    n, n_s, n_g = network.n_spll, len(trains), len(gates)
    p = {name: network.matrix()[:, j] for j, name in enumerate(PARAM_NAMES)}
    rows = n_g * n_s  # batch row = (gate, sample); every row holds N sPLLs

    # Input spikes per step (row k = step k, row 0 unused) and sample.
    counts = np.zeros((n_steps + 1, n_s), dtype=np.int32)
    for s, x in enumerate(trains):
        counts[1:, s] = arrival_counts(x, n_steps, dt)
    sample_of_row = np.tile(np.arange(n_s), n_g)

    # Exact one-step propagators, each part's parameters named by the model's tables.
    r = roles()
    e_fac = np.exp(-dt / p[r.fac.tau])
    e_trg, k_tde, e_tde = exact_propagator(p[r.trg.tau], p[r.tde.tau], p[r.tde.c], dt)
    e_cs, k_cco, e_cco = exact_propagator(p[r.cco_syn.tau], p[r.cco.tau], p[r.cco.c], dt)
    b_cco = p[r.offset] * membrane_gain(p[r.cco.tau], p[r.cco.c], dt)
    shape = (rows, n)
    hold_tde = DitheredHold(HOLDS[hold](p[r.tde.t_refr], dt), shape)
    hold_cco = DitheredHold(HOLDS[hold](p[r.cco.t_refr], dt), shape)
    thr_tde, thr_cco = p[r.tde.v_thr], p[r.cco.v_thr]

    # Gates padded to the largest K (threshold +inf never fires); golden rows flagged.
    k_max = max([g.n_levels for g in gates if g is not None] + [1])
    thresholds = np.full((rows, n, k_max), np.inf)
    increments = np.zeros((rows, n, k_max))
    golden = np.zeros((rows, n), dtype=bool)
    for gi, g in enumerate(gates):
        sl = slice(gi * n_s, (gi + 1) * n_s)
        if g is None:
            golden[sl] = True
        else:
            thresholds[sl, :, : g.n_levels] = g.thresholds
            increments[sl, :, : g.n_levels] = g.increments

    i_fac, i_trg, v_tde, i_cco, v_cco = (np.zeros(shape) for _ in range(5))
    refr_tde = np.zeros(shape, dtype=np.int64)
    refr_cco = np.zeros(shape, dtype=np.int64)
    n_tde = np.zeros(shape, dtype=np.int64)
    n_cco = np.zeros(shape, dtype=np.int64)
    g_fac, g_trg, g_cco = p[r.driven.gain], p[r.gated.gain], p[r.fed.gain]
    for step in range(1, n_steps + 1):
        # Advance every state over the step (membranes held at 0 while refractory).
        free_tde = refr_tde == 0
        free_cco = refr_cco == 0
        v_tde = np.where(free_tde, v_tde * e_tde + i_trg * k_tde, 0.0)
        v_cco = np.where(free_cco, v_cco * e_cco + i_cco * k_cco + b_cco, 0.0)
        refr_tde -= ~free_tde
        refr_cco -= ~free_cco
        i_trg *= e_trg
        i_cco *= e_cs
        i_fac *= e_fac
        # Threshold crossings at the step's end.
        tde_spike = v_tde >= thr_tde
        cco_spike = v_cco >= thr_cco
        if tde_spike.any():
            v_tde[tde_spike] = 0.0
            refr_tde = np.where(tde_spike, hold_tde.after(tde_spike), refr_tde)
            n_tde += tde_spike
            i_cco += tde_spike * g_cco
        if cco_spike.any():
            v_cco[cco_spike] = 0.0
            refr_cco = np.where(cco_spike, hold_cco.after(cco_spike), refr_cco)
            n_cco += cco_spike
            r, c = np.nonzero(cco_spike)
            x = i_fac[r, c]
            gated = np.where(
                golden[r, c],
                x,
                np.where(x[:, None] > thresholds[r, c], increments[r, c], 0.0).sum(axis=1),
            )
            i_trg[r, c] += g_trg[c] * gated
        arrivals = counts[step]
        if arrivals.any():
            i_fac += arrivals[sample_of_row][:, None] * g_fac

    out = []
    for gi, g in enumerate(gates):
        row = []
        for s in range(n_s):
            b = gi * n_s + s
            row.append(
                SimulationResult(
                    tde_counts=n_tde[b].copy(),
                    cco_counts=n_cco[b].copy(),
                    duration=duration,
                    backend="standard-reference",
                    info={
                        "dt": dt,
                        "hold": hold,
                        "gate_levels": 0 if g is None else g.n_levels,
                        "sample": int(sample_of_row[b]),
                    },
                )
            )
        out.append(row)
    return out
