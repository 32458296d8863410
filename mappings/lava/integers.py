"""Loihi's integer arithmetic of the standard sPLL on Lava's processes: the 12-bit decays,
the CCO offset's bias, the gains of kicks, the thresholds, the 8-bit weights and 13-bit biases,
and the refractory units that hold a neuron, from which
:func:`~mappings.lava.standard.lava_standard` builds its
:class:`~mappings.lava.standard.LavaStandard` (the populations and connections are
:mod:`mappings.lava.standard`'s docstring).

Units as Loihi's: a decay ``δ`` of 12 bits (``keep = 4096 - δ``, the factor ``keep / 4096`` a
step), a current ``u`` and potential ``v`` in units of ``1/64`` of an ``a_in`` unit (a
threshold ``θ = vth · 64``), a ``Dense`` weight ``w`` with exponent ``e`` worth ``w 2^e``
``a_in`` units. Arrays are per sPLL, shape ``(N,)``, unless a docstring says otherwise; a
population's parameters and connections are :class:`~mappings.lava.standard.LavaStandard`'s
``lif`` and ``dense`` forms.

**Refractory unit** (:func:`refractory_unit`; Lava's ``LIFRefractory`` is floating point
only). It holds its neuron ``X`` for exactly ``R = round(t_refr / dt - 1/2)`` steps after each
spike (:func:`~spll_hw.model.holds.compensated_hold`, the NIR graph's hold: a spike
detected at its step's end is on average half a step late; ``R >= 2``): ``v`` starts from 0 in
step ``s + R + 1`` after a spike in step ``s``, its current ``u`` unchanged.
Let ``X`` spike in step ``s`` (a spike of ``X`` is one of the network's unless ``hold_X``
fires in the same step):

* ``hold_X`` fires in steps ``s+1 .. s+R`` (from ``X``, +2; itself, +2; ``end_X``, -4), and
  meanwhile cancels ``X``'s spikes in the gate (-2): no relay, no AND neuron sees them. The
  relay of ``X`` in the gate fires in step ``s+1`` for a spike of ``X`` that is the network's
  only (``X`` +2, ``hold_X`` -2).
* ``end_X`` counts ``hold_X``'s spikes (+1, ``v`` never decays) and fires on the ``R - 1``-th,
  in step ``s+R``, which resets it; its own spike (-1) cancels the one count left.
* A forcing current ``2^18 F`` in ``u`` (:func:`_threshold` picks ``F <= 7`` and ``vth``) in
  steps ``s+2 .. s+R``: the relay adds ``F keep`` (a_in) in ``s+2``, ``hold_X`` adds ``F δ``
  in ``s+2 .. s+R+1`` and ``end_X`` ``-4096 F`` in ``s+R+1``, where ``δ`` is ``u``'s decay
  (``du + 1``) and ``keep = 4096 - δ``. A multiple of 4096 decays without rounding with a
  ``u >= 0`` (``(u + 4096 m) keep >> 12 = (u keep >> 12) + m keep``; the sPLL's currents are
  never negative), so the force is ``2^18 F`` in every held step and 0 from ``s+R+1`` on,
  leaving ``u`` what it would have been. Whatever ``X`` does in the held steps is cancelled;
  what matters is that it surely fires in step ``s+R``, which leaves ``v = 0``.
  :func:`_fires_last` proves that from ``v``'s bounds with the most the neuron's own current
  and bias can add in a step (``F`` above ``θ``: it fires on every held step; below, as the
  CCOs' thresholds need for ``g_cco``'s 8-bit weights to keep their resolution, it fires
  every few steps, the last on ``s+R``). ``tests/test_standard_lava.py`` checks the units spike
  for spike against the same integers held by a counter.

**Dithered hold** (``hold="dithered"``, :data:`~mappings.lava.standard.HOLDS`). Whole steps
restart a neuron up to half a step late or early every cycle, which a TDE that bursts every few
steps accumulates. With this hold each neuron's period is ``R = base`` steps but every
``n``-th spike ``R + 1`` or ``R - 1`` (:func:`~spll_hw.model.holds.counter_dither`: the mean
nearest ``t_refr / dt - 1/2``). ``dither_X`` counts the neuron's network spikes through its
relay (weight ``255 // (n - 1)``, step ``s+2``) and fires on the ``n``-th, which resets it; its
spike reaches ``end_X`` in step ``s+3``, ``-1`` (one count more to go: the hold lasts ``R + 1``,
``R >= 3``) or ``+1`` (one less: ``R - 1``, ``R >= 4``), and the force, ended by ``end_X``,
lasts as long; :func:`_fires_last` proves both holds. The export tries it after the
compensated hold at each step (:mod:`mappings.lava.dt_choice`).

The force and its removal pass through 16-bit ``a_in`` in one step (``4096 F`` beside the
trigger), which bounds ``F`` and with it the thresholds: at 10 µs the TDE's ``vth`` drops
below :data:`VTH_TDE` on hard-driven networks (24421 on biotac-vary-offset-lif).

**Integers** (``q`` = 12 decay bits as Loihi): a time constant ``tau`` is
``δ = round(4096 (1 - e^{-dt/tau}))``; ``u`` decays by ``δ`` (``du = δ - 1``, Lava adds
Loihi's offset 1), ``v`` by ``δ`` (``dv = δ``; 0, no leak, where ``tau`` is too long for 12
bits, as the CCO's 0.314 s at 10 µs). A kicked synapse too long for them takes ``δ = 1``,
Loihi's longest, and the gains into it keep their kicks' charge (:func:`loihi_decays`,
:func:`charges`). The offset ``I`` into a CCO of threshold ``θ = vth · 64`` is the per-step
potential (bias) with which the offset alone makes it fire at golden's free-running period,
where it does (:func:`free_running_offset`: the membrane's decay rounds by up to 27 % at 10 µs,
and the exact gain of the realised one, ``I τ' (δ_v / 4096) / (C v_thr) · θ``, used before
2026-11-27, ran slow CCOs 3-6 % off); a kick into a synapse is ``u = k I / v_thr · θ``,
``k`` the exact one-step propagator of the realised decays
(:func:`~spll_hw.model.discrete.exact_propagator`, the NIR graph's exact charge): Loihi adds
``u`` to ``v`` in the step it arrives and decays it after, which charges the membrane as the
current would between steps (the constant current's gain, used for kicks before 2026-11-27,
delivered ``dt / (τ (1 - e^(-dt/τ)))`` times a kick's charge: 1.17 for
``biotac-time-scaled-lif``'s ``tau_tde_trg`` of 83 µs at 25 µs). A ``Dense`` weight ``w`` with
exponent ``e`` adds ``w 2^e · 64`` to ``u`` (Lava shifts the synaptic input by 6 bits); its
accumulated sum must fit ``a_in``'s 16 bits.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from spll_hw.model.discrete import decay_constant, membrane_gain, realised_tau
from spll_hw.model.frequency import free_frequency
from spll_hw.model.holds import CounterDither, compensated_hold, counter_dither
from spll_hw.model.roles import roles

from .loihi import A_IN_MAX, DECAY_BITS, DECAY_UNITY, is_graded, most_kicks, split_weight

#: Thresholds of the TDE and CCO processes (17-bit ``vth``; ``θ = vth · 64``).
VTH_TDE = 2**16
VTH_CCO = 2**17 - 1
#: Largest force ``F`` of a refractory unit (``2^18 F`` in ``u``; its removal, ``-F keep``,
#: fits 16-bit a_in up to 8).
MAX_FORCE = 7
#: Threshold of a refractory unit's dither counter (``v > 255 · 64``): a counter of period
#: ``n`` (2..16) counts ``255 // (n - 1)`` a spike, so that its ``n``-th spike, not its
#: ``n-1``-th, crosses (:func:`refractory_unit`).
DITHER_VTH = 255


def holds(t_refr: np.ndarray, dt: float, hold: str) -> CounterDither:
    """The refractory holds [steps] of periods ``t_refr`` [s] at ``dt`` [s] by rule ``hold``
    (:data:`~mappings.lava.standard.HOLDS`), as counters' rules (undithered: ``step`` 0)."""
    if hold == "dithered":
        return counter_dither(t_refr, dt)
    base = compensated_hold(t_refr, dt)
    return CounterDither(base, np.zeros_like(base), np.zeros_like(base))


