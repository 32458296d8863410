"""The sPLL from standard neurons: the multiplicative gate as a K-level multiplier.

The golden TDE multiplies at run time: at each CCO spike ``I_trg += g_trg * I_fac(t-)``. No
standard neuron (LIF, CubaLIF, LI, IF) and no fixed synapse multiplies two run-time quantities,
so the standard sPLL replaces the product by a staircase of K levels::

    I_trg += g_trg * q(I_fac(t-)),   q(x) = sum_k increments[k] * [x > thresholds[k]]

built from two kinds of standard neurons per level k and sPLL:

* **level neuron** k: a CubaLIF whose synaptic current is a copy of ``I_fac`` scaled by
  ``1 / thresholds[k]`` (time constant ``tau_tde_fac``, input weight ``g_tde_fac /
  thresholds[k]``) and whose membrane follows that current within one step (membrane time
  constant = the time step, threshold 1). It fires on every step while
  ``I_fac > thresholds[k]``: a comparator. Its reset only clears the membrane, never the copy.
* **AND neuron** k: a memoryless LIF (time constant = the time step, threshold 1.5) fed by level
  neuron k and the sPLL's CCO with weight 1 each. It fires only on a step in which both fire:
  the coincidence of a CCO spike with ``I_fac`` above level k. Its spike adds
  ``g_trg * increments[k]`` to the TDE's trigger current through a fixed synapse.

The error of the staircase falls with K. Where the levels go is a choice (:func:`gate_levels`):
``"uniform"`` (equal steps up to a high quantile of ``I_fac``), ``"quantile"`` (each level at a
quantile of ``I_fac``'s distribution, so every bin is equally likely) or ``"band-quantile"``
(the same over the network's band: the mixture of ``I_fac``'s distributions at rates from the
network's lowest to its highest free-running frequency); all reconstruct a bin by the
conditional mean of ``I_fac`` in it. The distribution is that of ``I_fac`` under Poisson input
at the expected rate (``input_rate``, or the band's rates), which depends on ``g_tde_fac``,
``tau_tde_fac`` and the rates only, so the levels need no simulation of the network. Levels
placed for one rate are coarse where the input is much slower: on a slow sPLL (``tau_tde_fac``
31 ms) driven at 32 Hz, ``I_fac`` at the CCO's spikes stays within one uniform 300-Hz level, so
the gate passes no phase (docs/backends.md). ``benchmarks/bench_standard.py`` measures the
placements (the table in docs/backends.md).

Everything else of the sPLL is standard already: the CCO is a CubaLIF with a bias (its offset
current), the TDE a CubaLIF whose synaptic current is ``I_trg``. Where a target has refractory
periods they are used as they are; where it has none (NIR; Lava's LIF in fixed point), a
refractory unit of standard neurons holds each TDE and CCO for its refractory steps
(:class:`RefractoryTimers` for NIR; Lava's integer one in :mod:`mappings.lava.integers`). The
former stand-in, a self-inhibition by the charge the hold at 0 would have cost
(:func:`inhibition_weights`), remains NIR's ``refractory="self-inhibition"``.

The targets build their graphs from this module: :mod:`mappings.nir.standard` (NIR of standard
nodes) and :mod:`mappings.lava.standard` (Lava's own LIF and Dense in Loihi's integers); both
check the network and time step with :func:`target_parameters`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.signal import lfilter

from spll_hw.model.holds import compensated_hold
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES
from spll_hw.simulate import poisson_spikes, simulate

#: Level placements :func:`gate_levels` knows.
PLACEMENTS = ("uniform", "quantile", "band-quantile")
#: Input rate [Hz] the levels are placed for when none is given (the reference workload's).
DEFAULT_INPUT_RATE = 300.0
#: Default number of levels.
DEFAULT_LEVELS = 8
#: Default placement (the better one on the reference workload, table in docs/backends.md).
DEFAULT_PLACEMENT = "uniform"
#: Upper quantile of I_fac the uniform placement spans.
UNIFORM_TOP_QUANTILE = 0.999
#: Largest K accepted (each level costs 2 neurons per sPLL).
MAX_LEVELS = 256
#: Poisson rates, geometrically spaced over the network's free-running frequencies, whose
#: mixture of ``I_fac`` distributions the ``"band-quantile"`` placement places its levels on.
BAND_RATES = 5


@dataclass(frozen=True)
class Gate:
    """The K-level multiplier of every sPLL of a network.

    Attributes:
        thresholds: level thresholds on ``I_fac`` [A], shape ``(N, K)``, strictly increasing and
            > 0 per row.
        increments: what each active level adds to the gated value [A], shape ``(N, K)``, > 0:
            the trigger current jumps by ``g_tde_trg * increments[i, k]`` per active level.
        placement: how the levels were placed (one of :data:`PLACEMENTS` or ``"custom"``).
        input_rates: the Poisson input rates [Hz] they were placed for (one for ``"uniform"``
            and ``"quantile"``, up to :data:`BAND_RATES` for ``"band-quantile"``, none for custom
            levels).
    """

    thresholds: np.ndarray
    increments: np.ndarray
    placement: str = "custom"
    input_rates: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        t = np.array(self.thresholds, dtype=float)
        d = np.array(self.increments, dtype=float)
        if t.ndim != 2 or t.shape != d.shape or t.shape[1] < 1:
            raise ValueError(
                f"gate thresholds and increments must both have shape (N, K), K >= 1; got "
                f"{t.shape} and {d.shape}"
            )
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(d))):
            raise ValueError("gate thresholds and increments must be finite")
        if np.any(t <= 0) or np.any(np.diff(t, axis=1) <= 0):
            raise ValueError("gate thresholds must be > 0 and strictly increasing per sPLL")
        if np.any(d <= 0):
            raise ValueError("gate increments must be > 0")
        t.setflags(write=False)
        d.setflags(write=False)
        object.__setattr__(self, "thresholds", t)
        object.__setattr__(self, "increments", d)

    @property
    def n_levels(self) -> int:
        return int(self.thresholds.shape[1])

    def __call__(self, i_fac: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """The staircase ``q(i_fac)`` [A] of the sPLLs ``rows`` (all when ``None``); ``i_fac``
        has shape ``(len(rows),)`` (or ``(N,)``)."""
        t = self.thresholds if rows is None else self.thresholds[rows]
        d = self.increments if rows is None else self.increments[rows]
        active = np.asarray(i_fac, dtype=float)[:, None] > t
        return np.where(active, d, 0.0).sum(axis=1)


class GateLayout(NamedTuple):
    """Where clocked targets put the gate's neurons of N sPLLs with K levels
    (:func:`gate_layout`): one population of ``size = M + 6N`` memoryless neurons
    (``M + 2N`` without timers), ``M = N K``.

    Rows ``0..M-1`` are the AND neurons (level k of sPLL i at row ``i K + k``); rows
    ``M..M+N-1`` (``relay_tde``) relay each TDE's spike and rows ``M+N..M+2N-1``
    (``relay_cco``) each CCO's. A relay fires whenever its source did, so the source's spike
    reaches other neurons (a TDE's ``g_cco`` to its CCO) and its own refractory unit through
    the population's outgoing synapses. Rows ``refr_a`` and ``refr_b`` (``2N`` each, the N
    TDEs' then the N CCOs', :class:`RefractoryTimers`) relay the two timers of each refractory
    unit. ``spll_of_and``: the sPLL of each AND neuron, shape ``(M,)``. ``from_tde``,
    ``from_cco``: the population's weights from the TDEs and the CCOs in spikes, shape
    ``(size, N)`` (int): each CCO to its K AND neurons with weight 1 (with the level neuron's 1
    above the AND threshold of 1.5 spikes), each TDE and CCO to its relay with weight 2 (above
    it alone).
    """

    n_and: int
    size: int
    spll_of_and: np.ndarray
    relay_tde: np.ndarray
    relay_cco: np.ndarray
    refr_a: np.ndarray
    refr_b: np.ndarray
    from_tde: np.ndarray
    from_cco: np.ndarray


def gate_layout(n_spll: int, levels: int, timers: bool = True) -> GateLayout:
    """The :class:`GateLayout` of ``n_spll`` sPLLs with ``levels`` gate levels; without
    ``timers`` (a target without refractory units) it ends after the relays (``M + 2N`` rows,
    ``refr_a`` and ``refr_b`` empty)."""
    n, m = np.arange(n_spll), n_spll * levels
    size, spll_of_and = m + (6 if timers else 2) * n_spll, np.repeat(n, levels)
    relay_tde, relay_cco = m + n, m + n_spll + n
    refr_a = m + 2 * n_spll + np.arange(2 * n_spll if timers else 0)
    refr_b = refr_a + 2 * n_spll
    from_tde = np.zeros((size, n_spll), np.int64)
    from_tde[relay_tde, n] = 2
    from_cco = np.zeros((size, n_spll), np.int64)
    from_cco[np.arange(m), spll_of_and] = 1
    from_cco[relay_cco, n] = 2
    return GateLayout(
        m, size, spll_of_and, relay_tde, relay_cco, refr_a, refr_b, from_tde, from_cco
    )


class RefractoryTimers(NamedTuple):
    """The refractory units of N sPLLs on a clock of step ``dt`` (:func:`refractory_timers`),
    per unit, the N TDEs first, then the N CCOs, shape ``(2N,)`` each.

    A unit holds its neuron for ``steps`` = ``round(t_refr / dt - 1/2)`` whole steps after
    each spike (:func:`compensated_hold`: a clocked neuron fires at the end of the step its
    threshold crossing falls in, on average half a step late, so the grid's
    ``round(t_refr / dt)`` would restart it on average half a step late). It is made
    of standard neurons: two *timers* (comparators on a decaying current, like the gate's level
    neurons: synaptic time constant ``tau``, membrane time constant ``dt``, threshold 1) that
    the neuron's spike of step ``s`` kicks in step ``s + 1`` by ``kick_a`` and ``kick_b``.
    The kicked current decays by ``decay`` per step, so timer a fires in steps
    ``s+1..s+steps`` (``kick_a decay^(steps-1) > 1 > kick_a decay^steps``) and timer b in
    ``s+1..s+steps+1``, each with half a step's factor of margin on either side; what is
    left of a kick when the next one comes (``<= decay^(steps+1)`` of it) is far below that
    margin. The targets use them to

    * drop the neuron's spikes while timer a fires (the spike the consumers see is the neuron's
      spike AND NOT timer a), and
    * hold its membrane at 0 meanwhile: a current of 2 thresholds a step added to its synapse
      in steps ``s+1..s+steps`` makes it fire (and reset to 0) on each of them, so it starts
      from 0 in step ``s+steps+1``, where the added current is removed exactly. With ``a =
      dt / tau_syn`` of the neuron's synapse, the current added is ``2 (1 - a)`` per spike of
      the neuron's relay (step ``s+1``), ``2 a + 2 (1 - a)`` while timer a fires and ``-2
      (1 - a)`` while timer b fires (the sum is ``2, 2a, ..., 2a, -2 (1-a)`` in steps
      ``s+1, ..., s+steps+1``, which a synapse decaying by ``1 - a`` turns into ``2, 2, ...,
      2, 0``). These are the weights in exact arithmetic; nir-standard's float32 file holds
      weights of the same meaning that float32 represents exactly
      (``mappings.nir.standard.hold_weights``).

    A unit of ``steps == 0`` (a refractory period under half a step) has kicks of 0: it never
    fires and adds nothing.
    """

    steps: np.ndarray
    tau: np.ndarray
    decay: np.ndarray
    kick_a: np.ndarray
    kick_b: np.ndarray


#: Largest ``log2`` of a timer's kick: the kicks stay far inside float32 (2^127).
MAX_KICK_LOG2 = 100.0
#: Largest ``log2`` factor a timer's current decays by per step.
MAX_DECAY_LOG2 = 4.0


def refractory_timers(network: Network, dt: float) -> RefractoryTimers:
    """The :class:`RefractoryTimers` of ``network`` at step ``dt`` [s]."""
    p, r = dict(zip(PARAM_NAMES, network.matrix().T, strict=True)), roles()
    steps = compensated_hold(np.r_[p[r.tde.t_refr], p[r.cco.t_refr]], dt)
    # Decay 2^-c a step: as fast as float32 allows (the margins are 2^(c/2)).
    c = np.minimum(MAX_DECAY_LOG2, MAX_KICK_LOG2 / (steps + 1.0))
    decay = 2.0**-c
    on = steps > 0
    kick_a = np.where(on, 2.0 ** (c * (steps - 0.5)), 0.0)
    kick_b = np.where(on, 2.0 ** (c * (steps + 0.5)), 0.0)
    return RefractoryTimers(steps, dt / (1.0 - decay), decay, kick_a, kick_b)


def gate_levels(
    network: Network,
    n_levels: int = DEFAULT_LEVELS,
    placement: str = DEFAULT_PLACEMENT,
    input_rate: float = DEFAULT_INPUT_RATE,
) -> Gate:
    """The K-level gate of every sPLL of ``network``, placed for Poisson input at
    ``input_rate`` [Hz] (``"band-quantile"``: at the rates :func:`placement_rates` names).

    The normalised facilitatory current ``n = I_fac / g_tde_fac`` under Poisson input has a
    distribution that depends on ``rate * tau_tde_fac`` only; it is sampled once per distinct
    ``tau_tde_fac`` (deterministically) and the levels are placed on it:

    * ``"uniform"``: thresholds ``(k - 1/2) h``, ``k = 1..K``, ``h = Q(0.999) / K``;
    * ``"quantile"``: thresholds at the quantiles ``(k - 1/2) / K``;
    * ``"band-quantile"``: the same on the mixture of the samples at every rate of the band.

    Each bin ``[thresholds[k], thresholds[k+1])`` (the last one open) is reconstructed by the
    conditional mean of ``n`` in it, the value that minimises the squared error; below the
    first threshold the gate passes nothing.

    Raises:
        ValueError: ``n_levels`` not in ``1..MAX_LEVELS``, an unknown placement, a rate that is
            not finite and > 0, or an sPLL whose ``g_tde_fac`` is 0 (nothing to gate).
    """
    if isinstance(n_levels, bool) or not isinstance(n_levels, int | np.integer):
        raise ValueError(f"gate levels K must be an integer, got {n_levels!r}")
    if not 1 <= n_levels <= MAX_LEVELS:
        raise ValueError(f"gate levels K must be in 1..{MAX_LEVELS}, got {n_levels}")
    if placement not in PLACEMENTS:
        raise ValueError(f"gate placement must be one of {PLACEMENTS}, got {placement!r}")
    if not (isinstance(input_rate, int | float) and math.isfinite(input_rate) and input_rate > 0):
        raise ValueError(f"gate input_rate must be a finite rate > 0 Hz, got {input_rate!r}")
    m = network.matrix()
    g_fac = m[:, PARAM_NAMES.index("g_tde_fac")]
    tau_fac = m[:, PARAM_NAMES.index("tau_tde_fac")]
    zero = np.flatnonzero(g_fac <= 0)
    if zero.size:
        raise ValueError(
            f"sPLL {zero[0]}: g_tde_fac is 0, so I_fac is always 0 and the standard gate has no "
            "levels to place (target: standard construction)"
        )
    rates = placement_rates(network, placement, float(input_rate))
    thresholds = np.empty((network.n_spll, n_levels))
    increments = np.empty_like(thresholds)
    for i in range(network.n_spll):
        rate_taus = tuple(float(rate * tau_fac[i]) for rate in rates)
        t, r = _normalised_levels(rate_taus, int(n_levels), placement)
        thresholds[i] = g_fac[i] * t
        increments[i] = g_fac[i] * np.diff(np.r_[0.0, r])
    return Gate(thresholds, increments, placement, rates)


@dataclass(frozen=True)
class GateOptions:
    """How a standard target builds its gate for a network: the options
    :func:`~mappings.nir.standard.to_standard_nir` and
    :func:`~mappings.lava.standard.lava_standard` share (each takes its step ``dt`` [s] and
    its own refractory options beside them).

    Attributes:
        levels: gate levels K per sPLL (a count, ``1..MAX_LEVELS``).
        placement: where :func:`gate_levels` places them (one of :data:`PLACEMENTS`).
        input_rate: the Poisson input rate [Hz] they are placed for (``"band-quantile"``:
            the network's band of rates instead, :func:`placement_rates`).
        gate: the gate itself, thresholds and increments in amperes, one row per sPLL of the
            network, or ``None``: :func:`gate_levels` of the three above. Where given, those
            three are unused (a part of a network written with its rows of the whole
            network's gate).
    """

    levels: int = DEFAULT_LEVELS
    placement: str = DEFAULT_PLACEMENT
    input_rate: float = DEFAULT_INPUT_RATE
    gate: Gate | None = None


#: The gate options of a standard target where none are given: :data:`DEFAULT_LEVELS` levels
#: placed by :data:`DEFAULT_PLACEMENT` for :data:`DEFAULT_INPUT_RATE`.
DEFAULT_GATE = GateOptions()


def placement_rates(network: Network, placement: str, input_rate: float) -> tuple[float, ...]:
    """The Poisson rates [Hz] :func:`gate_levels` places the levels of ``placement`` for:
    ``(input_rate,)``, or for ``"band-quantile"`` :data:`BAND_RATES` rates geometrically
    spaced from the network's lowest to its highest free-running frequency (the band its
    layout spans; one where they are equal, ``input_rate`` alone where no sPLL oscillates),
    lowest first."""
    if placement != "band-quantile":
        return (input_rate,)
    f = np.asarray(network.free_frequencies(), dtype=float)
    f = f[np.isfinite(f) & (f > 0)]
    if not f.size:
        return (input_rate,)
    if f.min() == f.max():
        return (float(f[0]),)
    return tuple(float(x) for x in np.geomspace(f.min(), f.max(), BAND_RATES))


@lru_cache(maxsize=256)
def _normalised_levels(
    rate_taus: tuple[float, ...], k: int, placement: str
) -> tuple[np.ndarray, np.ndarray]:
    """Thresholds and bin reconstructions of ``n = I_fac / g_fac`` for Poisson input of
    ``rate * tau_fac`` in ``rate_taus`` (their mixture)."""
    n = np.sort(np.concatenate([_stationary_samples(x) for x in rate_taus]))
    if placement == "uniform":
        h = np.quantile(n, UNIFORM_TOP_QUANTILE) / k
        t = (np.arange(1, k + 1) - 0.5) * h
    else:
        t = np.quantile(n, (np.arange(1, k + 1) - 0.5) / k)
    # Distinct, increasing, > 0 (a tiny rate can put several quantiles at the same point).
    t = np.maximum(t, 1e-3 * max(float(n.mean()), 1e-9))
    for j in range(1, k):
        t[j] = max(t[j], t[j - 1] * (1 + 1e-9) + 1e-12)
    edges = np.searchsorted(n, t)
    r = np.empty(k)
    for j in range(k):
        hi = edges[j + 1] if j + 1 < k else n.size
        r[j] = n[edges[j] : hi].mean() if hi > edges[j] else t[j]
    # A reconstruction below the previous one (an empty or thin bin) would make an increment
    # <= 0; keep them increasing.
    for j in range(k):
        lo = r[j - 1] if j else 0.0
        r[j] = max(r[j], lo + 1e-9 * max(1.0, lo), t[j] if r[j] <= lo else 0.0)
    return t, r


def _stationary_samples(rate_tau: float) -> np.ndarray:
    """Samples of ``n(t) = sum_i exp(-(t - t_i) / tau)`` (time in units of ``tau``) under a
    Poisson train of ``rate_tau`` spikes per ``tau`` (fixed seed), on a grid of ``tau / 100``
    (spikes at the end of their grid cell) after a warm-up of 10 ``tau``."""
    rng = np.random.default_rng(12345)
    step = 0.01
    span = 3000.0
    counts = rng.poisson(rate_tau * step, int(span / step)).astype(float)
    n = lfilter([1.0], [1.0, -math.exp(-step)], counts)
    return n[int(10 / step) :]


def target_parameters(network: Network, dt: float, target: str) -> dict[str, np.ndarray]:
    """The parameters of ``network`` by name (:data:`~spll_hw.params.PARAM_NAMES`), shape
    ``(N,)`` each, for a clocked ``target`` of step ``dt`` [s].

    Raises:
        ValueError: naming ``target`` when ``network`` is not a
            :class:`~spll_hw.network.Network` or ``dt`` is not a finite time > 0.
    """
    if not isinstance(network, Network):
        raise ValueError(f"{target} needs a spll_hw Network, got {type(network).__name__}")
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"{target}: dt must be a finite time > 0 s, got {dt!r}")
    return dict(zip(PARAM_NAMES, network.matrix().T, strict=True))


def inhibition_weights(network: Network, input_rate: float) -> dict[str, np.ndarray]:
    """Self-inhibition weights (potential per step, threshold 1) standing in for the TDE's and
    the CCO's refractory periods, per sPLL, shape ``(N,)`` each.

    A refractory neuron loses the charge its current would have delivered while it is held at
    0. The weight removes that charge on average: from a golden run on a Poisson train at
    ``input_rate`` (1 s, fixed seed), the mean over a neuron's spikes of
    ``∫_0^t_refr I(t_s + s) ds / (c v_thr)`` with the current decaying from its value just
    after the spike (the CCO's includes the offset), spread over the synapse it enters
    (``w tau_syn / dt`` steps of potential in total).
    """
    p, r = dict(zip(PARAM_NAMES, network.matrix().T, strict=True)), roles()
    train = poisson_spikes(input_rate, 1.0, 2024)
    res = simulate(network, train, 1.0)
    lost = {}
    for part, spikes, var, syn, mem in (
        ("tde", res.tde_spikes, "i_trg", r.trg, r.tde),
        ("cco", res.cco_spikes, "i_cco", r.cco_syn, r.cco),
    ):
        tau_s, refr, c, thr = p[syn.tau], p[mem.t_refr], p[mem.c], p[mem.v_thr]
        times = np.unique(np.concatenate([s for s in spikes if len(s)] or [np.zeros(0)]))
        mean_current = np.zeros(network.n_spll)
        if times.size:
            trace = simulate(network, train, 1.0, record_spikes=False, probe_times=times)
            values = trace.info["trace"][var]
            for i, s in enumerate(spikes):
                if len(s):
                    mean_current[i] = values[i, np.searchsorted(times, s)].mean()
        charge = mean_current * tau_s * -np.expm1(-refr / tau_s)
        if part == "cco":
            charge = charge + p[r.offset] * refr
        lost[part] = charge / (c * thr) / tau_s  # total potential w tau_s/dt = charge/(c thr)
    return lost
