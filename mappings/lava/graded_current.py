"""A CCO's synaptic current kept at more than Loihi's ``u`` resolution: a ``GradedVec``
(``lava.proc.graded``, 24-bit graded spikes) that holds it and passes it to the CCO every
step, what ``lava_standard(current="graded")`` builds (:mod:`mappings.lava.standard`).

Why: Loihi's LIF decays its current ``u`` by ``sgn(u) (|u| keep >> 12)``, a truncation that
takes up to a whole unit of ``u`` every step. A feedback kick of a few thousand units decaying
by ``δ = 17/4096`` loses 10 % of its charge that way (:func:`~mappings.lava.loihi.kept_charge`);
a network whose TDEs fire a few times a second (``biotac-time-scaled-lif`` at 32 Hz) sees it
as a CCO running slow.

**Construction** (per set of sPLLs with CCO population ``cco``; ``c`` in units of ``2^-s``
``a_in`` units, ``keep = 4096 - δ`` the CCO synapse's decay):

* ``cur`` (``GradedVec``, ``vth = 0``): ``c(t) = c(t-1) + ⌊-δ c(t-1) / 4096⌋ + K`` for a TDE
  spike relayed in step ``t - 1`` (``cur_keep``: weight 1; ``cur_decay``: ``-δ`` at
  ``weight_exp`` -12, split into two ``Dense`` where ``δ`` has more than 8 bits; ``gate_cur``:
  the kick ``K = round(k keep / 4096 · 2^s)``, ``k`` the CCO's own kick in ``a_in`` units,
  15 bits as two ``Dense`` of exponents 7 and 0). So ``c(t)`` is what the current will be in
  step ``t + 1`` before that step's kick, decayed in steps of ``2^-s`` ``a_in`` units.
* The CCO (``du = 4095``: ``u`` is its ``a_in`` alone, every step) gets the kick ``k`` directly
  from the TDE's relay, as with a LIF current, and ``⌊c(t-1) / 2^s⌋`` from ``cur``
  (``cur_cco``: weight 1 at ``weight_exp -s``): ``u(t) = 64 (k + ⌊c(t-1) / 2^s⌋)``, the
  current decayed exactly but for its last ``a_in`` unit, which is not carried over.
* ``on`` (a LIF that fires every step: ``v = bias = 1 > 0``) adds ``P = round(δ 2^(s-1) /
  4096)`` to ``c`` every step (``on_cur``), a pedestal whose fixed point ``⌊4096 P / δ⌋`` (where
  a decaying ``c`` comes to rest) is about half an ``a_in`` unit: the CCO then gets the current
  rounded to an ``a_in`` unit, and 0 where it is 0. Where ``4096 / δ`` is coarser than that
  half unit, ``P`` rounds to 0 and the current is truncated.
* The refractory unit's force reaches the CCO's ``a_in`` as before; with ``du = 4095`` its
  start (``F keep``) is 0 and its hold ``4096 F`` a step (:func:`~mappings.lava.integers.
  refractory_unit`).

``s`` is as large as 12 allows with ``K`` within 15 bits and ``c`` within 24 bits at the most
the kicks can add up to (one every ``gap`` steps, the TDE's refractory steps + 1:
:func:`carried`). The CCO's ``a_in`` carries the kick, the current and the force in one step:
its threshold is chosen so that they fit 16 bits (:func:`~mappings.lava.integers._threshold`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .loihi import DECAY_BITS, DECAY_UNITY, SPLIT_MAX, most_kicks, split_weight

#: Bits of a graded spike (Loihi 2's, ``PyGradedVecModelFixed``'s precision).
GRADED_BITS = 24
#: Finest scale of ``c``: ``2^-12`` ``a_in`` units (as fine as the decay's 12 bits).
MAX_SCALE = 12


class GradedCurrent(NamedTuple):
    """The ``GradedVec`` population (in ``lif``, marked ``graded``) and ``Dense`` of one set's
    CCO currents, in :class:`~mappings.lava.standard.LavaStandard`'s forms."""

    lif: dict
    dense: dict