def free_running_offset(p: dict, delta: np.ndarray, dt: float) -> np.ndarray:
    """The CCO offset's potential per step [units of the CCO's θ], per sPLL: the bias with
    which a CCO that the offset alone drives fires at golden's free-running period.

    Loihi's 12-bit decay ``δ`` of ``tau_cco`` (``delta``) realises ``τ'``
    (:func:`~spll_hw.model.discrete.realised_tau`), 9-27 % off on slow CCOs (``tau_cco`` =
    56 ms at 10 µs: ``δ = 1``, ``τ' = 41 ms``). A constant current's exact gain with ``τ'``,
    ``b = I τ' (1 - k) / (C v_thr)`` a step with ``k = 1 - δ / 4096``, takes ``v_m = b (1 - k^m)
    / (1 - k)`` to ``θ`` later or sooner than golden's ``v(t) = I τ / C (1 - e^(-t/τ))`` (a CCO
    that only the offset drives ran 3-6 % off golden's rate, and a PLL whose CCO runs off
    locks elsewhere). Where the offset drives the CCO past its threshold the bias keeps
    golden's free-running charge time ``T``, the period of
    :func:`~spll_hw.model.frequency.free_frequency` (thesis eq. 6) less ``t_cco_refr``, which
    the refractory unit holds: ``b = (1 - k) / (1 - k^(T / dt))`` (``dt / T`` where ``δ = 0``,
    no leak); elsewhere it is the exact gain (:func:`~spll_hw.model.discrete.membrane_gain` of
    ``τ'``; ``dt / C`` without leak).

    Args:
        p: the network's parameters at the target (per sPLL).
        delta: the 12-bit decay of each CCO's membrane, shape ``(N,)``.
        dt: the step [s].
    """
    cco = roles().cco
    tau, c, v_thr, i = p[cco.tau], p[cco.c], p[cco.v_thr], p[roles().offset]
    keep = 1.0 - np.asarray(delta, dtype=np.float64) / DECAY_UNITY
    leaks = delta > 0
    tau_r = realised_tau(np.where(leaks, delta, 1), dt, DECAY_BITS)
    gain = i * np.where(leaks, membrane_gain(tau_r, c, dt), dt / c) / v_thr
    f = np.array([free_frequency(*q) for q in zip(i, tau, c, v_thr, p[cco.t_refr], strict=True)])
    free = f > 0
    steps = (1 / np.where(free, f, 1.0) - p[cco.t_refr]) / dt  # T / dt
    kept = np.where(leaks, keep, 0.5)
    free_running = np.where(leaks, (1 - keep) / -np.expm1(steps * np.log(kept)), 1 / steps)
    return np.where(free, free_running, gain)


