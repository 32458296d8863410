"""Loihi's LIF and Dense arithmetic in numpy: the bit-accurate executor of the standard sPLL
on Lava's own processes (:mod:`mappings.lava.standard`), what ``standard-fixed-point`` runs.

**Step** ``t = 1, 2, ...`` (Lava's ``LoihiProtocol``): every ``Dense`` delivers what it received
at ``t - 1``; every LIF updates ``u <- sgn(u) (|u| (4096 - du - 1) >> 12) + (a_in << 6)`` (wrapping
at 24 bits), ``v <- clip(sgn(v) (|v| (4096 - dv) >> 12) + u + bias, ±(2^23 - 1))``, spikes if
``v > vth << 6`` and resets ``v`` to 0. The input spike count of step ``k`` (a spike at ``t``
counts in ``max(1, ceil(t/dt))``) reaches the level neurons at step ``k + 1``; a spike between
neurons arrives one step later, so a CCO spike's trigger reaches the TDE two steps after it.
:func:`simulate_fixed` is this arithmetic in numpy, the project's bit-accurate reference of
what Lava (``PyLifModelBitAcc``, ``PyDenseModelBitAcc``) computes; the exported ``run.py``
runs Lava itself, and ``tests/test_standard_lava.py`` checks the two agree spike for spike.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from spll_hw.result import SimulationResult

if TYPE_CHECKING:
    from .standard import LavaStandard

#: Loihi word limits.
A_IN_MAX = 2**15 - 1
UV_MAX = 2**23
DECAY_BITS = 12
DECAY_UNITY = 2**DECAY_BITS


def simulate_fixed(
    params: LavaStandard, counts: np.ndarray, record_spikes: bool = False
) -> dict[str, np.ndarray]:
    """Lava's bit-accurate arithmetic of ``params`` in numpy (the module docstring's step).

    Args:
        params: the integers (:func:`~mappings.lava.standard.lava_standard`).
        counts: input spike count per step and sample, shape ``(T, B)`` (step ``k`` is row
            ``k - 1``).
        record_spikes: also return the spike rasters.

    Returns:
        ``tde_counts``, ``cco_counts`` of shape ``(B, N)``; with ``record_spikes`` also
        ``POP_raster`` of every population, shape ``(T, B, size)``, and ``tde_raster``,
        ``cco_raster`` of the whole network, shape ``(T, B, N)`` (bool).
    """
    counts = np.asarray(counts, dtype=np.int64)
    n_steps, batch = counts.shape
    lif = params.lif
    pops = list(lif)
    sizes = {pop: lif[pop]["bias_mant"].shape[0] for pop in pops}
    bias = {
        pop: np.where(
            lif[pop]["bias_exp"] >= 0,
            lif[pop]["bias_mant"] << np.maximum(lif[pop]["bias_exp"], 0),
            lif[pop]["bias_mant"] >> np.maximum(-lif[pop]["bias_exp"], 0),
        )
        for pop in pops
    }
    u = {pop: np.zeros((batch, sizes[pop]), np.int64) for pop in pops}
    v = {pop: np.zeros((batch, sizes[pop]), np.int64) for pop in pops}
    spikes = {pop: np.zeros((batch, sizes[pop]), np.int64) for pop in pops}
    # The weights are sparse (a few per row): CSR integer matrices, exact and fast.
    from scipy.sparse import csr_matrix

    dense = [(src, dst, csr_matrix(np.asarray(w, np.int64)), e)
             for src, dst, w, e, _ in params.dense.values()]  # fmt: skip
    n = params.n_spll
    # Where each TDE / CCO population's neurons go in the network's (N,) vectors.
    parts = {part: [(pop, params.members[pop]) for pop in pops if pop.startswith(part)]
             for part in ("tde", "cco")}  # fmt: skip
    totals = {part: np.zeros((batch, n), np.int64) for part in parts}
    rasters = {pop: [] for pop in pops} if record_spikes else None
    for t in range(n_steps):
        # Dense: what its source sent at the previous step (the source's step t - 1 output;
        # for the generator, the count of step t - 1), weighted and shifted.
        a_in = {pop: np.zeros((batch, sizes[pop]), np.int64) for pop in pops}
        for src, dst, w, e in dense:
            if src == "input":
                if t == 0:
                    continue
                s = counts[t - 1][:, None]
            else:
                s = spikes[src]
            if not s.any():
                continue
            acc = np.asarray(w @ s.T).T.astype(np.int64)
            a_in[dst] += acc << e if e > 0 else acc >> -e
        for pop in pops:
            p = lif[pop]
            a = a_in[pop].astype(np.int16).astype(np.int64)  # a_in is a 16-bit port
            uu = _decay(u[pop], DECAY_UNITY - p["du"] - 1) + (a << 6)
            uu = np.where(uu > UV_MAX, uu - 2 * UV_MAX, uu)
            uu = np.where(uu <= -UV_MAX, uu + 2 * UV_MAX, uu)
            u[pop] = uu
            vv = _decay(v[pop], DECAY_UNITY - p["dv"]) + uu + bias[pop]
            vv = np.clip(vv, -UV_MAX + 1, UV_MAX - 1)
            fired = vv > (p["vth"] << 6)
            vv[fired] = 0
            v[pop] = vv
            spikes[pop] = fired.astype(np.int64)
        for part, members in parts.items():
            for pop, idx in members:
                totals[part][:, idx] += spikes[pop]
        if rasters is not None:
            for pop in pops:
                rasters[pop].append(spikes[pop].astype(bool))
    out = {"tde_counts": totals["tde"], "cco_counts": totals["cco"]}
    if rasters is not None:
        out.update({f"{pop}_raster": np.array(r) for pop, r in rasters.items()})
        for part, members in parts.items():
            whole = np.zeros((n_steps, batch, n), dtype=bool)
            for pop, idx in members:
                whole[:, :, idx] = out[f"{pop}_raster"]
            out[f"{part}_raster"] = whole
    return out


def _decay(x: np.ndarray, keep: int) -> np.ndarray:
    """Loihi's decay: ``sgn(x) (|x| keep >> 12)`` (truncation toward zero)."""
    return np.sign(x) * ((np.abs(x) * keep) >> 12)


def results_from(
    out: dict, duration: float, dt: float, backend: str, record_spikes: bool
) -> list[SimulationResult]:
    """One :class:`SimulationResult` per sample of :func:`simulate_fixed`'s (or Lava's)
    output; a spike in step ``k`` is reported at ``k dt``."""
    results = []
    for b in range(out["tde_counts"].shape[0]):
        res = SimulationResult(
            tde_counts=np.asarray(out["tde_counts"][b], dtype=np.int64),
            cco_counts=np.asarray(out["cco_counts"][b], dtype=np.int64),
            duration=duration,
            backend=backend,
            info={"dt": dt},
        )
        if record_spikes and "tde_raster" in out:
            t = (np.arange(out["tde_raster"].shape[0]) + 1) * dt
            res.tde_spikes = [t[out["tde_raster"][:, b, i]] for i in range(res.n_spll)]
            res.cco_spikes = [t[out["cco_raster"][:, b, i]] for i in range(res.n_spll)]
        results.append(res)
    return results
