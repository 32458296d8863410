"""Loihi's LIF and Dense arithmetic: the bit-accurate executor of the standard sPLL
on Lava's own processes (:mod:`mappings.lava.standard`), what ``standard-fixed-point`` runs.

**Step** ``t = 1, 2, ...`` (Lava's ``LoihiProtocol``): every ``Dense`` delivers what it received
at ``t - 1``; every LIF updates ``u <- sgn(u) (|u| (4096 - du - 1) >> 12) + (a_in << 6)`` (wrapping
at 24 bits), ``v <- clip(sgn(v) (|v| (4096 - dv) >> 12) + u + bias, ±(2^23 - 1))``, spikes if
``v > vth << 6`` and resets ``v`` to 0; a ``GradedVec`` (a population marked ``graded``,
:mod:`mappings.lava.graded_current`) sends its ``a_in`` (24 bits, no wrap at 16) as a graded
spike, which a ``Dense`` weighs and shifts as it does a count of spikes. A TDE or CCO emits
its spike unless its refractory unit's hold neuron (population ``hold_tde*`` /
``hold_cco*``) fires in the same step. The input spike count of step ``k`` (a spike at ``t``
counts in ``max(1, ceil(t/dt))``) reaches the level neurons at step ``k + 1``; a spike
between neurons arrives one step later, so a CCO spike's trigger reaches the TDE two steps
after it.
:func:`simulate_fixed` is this arithmetic in the Rust core (``engine/src/loihi.rs``), the
project's bit-accurate reference of what Lava (``PyLifModelBitAcc``, ``PyDenseModelBitAcc``)
computes; the exported ``run.py`` runs Lava itself, and ``tests/test_standard_lava.py`` checks
the two agree spike for spike (``tests/loihi_reference.py`` states the step in numpy, and
``tests/test_loihi_engine.py`` checks the core against it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix

from spll_hw import _engine
from spll_hw.model import grid
from spll_hw.neuron_graph import COUNTS_KEY
from spll_hw.result import SimulationResult

if TYPE_CHECKING:
    from .standard import LavaStandard

#: Loihi word limits.
A_IN_MAX = 2**15 - 1
UV_MAX = 2**23
DECAY_BITS = 12
DECAY_UNITY = 2**DECAY_BITS


def simulate_fixed(
    params: LavaStandard,
    counts: np.ndarray,
    record_spikes: bool = False,
    threads: int | None = None,
) -> dict[str, np.ndarray]:
    """Lava's bit-accurate arithmetic of ``params`` (the module docstring's step), run by the
    Rust core (``spll_hw._engine.simulate_loihi``, the samples in parallel, the GIL released).

    Args:
        params: the integers (:func:`~mappings.lava.standard.lava_standard`).
        counts: input spike count per step and sample, shape ``(T, B)`` (step ``k`` is row
            ``k - 1``).
        record_spikes: also return the spike rasters.
        threads: threads for the samples (``None``: one per core).

    Returns:
        ``tde_counts``, ``cco_counts`` of shape ``(B, N)``, ``neuron_counts`` (the spikes of
        every neuron, a ``GradedVec``'s steps with a value sent, shape ``(B, size)`` in the
        order of ``params.lif``, :func:`mappings.lava.neuron_graph.lava_graph`'s); with
        ``record_spikes`` also
        ``POP_raster`` of every population, shape ``(T, B, size)``, and ``tde_raster``,
        ``cco_raster`` of the whole network, shape ``(T, B, N)`` (bool).
    """
    counts = np.ascontiguousarray(counts, dtype=np.int64)
    if counts.ndim != 2:
        raise ValueError(f"counts must have shape (steps, samples), got {counts.shape}")
    net = _Merged(params)
    ran = _engine.simulate_loihi(*net.engine_arrays(), counts, record_spikes, threads)
    sent = ran["sent"]
    totals = net.totals(sent, ran["held"])
    out = {"tde_counts": totals["tde"], "cco_counts": totals["cco"], "neuron_counts": sent}
    if record_spikes:
        raster = ran["raster"].transpose(1, 0, 2)  # (T, B, size)
        for pop, cols in net.columns.items():
            out[f"{pop}_raster"] = raster[:, :, cols]
        for part in totals:
            out[f"{part}_raster"] = net.output(part, raster)
    return out


class _Merged:
    """Every population of ``params`` as one vector of neurons (in the order of
    ``params.lif``), each with its population's decays, threshold and its own bias, and every
    ``Dense`` between them as one sparse integer matrix on that vector: a weight with exponent
    ``e >= 0`` is ``w << e`` (a left shift of the accumulated sum is one of each weight); one
    with ``e < 0`` keeps its own matrix, its sum shifted right (:attr:`shifted`), as does each
    ``Dense`` from the input (:attr:`inputs`)."""

    def __init__(self, params: LavaStandard) -> None:
        lif = params.lif
        sizes = [lif[pop]["bias_mant"].shape[0] for pop in lif]
        start = dict(zip(lif, np.cumsum([0, *sizes[:-1]]), strict=True))
        self.size = int(sum(sizes))
        self.columns = {pop: start[pop] + np.arange(k) for pop, k in zip(lif, sizes, strict=True)}
        per_neuron = lambda key: np.concatenate(  # noqa: E731
            [np.full(k, int(lif[pop][key]), np.int64) for pop, k in zip(lif, sizes, strict=True)]
        )
        self.keep_u = DECAY_UNITY - per_neuron("du") - 1
        self.keep_v = DECAY_UNITY - per_neuron("dv")
        self.threshold = per_neuron("vth") << 6
        # GradedVec neurons (a graded current): no LIF state; they send what they receive.
        self.graded = np.concatenate(
            [self.columns[pop] for pop in lif if is_graded(lif[pop])] or [[]]
        ).astype(np.int64)
        mant = np.concatenate([np.asarray(lif[pop]["bias_mant"], np.int64) for pop in lif])
        exp = np.concatenate([np.asarray(lif[pop]["bias_exp"], np.int64) for pop in lif])
        self.bias = np.where(exp >= 0, mant << np.maximum(exp, 0), mant >> np.maximum(-exp, 0))
        self.inputs = []  # (target neurons, weights, exponent) of each Dense from the input
        # The same, summed into one weight per neuron where e >= 0 (the count times w << e),
        # those with e < 0 apart (their products shifted right).
        self.input_weights = np.zeros(self.size, np.int64)
        self.input_shifted = []
        rows, cols, values, self.shifted = [], [], [], []
        for src, dst, w, e, _ in params.dense.values():
            w = np.asarray(w, np.int64)
            e = int(e)
            if src == "input":  # graded: the step's count times the weight
                self.inputs.append((self.columns[dst], w[:, 0], e))
                if e >= 0:
                    np.add.at(self.input_weights, self.columns[dst], w[:, 0] << e)
                else:
                    self.input_shifted.append((self.columns[dst], w[:, 0], e))
                continue
            r, c = np.nonzero(w)
            if e < 0:
                m = coo_matrix((w[r, c], (self.columns[dst][r], self.columns[src][c])),
                               shape=(self.size, self.size))  # fmt: skip
                self.shifted.append((csr_matrix(m), e))
                continue
            rows.append(self.columns[dst][r])
            cols.append(self.columns[src][c])
            values.append(w[r, c] << e)
        if rows:
            m = coo_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(self.size, self.size))  # fmt: skip
        else:
            m = coo_matrix((self.size, self.size), dtype=np.int64)
        self.w = csr_matrix(m)  # duplicates (two Dense between the same neurons) are summed
        # Where each TDE / CCO population's neurons go in the network's (N,) vectors, and
        # those of their refractory units' hold neurons (whose spikes mark the held steps).
        self.n_spll = params.n_spll
        self.parts = {}
        for part in ("tde", "cco"):
            self.parts[part] = tuple(
                self._gather(params, [pop for pop in lif if pop.startswith(prefix)])
                for prefix in (part, f"hold_{part}")
            )

        # Each sPLL's TDE (CCO) neuron and its hold neuron, where it has one: a spike of both
        # in one step is not emitted (:meth:`output`), shape (2, pairs).
        self.held_pairs = np.concatenate(
            [self._pairs(*self.parts[part]) for part in ("tde", "cco")], axis=1
        )

    def engine_arrays(self) -> tuple:
        """The arguments of ``_engine.simulate_loihi`` before the counts: the per-neuron
        vectors, the shifted inputs ``(neurons, weights, shift)``, every matrix by source
        column ``(starts, rows, weights, shift)`` and the held pairs."""
        matrices = [(self.w, 0)] + [(w, -e) for w, e in self.shifted]
        by_column = []
        for m, shift in matrices:
            c = m.tocsc()
            c.sum_duplicates()
            by_column.append(
                (c.indptr.astype(np.int64), c.indices.astype(np.int64),
                 c.data.astype(np.int64), int(shift))
            )  # fmt: skip
        graded = np.zeros(self.size, np.int64)
        graded[self.graded] = 1
        return (
            self.keep_u, self.keep_v, self.threshold, self.bias.astype(np.int64), graded,
            self.input_weights,
            [(np.asarray(cols, np.int64), np.asarray(w, np.int64), -e)
             for cols, w, e in self.input_shifted],
            by_column,
            np.ascontiguousarray(self.held_pairs, dtype=np.int64),
        )  # fmt: skip

    def _pairs(self, neurons, holds) -> np.ndarray:
        """The columns ``(neuron, its hold)`` of every sPLL that ``neurons`` (columns, sPLLs)
        and ``holds`` both have, as :meth:`output` pairs them (the last of either), shape
        ``(2, pairs)``."""
        neuron = np.full(self.n_spll, -1, np.int64)
        hold = np.full(self.n_spll, -1, np.int64)
        neuron[neurons[1]], hold[holds[1]] = neurons[0], holds[0]
        both = (neuron >= 0) & (hold >= 0)
        return np.stack([neuron[both], hold[both]])

    def totals(self, sent: np.ndarray, held: np.ndarray) -> dict[str, np.ndarray]:
        """The spikes the network's TDEs and CCOs emit, ``{"tde": (B, N), "cco": (B, N)}``,
        from every neuron's spike count ``sent`` (B, size) less, for a neuron with a hold, the
        steps both spiked, ``held`` (B, pairs) in the order of :attr:`held_pairs`."""
        emitted = sent.copy()
        np.subtract.at(emitted.T, self.held_pairs[0], held.T)
        emitted[:, self.graded] = 0  # a GradedVec's sends are no spikes
        totals = {}
        for part in ("tde", "cco"):
            cols, members = self.parts[part][0]
            totals[part] = np.zeros((sent.shape[0], self.n_spll), np.int64)
            last = np.full(self.n_spll, -1, np.int64)
            last[members] = cols  # as output's assignment, the last neuron of an sPLL
            has = last >= 0
            totals[part][:, has] = emitted[:, last[has]]
        return totals

    def _gather(self, params: LavaStandard, pops: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """The columns of ``pops`` and the sPLLs their neurons stand for."""
        if not pops:
            return np.zeros(0, np.int64), np.zeros(0, np.int64)
        return (
            np.concatenate([self.columns[pop] for pop in pops]),
            np.concatenate([np.asarray(params.members[pop]) for pop in pops]),
        )

    def output(self, part: str, fired: np.ndarray) -> np.ndarray:
        """The spikes of the TDEs or CCOs (``part``) that the network emits, shape
        ``fired.shape[:-1] + (N,)``, from the spikes of every neuron ``fired`` (last axis the
        merged vector): a neuron's spike in a step its refractory unit holds it is not one."""
        (cols, members), (held_cols, held_members) = self.parts[part]
        out = np.zeros((*fired.shape[:-1], self.n_spll), dtype=bool)
        out[..., members] = fired[..., cols]
        out[..., held_members] &= ~fired[..., held_cols]
        return out


def is_graded(population: dict) -> bool:
    """Whether a population of :class:`~mappings.lava.standard.LavaStandard`'s ``lif`` is a
    ``GradedVec`` (marked ``graded``, :mod:`mappings.lava.graded_current`), not a LIF."""
    return bool(int(population.get("graded", 0)))


#: Largest weight :func:`split_weight` writes (15 bits).
SPLIT_MAX = (255 << 7) | 127


def split_weight(value):
    """A weight of up to 15 bits (int or int array, ``0..``:data:`SPLIT_MAX`) as Loihi's 8-bit
    weights of two ``Dense`` at exponents 7 and 0, ``((7, value >> 7), (0, value & 127))``,
    whose sum is ``value`` exactly."""
    return (7, value >> 7), (0, value & 127)


def most_kicks(keep, gap) -> np.ndarray:
    """The most kicks a current decaying by ``keep / 4096`` a step holds at once, kicked at
    most once every ``gap`` steps: ``1 / (1 - (keep / 4096)^gap)`` (arrays broadcast)."""
    kept = np.asarray(keep, dtype=np.float64) / DECAY_UNITY
    return 1.0 / (1.0 - kept ** np.asarray(gap, dtype=np.float64))


def _decay(x: np.ndarray, keep) -> np.ndarray:
    """Loihi's decay: ``sgn(x) (|x| keep >> 12)`` (truncation toward zero), as the floor of
    ``x keep / 4096`` rounded up where the product is negative (``keep`` an int or an array
    that broadcasts)."""
    p = x * keep
    return (p + ((p >> 63) & (DECAY_UNITY - 1))) >> DECAY_BITS


def kept_charge(kick: np.ndarray, delta: np.ndarray, max_steps: int = 1 << 20) -> np.ndarray:
    """The fraction of its charge that a lone kick of ``kick`` units of ``u`` (int, >= 0)
    delivers to the membrane under Loihi's decay by ``delta / 4096`` a step (``delta`` >= 1,
    the shape of ``kick``): the sum of ``u`` over the steps until it is 0 (truncated to whole
    units each step, :func:`_decay`), against ``kick 4096 / delta``, the exact decay's. Near 1
    where ``kick delta / 4096`` is many units a step; where it is under 1 the kick loses at
    least a unit a step and lasts ``kick`` steps instead of ``4096 / delta``."""
    u = np.asarray(kick, dtype=np.int64).copy()
    delta = np.asarray(delta, dtype=np.int64)
    total = np.zeros(u.shape)
    for _ in range(max_steps):
        if not u.any():
            break
        total += u
        u = _decay(u, DECAY_UNITY - delta)
    exact = np.asarray(kick, dtype=float) * DECAY_UNITY / delta
    return np.divide(total, exact, out=np.ones(u.shape), where=exact > 0)


def run_trains(
    params: LavaStandard, trains, duration: float, backend: str, record_spikes: bool = False
) -> list[SimulationResult]:
    """:func:`simulate_fixed` of every train (sorted input spike times [s]) for ``duration``
    [s], the input binned by the model's grid; one result per train."""
    steps = grid.n_steps(duration, params.dt)
    counts = np.stack([grid.arrival_counts(x, steps, params.dt) for x in trains], axis=1)
    out = simulate_fixed(params, counts, record_spikes=record_spikes)
    return results_from(out, duration, params.dt, backend, record_spikes)


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
        if "neuron_counts" in out:
            res.info[COUNTS_KEY] = np.asarray(out["neuron_counts"][b], dtype=np.int64)
        if record_spikes and "tde_raster" in out:
            t = (np.arange(out["tde_raster"].shape[0]) + 1) * dt
            res.tde_spikes = [t[out["tde_raster"][:, b, i]] for i in range(res.n_spll)]
            res.cco_spikes = [t[out["cco_raster"][:, b, i]] for i in range(res.n_spll)]
        results.append(res)
    return results