def longest_decays(p: dict, r, dt: float) -> tuple[str, ...]:
    """A note per kicked synapse too long for 12 bits at ``dt`` [s] on some sPLLs, which takes
    Loihi's longest decay with its charge kept (:func:`loihi_decays`, :func:`charges`), or
    none."""
    notes = []
    for syn in (r.trg, r.cco_syn):
        idx = np.flatnonzero(_takes_longest(p[syn.tau], dt))
        if idx.size:
            notes.append(
                f"{spll_ranges(idx)}: {syn.tau} (at least {np.min(p[syn.tau][idx]):g} s) is too "
                f"long for Loihi's 12-bit decays at dt = {dt:g} s; it decays as the longest they "
                f"have, {realised_tau(1, dt, DECAY_BITS):.3g} s, the gains into it scaled so that "
                "its kicks keep their charge"
            )
    return tuple(notes)


def per_exponent(src: str, dst: str, weights: dict, idx: np.ndarray) -> dict:
    """The ``Dense`` from ``src`` to the neurons ``idx`` of ``dst`` (:func:`dense_weights`'s
    ``{exponent: weights}``, rows the network's sPLLs): one per exponent that any of them
    uses, named ``{src}_{dst}`` where one does, ``{src}_{dst}_e{exponent}`` where several;
    none where every weight is 0."""
    used = {e: w[idx] for e, w in weights.items() if w[idx].any()}
    if len(used) == 1:
        ((e, w),) = used.items()
        return {f"{src}_{dst}": (src, dst, w, e, 0)}
    return {f"{src}_{dst}_e{e}": (src, dst, w, e, 0) for e, w in used.items()}