def carried(held: np.ndarray) -> np.ndarray:
    """How many kicks a CCO's ``a_in`` may carry at once with a graded current, per sPLL: its
    own kick plus the current, at most ``1 / (1 - (keep / 4096)^gap)`` kicks, the most the
    worst of its holds allows.

    Args:
        held: per sPLL and hold ``(steps, keep_u, keep_v, gap)`` of its CCO (``keep_u`` the
            synapse's decay, ``gap`` the fewest steps between two TDE spikes), shape
            ``(N, holds, 4)``.
    """
    return 1.0 + np.max(most_kicks(held[..., 1], held[..., 3]), axis=1)


def graded_current(
    cco: str,
    tag: str,
    delta: int,
    kicks: np.ndarray,
    accumulated: np.ndarray,
    relay: np.ndarray,
    size_gate: int,
) -> GradedCurrent:
    """The graded currents of the CCO population ``cco`` (the module docstring).

    Args:
        cco: the CCO population's name; ``tag`` its set's (``cur{tag}`` is the new one).
        delta: the CCO synapse's 12-bit decay ``δ`` (1..4095).
        kicks: each CCO's kick per TDE spike [a_in units] as its ``Dense`` realise it,
            shape ``(size,)``.
        accumulated: the most kicks the current can hold at once, per CCO (:func:`carried`
            less the kick itself), shape ``(size,)``.
        relay: the gate row of each CCO's TDE relay, shape ``(size,)``.
        size_gate: the gate population's size.

    Raises:
        ValueError: where the kicks do not fit 15 bits even at ``s = 0``.
    """
    size = kicks.size
    keep = (DECAY_UNITY - delta) / DECAY_UNITY
    carry = np.asarray(kicks, dtype=np.float64) * keep
    most = float(np.max(carry * accumulated)) + 1.0  # c's largest [a_in units], the pedestal's

    scale = min(
        MAX_SCALE,
        math.floor(math.log2(SPLIT_MAX / max(float(np.max(carry)), 1.0))),
        math.floor(math.log2((2 ** (GRADED_BITS - 1) - 1) / most)),
    )
    if scale < 0:
        raise ValueError(
            f"lava-standard: a graded CCO current's kick of {float(np.max(kicks)):g} a_in units "
            "does not fit 15 bits (use current='lif')"
        )
    k = np.round(carry * 2.0**scale).astype(np.int64)
    name, on = f"cur{tag}", f"on{tag}"
    eye = np.eye(size, dtype=np.int64)
    zeros = np.zeros(size, np.int64)
    lif = {
        name: {"graded": 1, "du": 0, "dv": 0, "vth": 0, "bias_mant": zeros, "bias_exp": zeros},
        # fires every step (v = bias = 1 > 0): the half unit's pedestal
        on: {"du": 4095, "dv": 4095, "vth": 0, "bias_mant": zeros + 1, "bias_exp": zeros},
    }
    dense = {f"{name}_keep": (name, name, eye, 0, GRADED_BITS)}
    pedestal = round(delta * 2.0 ** (scale - 1) / DECAY_UNITY) if scale else 0
    for e, w in split_weight(pedestal):
        if w:
            dense[f"{on}_{name}_{e}"] = (on, name, w * eye, e, 0)
    shift = max(0, delta.bit_length() - 8)
    for suffix, value, e in (("decay", delta >> shift, shift - DECAY_BITS),
                             ("decay_low", delta & ((1 << shift) - 1), -DECAY_BITS)):  # fmt: skip
        if value:
            dense[f"{name}_{suffix}"] = (name, name, -value * eye, e, GRADED_BITS)
    for e, w in split_weight(k):
        if w.any():
            weights = np.zeros((size, size_gate), np.int64)
            weights[np.arange(size), relay] = w
            dense[f"gate_{name}_{e}"] = ("gate", name, weights, e, 0)
    dense[f"{name}_{cco}"] = (name, cco, eye, -scale, GRADED_BITS)
    return GradedCurrent(lif, dense)
