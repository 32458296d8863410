"""The discrete-time algorithm of the Lava sPLL models and the values of their process variables.

Both ProcessModels run the discrete-time model specified in ``engine/src/fixed_point.rs`` (the
fixed-point reference of ``quantize``), one Lava time step per step ``k = 1 .. K`` of ``dt``:

1. TDE synapses: if the CCO fired at ``k - 1``, the trigger current gets
   ``gate * f_{k-1}`` (the facilitatory current as it stood when the CCO fired); then
   ``f_k = decay(f_{k-1}) + n_k w_fac`` (``n_k`` input spikes arrive at step ``k`` by the
   model's grid, :mod:`spll_hw.model.grid`) and ``g_k = decay(g_{k-1}) + gate``.
2. TDE membrane driven by ``g_k >> c_tde`` (``c``: the currents' fractional bits).
3. CCO synapse ``u_k = decay(u_{k-1}) + [TDE fired at k - 1] w_cco``.
4. CCO membrane driven by ``(u_k + bias) >> c_cco``.

A membrane with drive ``d``: during its refractory period the counter counts down and ``v``
stays 0; otherwise ``v_k = decay(v_{k-1}) + d`` and ``v_k > threshold`` is a spike (reset to 0,
counter set to the refractory steps), reported at ``k dt``. Currents are in "potential per step"
units: a current ``I`` into a membrane ``(tau, C)`` is ``I tau (1 - e^{-dt/tau}) / C``
(:func:`spll_hw.model.discrete.membrane_gain`), so a constant current charges the membrane
exactly as in continuous time.

``floating_pt`` (:class:`FloatParameters`) is this algorithm with real numbers, the exact
coefficients ``decay(x) = x e^{-dt/tau}`` and no fractional bits (``c = 0``): the ideal chip,
whose only differences from the golden engine are the time grid and the per-step treatment of
decaying synaptic currents.
``fixed_pt`` is the same algorithm on the integers of ``quantize.quantize(network, profile)``
(``QuantizedNetwork.fixed``): ``decay(x) = (x (2^D - delta)) >> D``, states saturating at
``2^(state_bits - 1) - 1``, the gate ``(f * trg_mantissa) >> trg_shift``; it agrees with
the ``golden-fixed-point`` backend spike for spike.
"""

import math
from dataclasses import dataclass

import numpy as np

from spll_hw.model.discrete import decay_fraction, membrane_gain
from spll_hw.model.grid import refractory_steps
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES


@dataclass(frozen=True)
class FloatParameters:
    """Real-valued coefficients of the algorithm for a network, every array of shape ``(N,)``.

    ``d_*``: fraction of a state lost per step, ``1 - e^{-dt/tau}`` (Lava's ``du``/``dv``
    convention); ``fac_weight`` [A] added to ``f`` per input spike; ``gate`` [V/(A step)] turns
    ``f`` into a trigger-current jump; ``cco_weight`` [V/step] the CCO synapse jump per TDE
    spike; ``bias`` [V/step]; thresholds [V]; refractory periods in steps.
    """

    dt: float
    d_fac: np.ndarray
    d_trg: np.ndarray
    d_tde: np.ndarray
    fac_weight: np.ndarray
    gate: np.ndarray
    tde_threshold: np.ndarray
    tde_refr: np.ndarray
    d_cco_syn: np.ndarray
    d_cco: np.ndarray
    cco_weight: np.ndarray
    bias: np.ndarray
    cco_threshold: np.ndarray
    cco_refr: np.ndarray

    @classmethod
    def from_network(cls, network: Network, dt: float) -> "FloatParameters":
        """The coefficients of ``network`` at time step ``dt`` [s]."""
        if not isinstance(network, Network):
            raise ValueError(f"expected a spll_hw Network, got {type(network).__name__}")
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"time step dt must be finite and > 0 s, got {dt!r}")
        p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
        d = {name: decay_fraction(p[name], dt) for name in PARAM_NAMES if name.startswith("tau_")}
        r = roles()  # the model's statement names every parameter used here
        # potential gained in one step per unit constant current [V/A]
        w = {m: membrane_gain(p[m.tau], p[m.c], dt) for m in (r.tde, r.cco)}
        return cls(
            dt=dt,
            d_fac=d[r.fac.tau],
            d_trg=d[r.trg.tau],
            d_tde=d[r.tde.tau],
            fac_weight=p[r.driven.gain],
            gate=p[r.gated.gain] * w[r.tde],
            tde_threshold=p[r.tde.v_thr],
            tde_refr=refractory_steps(p[r.tde.t_refr], dt),
            d_cco_syn=d[r.cco_syn.tau],
            d_cco=d[r.cco.tau],
            cco_weight=p[r.fed.gain] * w[r.cco],
            bias=p[r.offset] * w[r.cco],
            cco_threshold=p[r.cco.v_thr],
            cco_refr=refractory_steps(p[r.cco.t_refr], dt),
        )


def split_weights(weights: np.ndarray, mantissa_bits: int = 8) -> dict[int, np.ndarray]:
    """Integer weights as ``{exponent: mantissas}`` with unsigned ``mantissa_bits``-bit mantissas
    (Lava's ``Dense`` shares one exponent): ``weights[i] == mantissas[i] << exponent`` for the
    entries of each group and 0 elsewhere. Raises if a weight has bits below its exponent."""
    w = np.asarray(weights, dtype=np.int64)
    exps = np.array([max(0, int(x).bit_length() - mantissa_bits) for x in w], dtype=np.int64)
    if np.any((w >> exps) << exps != w):
        raise ValueError(f"weights {w} are not {mantissa_bits}-bit mantissas times 2**exponent")
    return {int(e): np.where(exps == e, w >> e, 0) for e in np.unique(exps)}