def spll_ranges(idx: np.ndarray) -> str:
    """``sPLL 4`` or ``sPLLs 0-3, 7, 9-10``: sorted sPLL indices as runs."""
    runs, start = [], int(idx[0])
    for a, b in zip(idx[:-1], idx[1:], strict=True):
        if b != a + 1:
            runs.append((start, int(a)))
            start = int(b)
    runs.append((start, int(idx[-1])))
    text = ", ".join(str(a) if a == b else f"{a}-{b}" for a, b in runs)
    return f"sPLL {text}" if idx.size == 1 else f"sPLLs {text}"


def loihi_decays(p: dict, r, dt: float) -> dict[str, np.ndarray]:
    """The 12-bit decay ``δ`` of every time constant of the sPLLs (per sPLL); ``ValueError``
    naming the first one outside what a LIF process takes.

    A potential may not decay at all (``dv = 0``: an integrator). A current decays by at least 1
    (``du + 1``, Loihi's offset). A synapse that the sPLL kicks (``tau_tde_trg``,
    ``tau_cco_syn``) too long for 12 bits at ``dt`` (``δ`` rounds to 0: a ``tau_cco_syn`` of
    84 ms at 10 µs) takes that least decay, Loihi's longest time constant (``4096 dt``), and
    :func:`charges` keeps its kicks' charge; the gate's ``tau_tde_fac``, whose value and not
    its charge the gate reads, is refused there."""
    kicked = (r.trg.tau, r.cco_syn.tau)
    decay = {}
    for name in r.time_constants:
        delta = decay_constant(p[name], dt, DECAY_BITS)
        if name in kicked:
            delta = np.maximum(delta, 1)
        low = 0 if name in (r.tde.tau, r.cco.tau) else 1
        bad = np.flatnonzero((delta < low) | (delta > 4095))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"sPLL {i}: {name} = {p[name][i]:g} s at dt = {dt:g} s needs a 12-bit decay of "
                f"{delta[i]}; target lava-standard needs {low}..4095 (change dt)"
            )
        decay[name] = delta
    return decay


def charges(p: dict, r, decay: dict, dt: float) -> dict[str, np.ndarray]:
    """The trigger's and the feedback's gains (per sPLL): as given, but scaled by ``tau_syn /
    tau'`` where the synapse they kick is too long for 12 bits and takes Loihi's longest decay
    (:func:`loihi_decays`; ``tau'`` = ``4096 dt``, under half of ``tau_syn``), so that its kicks
    still deliver their charge ``g tau_syn``, the mean current it carries (a factor 2 for a
    ``tau_cco_syn`` of 84 ms at 10 µs). Where 12 bits only round the decay the gain stays, as
    every other parameter keeps its rounding: scaling those too moved the checks both ways, by
    up to 2 points (``biotac-vary-offset-pacinian`` 3.8 -> 6.0 % at 50 µs, its ``tau_cco_syn``
    5 % off; ``biotac-time-scaled-pacinian`` 11.3 -> 7.9 % at 25 µs, a factor 2 off; 2026-11-27),
    so it is no construction rule."""
    out = {}
    for gain, syn in ((r.gated.gain, r.trg), (r.fed.gain, r.cco_syn)):
        tau = p[syn.tau]
        out[gain] = np.where(
            _takes_longest(tau, dt),
            p[gain] * tau / realised_tau(decay[syn.tau], dt, DECAY_BITS),
            p[gain],
        )
    return out


def _takes_longest(tau: np.ndarray, dt: float) -> np.ndarray:
    """Whether each kicked synapse's time constant ``tau`` [s] is too long for 12 bits at
    ``dt`` [s] (its decay rounds to 0), so that it takes Loihi's longest (:func:`loihi_decays`),
    bool, the shape of ``tau``."""
    return decay_constant(tau, dt, DECAY_BITS) < 1


def thresholds(
    unit: dict, held: dict, group_of: np.ndarray, p: dict, dt: float, carried: np.ndarray
) -> tuple[dict, dict]:
    """Each set of sPLLs' TDE and CCO ``vth`` (one per LIF process, :func:`_threshold`) and
    its refractory units' forces: ``({"tde", "cco"}: vth per sPLL, {"tde", "cco"}: force per
    set)``.

    Args:
        unit: per sPLL, per unit of ``vth``: ``offset`` (bias of the CCO), ``feedback`` and
            ``trigger`` (a_in of one TDE spike into the CCO, of one CCO spike into the TDE).
        held: per part, per sPLL and hold it may take ``(steps, keep_u, keep_v, gap)``
            (:func:`_threshold`), shape ``(N, holds, 4)``.
        group_of: each sPLL's set (LIF processes).
        carried: per sPLL, how many of its feedback kicks the CCO's ``a_in`` may carry at once
            (1; more where a graded current passes through it,
            :func:`~mappings.lava.graded_current.carried`).

    Raises:
        ValueError: naming the sPLLs and the parameter where a threshold would hold fewer than
            64 units (the CCO's offset beyond Loihi's bias, one trigger beyond 16-bit a_in).
    """
    n_groups = int(group_of.max()) + 1
    vth = {part: np.zeros(group_of.size, np.int64) for part in ("tde", "cco")}
    force = {part: np.zeros(n_groups, np.int64) for part in ("tde", "cco")}
    for g in range(n_groups):
        idx = np.flatnonzero(group_of == g)
        rows = {part: {tuple(int(x) for x in row) for row in held[part][idx].reshape(-1, 4)}
                for part in held}  # fmt: skip
        offset = float(np.max(unit["offset"][idx]))
        cco = _threshold(VTH_CCO, float(np.max(unit["feedback"][idx])), rows["cco"], offset,
                         limit=0.95 * (4095 << 7) / max(offset, 1e-300) / 64,
                         carried=float(np.max(carried[idx])))  # fmt: skip
        tde = _threshold(VTH_TDE, float(np.max(unit["trigger"][idx])), rows["tde"])
        for part, (v, f) in (("cco", cco), ("tde", tde)):
            vth[part][idx], force[part][g] = v, f
        if cco[0] < 64:
            raise ValueError(
                f"lava-standard: {spll_ranges(idx)}: i_cco_offset = "
                f"{np.max(p['i_cco_offset'][idx]):g} A charges the CCO by {offset:.3g} "
                f"thresholds a step at dt = {dt:g} s; Loihi's bias leaves it fewer than 64 "
                "threshold units (use a smaller dt)"
            )
        if tde[0] < 64:
            raise ValueError(
                f"lava-standard: {spll_ranges(idx)}: g_tde_trg = "
                f"{np.max(p['g_tde_trg'][idx]):g} gives a trigger of "
                f"{np.max(unit['trigger'][idx]):.3g} TDE thresholds in one step at dt = {dt:g} s; "
                "Loihi's 16-bit synaptic input leaves it fewer than 64 threshold units (use a "
                "smaller dt)"
            )
    return vth, force


def _threshold(
    cap: int,
    unit_input: float,
    groups: set,
    unit_bias: float = 0.0,
    limit: float = math.inf,
    carried: float = 1.0,
) -> tuple[int, int]:
    """A held population's ``vth`` and its refractory units' force ``F`` (``2^18 F`` in ``u``;
    0 where no group holds): the largest ``vth <= min(cap, limit)`` whose synaptic input
    (``unit_input`` a_in per unit of ``vth`` at most, every source at once) fits 16-bit a_in
    beside the force's ``4096 F`` (at 90 %, for the weights' rounding), and with which every
    group's unit surely makes the neuron fire on its last held step (:func:`_fires_last`).

    Args:
        groups: per group ``(steps, keep_u, keep_v, gap)``: the refractory steps, the current's
            and the potential's decay factors (``keep / 4096`` a step) and the fewest steps
            between two spikes of the input's source (its refractory steps + 1).
        unit_bias: the bias per unit of ``θ`` at most.
        carried: how many times ``unit_input`` the neuron's ``a_in`` may carry in one step.
    """

    def budget(force: int) -> float:
        room = 0.9 * (A_IN_MAX - DECAY_UNITY * force)
        return min(cap, limit, room / max(unit_input * carried, 1e-300))

    if all(g[0] == 0 for g in groups):
        return int(budget(0)), 0
    best = (0, 0)
    for force in range(1, MAX_FORCE + 1):
        # Candidates from the budget down by 1 % steps: the first that holds is this force's.
        top = budget(force)
        for vth in np.unique((top * 0.99 ** np.arange(500)).astype(np.int64))[::-1]:
            if vth < 64 or vth <= best[0]:
                break
            theta = 64 * int(vth)
            if all(
                _fires_last(theta, force << 18, steps, keep_v,
                            _drive(theta, unit_input * vth, unit_bias, keep_u, gap))
                for steps, keep_u, keep_v, gap in groups if steps
            ):  # fmt: skip
                best = (int(vth), force)
                break
    return best


def _drive(theta: int, a_in: float, unit_bias: float, keep_u: int, gap: int) -> float:
    """Most a held neuron's potential gains in one step from its own current and bias [u
    units]: input of ``a_in`` (a_in units, with 25 % for rounding) at most once every ``gap``
    steps into a current decaying by ``keep_u / 4096``, plus the bias."""
    return 1.25 * 64 * a_in * float(most_kicks(keep_u, gap)) + unit_bias * theta


def _fires_last(theta: int, force: int, steps: int, keep_v: int, drive: float) -> bool:
    """Whether a neuron of threshold ``θ`` (``u``/``v`` units), potential decaying by ``keep_v
    / 4096``, reset to 0 by a spike in step ``s`` and then charged by its own current and bias
    (``0..drive`` a step) and by ``force`` in steps ``s+2 .. s+steps``, surely fires in step
    ``s+steps``: its potential's bounds, step by step (a step it may or may not fire in leaves
    ``0..θ``)."""
    lo = hi = 0.0
    for j in range(1, steps + 1):
        f = force if j >= 2 else 0
        low = math.floor(lo * keep_v / DECAY_UNITY) + f
        high = hi * keep_v / DECAY_UNITY + f + drive
        if low > theta:
            lo = hi = 0.0
            if j == steps:
                return True
        elif high <= theta:
            lo, hi = low, high
        else:
            lo, hi = 0.0, float(theta)
    return False


class RefractoryUnit(NamedTuple):
    """The LIF processes (``lif``) and ``Dense`` (``dense``) of one population's refractory
    units, in :class:`~mappings.lava.standard.LavaStandard`'s forms (:func:`refractory_unit`)."""

    lif: dict
    dense: dict


def refractory_unit(
    held: str,
    steps: int,
    keep: int,
    force: int,
    reach: np.ndarray,
    relay: np.ndarray,
    dither: CounterDither | None = None,
) -> RefractoryUnit:
    """The refractory units that hold each neuron of population ``held`` for exactly ``steps``
    (``>= 2``) steps after each of its spikes, or ``steps + step`` after every ``period``-th
    (``dither``; the module docstring's arithmetic).

    Args:
        held: the population (its ``u`` decays by ``keep / 4096`` a step).
        force: ``F``: the forcing current is ``2^18 F`` in ``u`` (:func:`_threshold`).
        reach: the weights of ``held``'s spikes into the gate, shape ``(gate size, size)``,
            which the unit cancels while it holds.
        relay: the gate row of each neuron's relay of its spikes, shape ``(size,)``.
        dither: per neuron (shape ``(size,)`` each), its counter's ``step`` and ``period``
            (``base`` is ``steps``); ``None``: every hold is ``steps``.
    """
    size = reach.shape[1]
    end, hold = f"end_{held}", f"hold_{held}"
    eye = np.eye(size, dtype=np.int64)
    from_relay = np.zeros((size, reach.shape[0]), np.int64)
    from_relay[np.arange(size), relay] = 1
    dense = {
        f"{held}_{hold}": (held, hold, 2 * eye, 0, 0),
        f"{hold}_{hold}": (hold, hold, 2 * eye, 0, 0),
        f"{end}_{hold}": (end, hold, -4 * eye, 0, 0),
        f"{hold}_{end}": (hold, end, eye, 0, 0),
        f"{end}_{end}": (end, end, -eye, 0, 0),
        f"{hold}_gate": (hold, "gate", -2 * (reach > 0), 0, 0),
        f"{end}_{held}": (end, held, -32 * force * eye, 7, 0),
    }
    # The relay starts the force (F keep), the hold neuron keeps it (F (4096 - keep) a step).
    for src, what, value in (("gate", "start", force * keep),
                             (hold, "keep", force * (DECAY_UNITY - keep))):  # fmt: skip
        for e, w in split_weight(value):
            if w:
                dense[f"{src}_{held}_{what}_{e}"] = (
                    src,
                    held,
                    w * (from_relay if src == "gate" else eye),
                    e,
                    0,
                )
    lif = {
        end: unbiased_lif(size, du=4095, dv=0, vth=steps - 2),
        hold: unbiased_lif(size, du=4095, dv=4095, vth=1),
    }
    if dither is not None and dither.step.any():
        # The counter counts the neuron's spikes that are the network's (its relay, step s+1)
        # and fires on the period-th (s+2), taking one count off end_X or adding one (s+3).
        count = f"dither_{held}"
        weight = np.where(dither.step != 0, DITHER_VTH // np.maximum(dither.period - 1, 1), 0)
        lif[count] = unbiased_lif(size, du=4095, dv=0, vth=DITHER_VTH)
        dense[f"gate_{count}"] = ("gate", count, weight[:, None] * from_relay, 0, 0)
        for sign, what in ((-1, "lengthen"), (1, "shorten")):
            if np.any(dither.step == -sign):
                dense[f"{count}_{end}_{what}"] = (
                    count,
                    end,
                    sign * eye * (dither.step == -sign)[:, None],
                    0,
                    0,
                )
    return RefractoryUnit(lif, dense)


def unbiased_lif(size: int, du: int, dv: int, vth: int) -> dict:
    """A LIF process's parameters without bias."""
    zeros = np.zeros(size, np.int64)
    return {"du": du, "dv": dv, "vth": vth, "bias_mant": zeros, "bias_exp": zeros.copy()}


def col(values: np.ndarray) -> np.ndarray:
    """``values`` as an int64 column, shape ``(size, 1)`` (one source's weights)."""
    return np.asarray(values, dtype=np.int64).reshape(-1, 1)


def mantissa(value: float, what: str, floor: bool = False) -> tuple[int, int]:
    """``value ≈ w 2^e`` with ``w`` an 8-bit weight (``1..255``) and ``e`` in ``0..7`` (a
    negative exponent shifts the accumulated sum right, which only truncates more)."""
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"lava-standard: {what} {value!r} is not a positive number")
    e = max(0, math.ceil(math.log2(value / 255.0)))
    if e > 7:
        raise ValueError(f"lava-standard: {what} {value:g} exceeds 255 · 2^7")
    w = math.floor(value / 2.0**e) if floor else round(value / 2.0**e)
    return max(1, min(255, w)), e


def dense_weights(
    values: np.ndarray, what: str, may_vanish: bool = False
) -> tuple[dict[int, np.ndarray], np.ndarray]:
    """Integer weights of one sign (``|w| <= 255``) of target neurons (rows, shape ``(rows,
    sources)``, in ``a_in`` units): ``{exponent: weights}``, each weight 0 but in its
    exponent's matrix, and the rows (sPLLs) whose weights all round to 0.

    Each row takes the exponent that fits its own largest weight, unless one of its weights
    would round to 0 there (the row spans more than 8 bits): then each of that row's weights
    takes the exponent that fits itself, and Loihi sums the ``Dense`` of the exponents into
    the neuron's ``a_in``. A weight under half an ``a_in`` unit rounds to 0 even so, as every
    weight of exponent 0 rounds to the nearest unit (:func:`dropped` finds them). Rows within
    8 bits keep their one exponent: the integers of networks that fit are those they were.

    Raises:
        ValueError: naming ``what`` and the sPLLs where every weight of a row rounds to 0
            (its synapses would vanish), unless ``may_vanish``.
    """
    big = np.max(np.abs(values), axis=1)
    row_exp = np.array([mantissa(float(b), what)[1] if b > 0 else 0 for b in big], np.int64)
    exp = np.repeat(row_exp[:, None], values.shape[1], axis=1)
    w = np.clip(np.round(values / 2.0**exp).astype(np.int64), -255, 255)
    span = ((values != 0) & (w == 0)).any(axis=1)
    if span.any():
        size = np.abs(values[span])
        own = np.maximum(np.ceil(np.log2(np.maximum(size, 1e-300) / 255.0)), 0)
        exp[span] = np.where(size > 0, own, exp[span]).astype(np.int64)
        w[span] = np.clip(np.round(values[span] / 2.0 ** exp[span]), -255, 255).astype(np.int64)
    vanished = np.flatnonzero((big > 0) & ~w.any(axis=1))
    if vanished.size and not may_vanish:
        raise ValueError(
            f"{spll_ranges(vanished)}: a {what} weight of at most "
            f"{float(np.max(big[vanished])):.3g} a_in units rounds to 0 in Loihi's 8-bit "
            "weights, every one of the row (the synapse would vanish); target lava-standard "
            "cannot represent it (try fewer gate levels or another dt)"
        )
    return {int(e): np.where(exp == e, w, 0) for e in np.unique(exp)}, vanished


def dropped(values: np.ndarray, weights: dict[int, np.ndarray], what: str) -> tuple[str, ...]:
    """A note on the weights of ``values`` (rows sPLLs, ``a_in`` units) that :func:`dense_weights`
    rounded to 0 beside others of their row that it kept (under half an ``a_in`` unit), or
    none."""
    kept = np.any([w != 0 for w in weights.values()], axis=0)
    lost = (values != 0) & ~kept & kept.any(axis=1, keepdims=True)
    if not lost.any():
        return ()
    rows = np.flatnonzero(lost.any(axis=1))
    part = np.abs(values * lost).sum(axis=1)[rows] / np.abs(values[rows]).sum(axis=1)
    return (
        f"{spll_ranges(rows)}: {int(lost.sum())} {what} weights under half of Loihi's smallest "
        f"(at most {float(np.max(np.abs(values[lost]))):.3g} a_in units, together at most "
        f"{float(np.max(part)):.2g} of an sPLL's) round to 0: those levels add nothing to the "
        "TDE's trigger",
    )


def bias(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``values ≈ mant << exp`` per neuron, mantissa 13-bit signed, exponent ``0..7``."""
    v = np.asarray(values, dtype=float)
    exp = np.clip(np.ceil(np.log2(np.maximum(np.abs(v), 1.0) / 4095.0)), 0, 7).astype(np.int64)
    mant = np.round(v / 2.0**exp).astype(np.int64)
    if np.any(np.abs(mant) > 4096):
        i = int(np.argmax(np.abs(mant)))
        raise ValueError(
            f"lava-standard: bias {v[i]:g} of neuron {i} exceeds Loihi's 13-bit mantissa << 7"
        )
    return np.clip(mant, -4096, 4095), exp


def check_sums(dense: dict, lif: dict) -> None:
    """Every LIF target's summed synaptic input must fit ``a_in``'s 16 bits, as if all its
    sources fired at once (a refractory unit's own sum to ``4096 F`` at most, ``-4096 F`` at
    least); a ``GradedVec``'s (``graded``) has 24 bits, which its scale keeps
    (:func:`~mappings.lava.graded_current.graded_current`)."""
    pos: dict[str, np.ndarray] = {}
    neg: dict[str, np.ndarray] = {}
    for _, dst, w, e, bits in dense.values():
        if bits or is_graded(lif[dst]):
            continue  # graded spikes (the input's count, a current) or a graded target
        scaled = np.asarray(w, dtype=float) * 2.0**e
        pos[dst] = pos.get(dst, 0) + np.clip(scaled, 0, None).sum(axis=1)
        neg[dst] = neg.get(dst, 0) + np.clip(scaled, None, 0).sum(axis=1)
    for dst in pos:
        worst = max(float(np.max(pos[dst])), -float(np.min(neg[dst])) - 1)
        if worst > A_IN_MAX:
            raise ValueError(
                f"lava-standard: the synaptic input of {dst} can reach {worst:g}, beyond the "
                f"16-bit a_in of Loihi ({A_IN_MAX}); use fewer levels"
            )
