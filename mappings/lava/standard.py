"""The standard sPLL on Lava's own processes: its integer parameters, the builder of
``spll-hw export --to lava-standard``.

Lava's ``lava.proc.lif.process.LIF`` with its bit-accurate model ``PyLifModelBitAcc`` (tag
``fixed_pt``) and ``lava.proc.dense.process.Dense`` with ``PyDenseModelBitAcc`` are the Loihi
neuron and synapse, bit for bit. The standard sPLL (:mod:`mappings.standard.construction`)
needs nothing else:

==========  ===========  ======================================================================
population  size         LIF parameters (one ``du``, ``dv``, ``vth`` per process)
==========  ===========  ======================================================================
``level``   M = N K      ``du`` of ``tau_tde_fac`` (``u`` is a copy of ``I_fac``), ``dv = 4095``
                         (``v`` follows ``u``), ``vth = 0``; the level threshold is the neuron's
                         negative bias ``-thresholds[i, k]`` in ``u`` units
``gate``    M + 2N       ``du = 4095``, ``dv = 4095`` (memoryless), ``vth = 1`` (``v > 64``):
                         rows ``0..M-1`` the AND neurons (level + CCO, weight 1 each), rows
                         ``M..M+2N-1`` relays of each TDE and CCO (weight 2)
``tde``     N            ``du`` of ``tau_tde_trg``, ``dv`` of ``tau_tde``, ``vth`` up to
                         :data:`VTH_TDE` (lower where one trigger would overflow ``a_in``)
``cco``     N            ``du`` of ``tau_cco_syn``, ``dv`` of ``tau_cco``, ``vth`` up to
                         :data:`VTH_CCO` (lower where the offset needs it), bias = the offset
==========  ===========  ======================================================================

A LIF process has one ``du``, ``dv`` and ``vth``: where sPLLs' decays differ (grouped or
time-scaled layouts), each set of decays gets its own ``level``, ``tde`` and ``cco`` process
(``level0``, ``tde0``, ... ; :attr:`LavaStandard.members` says which sPLLs each holds).

Connections (``Dense``, 8-bit weights of one sign each, ``weight_exp``): input -> level
(graded: the input spike count of the step), level -> gate, tde -> gate, cco -> gate,
gate -> tde (the trigger: AND neuron k adds ``g_tde_trg · increments[i, k]``; the TDE relay's
self-inhibition), gate -> cco (the TDE relay's ``g_cco``; the CCO relay's self-inhibition).
Lava has ``LIFRefractory`` only in floating point, so a charge-balanced self-inhibition
stands in for the refractory periods
(:func:`~mappings.standard.construction.inhibition_weights`); NIR's refractory unit is not
ported (its timers would need kicks far beyond 24-bit states at ~100 held steps; error per
preset: docs/backends.md).

**Integers** (``q`` = 12 decay bits as Loihi): a time constant ``tau`` is
``δ = round(4096 (1 - e^{-dt/tau}))``; ``u`` decays by ``δ`` (``du = δ - 1``, Lava adds
Loihi's offset 1), ``v`` by ``δ`` (``dv = δ``; 0, no leak, where ``tau`` is too long for 12
bits, as the CCO's 0.314 s at 10 µs). A current ``I`` into a membrane of threshold
``θ = vth · 64`` is the per-step potential ``I τ' (δ_v / 4096) / (C v_thr) · θ``. A ``Dense``
weight ``w`` with exponent ``e`` adds ``w 2^e · 64`` to ``u`` (Lava shifts the synaptic input by
6 bits); its accumulated sum must fit ``a_in``'s 16 bits.

**Step**: Lava's ``LoihiProtocol`` with Loihi's arithmetic, stated in :mod:`mappings.lava.loihi`
(whose :func:`~mappings.lava.loihi.simulate_fixed` is its bit-accurate numpy executor); the
exported ``run.py`` (:mod:`mappings.lava.standalone_run`) runs Lava itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mappings.standard.construction import (
    DEFAULT_INPUT_RATE,
    DEFAULT_LEVELS,
    DEFAULT_PLACEMENT,
    Gate,
    gate_layout,
    gate_levels,
    inhibition_weights,
    target_parameters,
)
from spll_hw.model.discrete import decay_constant, realised_tau
from spll_hw.model.roles import roles
from spll_hw.network import Network

from .loihi import A_IN_MAX, DECAY_BITS, DECAY_UNITY

#: Default time step [s] (the Loihi-2-like profile's).
DEFAULT_DT = 1e-5
#: Thresholds of the TDE and CCO processes (17-bit ``vth``; ``θ = vth · 64``).
VTH_TDE = 2**16
VTH_CCO = 2**17 - 1
#: What a level neuron's ``u`` gains per input spike at most (keeps thresholds in the bias).
LEVEL_BIAS_MAX = 4095 << 7
#: Most sets of distinct decays (LIF processes per population) a network may need.
MAX_GROUPS = 16

#: The export folder's ``README.md`` (:meth:`LavaStandard.readme` fills it in).
README = """# sPLL network on Lava's own processes

{n} sPLLs as the standard-neuron construction ({k} gate levels) on `lava.proc.lif` LIF,
`lava.proc.dense` Dense and `lava.proc.io` ring buffers, with their bit-accurate fixed-point
models, dt = {dt:g} s. Needs numpy and lava-nc 0.10 only (`lava_compat.py` lets lava-nc 0.10
import on Python 3.11; install it with `pip install --ignore-requires-python lava-nc==0.10.0`):

    python run.py spikes.npy 1.0     # input spike times [s] (.npy), duration [s]

prints JSON with `tde_counts` and `cco_counts` per sPLL. `params.npz`: the integers
(`lif.POP.*`: du, dv, vth, bias_mant, bias_exp; `dense.NAME.weights` / `.meta`: source, target,
weight_exp, num_message_bits); `standard.json`: what they stand for; `spll_grid.py`: the step
each input spike counts in (spll-hw's grid rule).

## Check lava-nc against `check.json`

`check_inputs.npz` holds the inputs of the export's check and `check.json` the TDE and CCO
spike count of every sPLL on each, as spll-hw's numpy run of these integers counted them;
Lava's bit-accurate models count the same, exactly:

    python run.py --check             # every input (Lava steps ~1-2 thousand times a second)
    python run.py --check 0 3         # inputs 0 and 3 of check.json

prints a table and exits 0 when every count is `check.json`'s, 1 naming the inputs and sPLLs
that are not (`check_counts.py` compares them).
"""


@dataclass(frozen=True)
class LavaStandard:
    """Integer parameters of the standard sPLL on Lava's processes.

    Attributes:
        dt: time step [s].
        n_spll, levels: N and K.
        lif: per population (``gate`` and per set of decays ``level``, ``tde``, ``cco``):
            ``du``, ``dv``, ``vth`` (ints) and
            ``bias_mant``, ``bias_exp`` (int arrays of the population's size).
        dense: name -> ``(source, target, weights (target, source) int array, weight_exp,
            num_message_bits)``; source ``"input"`` is the spike generator.
        gate: the gate the integers realise.
        members: population -> the sPLLs (indices) it holds, for every population but
            ``gate``; a level population holds their K level neurons each, in order.
    """

    dt: float
    n_spll: int
    levels: int
    lif: dict
    dense: dict
    gate: Gate
    members: dict

    def arrays(self) -> dict[str, np.ndarray]:
        """Flat ``name -> array`` form (what the export writes to ``params.npz``)."""
        out = {"dt": np.array(self.dt), "n_spll": np.array(self.n_spll)}
        for pop, p in self.lif.items():
            for key, value in p.items():
                out[f"lif.{pop}.{key}"] = np.asarray(value)
        for pop, idx in self.members.items():
            out[f"members.{pop}"] = np.asarray(idx)
        for name, (src, dst, w, e, bits) in self.dense.items():
            out[f"dense.{name}.weights"] = np.asarray(w)
            out[f"dense.{name}.meta"] = np.array([src, dst, str(e), str(bits)])
        return out

    def info(self) -> dict:
        """The export folder's ``standard.json``: the gate levels and each population's
        decays and threshold."""
        return {
            "dt": self.dt,
            "n_spll": self.n_spll,
            "gate_levels": self.levels,
            "gate_placement": self.gate.placement,
            "thresholds_A": self.gate.thresholds.tolist(),
            "increments_A": self.gate.increments.tolist(),
            "populations": {
                k: {"du": int(v["du"]), "dv": int(v["dv"]), "vth": int(v["vth"])}
                for k, v in self.lif.items()
            },
        }

    def readme(self) -> str:
        """The export folder's ``README.md``: what it holds and how to run it."""
        return README.format(n=self.n_spll, k=self.levels, dt=self.dt)


def lava_standard(
    network: Network,
    *,
    dt: float = DEFAULT_DT,
    levels: int = DEFAULT_LEVELS,
    placement: str = DEFAULT_PLACEMENT,
    input_rate: float = DEFAULT_INPUT_RATE,
) -> LavaStandard:
    """The integers of ``network`` as the standard sPLL on Lava's LIF and Dense processes.

    One LIF process has one ``du`` and ``dv``: sPLLs whose 12-bit decays agree share the
    level, TDE and CCO processes, and each other set of decays (a time-scaled or grouped
    layout) gets its own (``level1``, ``tde1``, ``cco1``, ...; :attr:`LavaStandard.members`).

    Raises:
        ValueError: naming the parameter and the target ``lava-standard`` when the network
            cannot be represented: more than :data:`MAX_GROUPS` sets of decays, a decay outside
            12 bits at this ``dt``, or a weight, bias or synaptic sum outside Loihi's words.
    """
    p, r = target_parameters(network, dt, "lava-standard"), roles()
    decay = {}
    for name in r.time_constants:
        delta = decay_constant(p[name], dt, DECAY_BITS)
        # A potential may not decay at all (dv = 0: an integrator); a current decays by at
        # least 1 (du + 1, Loihi's offset).
        low = 0 if name in (r.tde.tau, r.cco.tau) else 1
        bad = np.flatnonzero((delta < low) | (delta > 4095))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"sPLL {i}: {name} = {p[name][i]:g} s at dt = {dt:g} s needs a 12-bit decay of "
                f"{delta[i]}; target lava-standard needs {low}..4095 (change dt)"
            )
        decay[name] = delta
    # One LIF process has one du and dv: sPLLs whose decays agree share processes.
    keys = np.stack([decay[name] for name in decay], axis=1)
    _, group_of = np.unique(keys, axis=0, return_inverse=True)
    group_of = group_of.reshape(-1)
    n_groups = int(group_of.max()) + 1
    if n_groups > MAX_GROUPS:
        raise ValueError(
            f"tau_* differ between sPLLs so that {n_groups} sets of 12-bit decays remain; target "
            f"lava-standard runs one LIF process per set and population, at most {MAX_GROUPS} "
            "(use a vary-offset or grouped layout)"
        )
    gate = gate_levels(network, levels, placement, input_rate)
    n, k = network.n_spll, gate.n_levels
    layout = gate_layout(n, k, timers=False)
    m, size_gate, spll_of_row = layout.n_and, layout.size, layout.spll_of_and
    relay_tde, relay_cco, tde_gate, cco_gate = (
        layout.relay_tde,
        layout.relay_cco,
        layout.from_tde,
        layout.from_cco,
    )

    # Per-step potential of a current [A], in units of each membrane's θ (per sPLL).
    def per_step(membrane, theta):
        d = decay[membrane.tau]
        safe = np.where(d == 0, 1, d)
        # A membrane of decay d gains tau' d / 2^12 per step per unit current; an integrator dt.
        gain = np.where(d == 0, dt, realised_tau(safe, dt, DECAY_BITS) * safe / DECAY_UNITY)
        return gain / (p[membrane.c] * p[membrane.v_thr]) * theta

    # The CCO's threshold is as fine as its offset (bias, at most 4095 << 7 a step) allows.
    unit_offset = float(np.max(p[r.offset] * per_step(r.cco, 1.0)))
    vth_cco = int(min(VTH_CCO, 0.95 * (4095 << 7) / max(unit_offset, 1e-300) / 64))
    if vth_cco < 64:
        raise ValueError(
            f"lava-standard: i_cco_offset = {np.max(p['i_cco_offset']):g} A charges the CCO by "
            f"{unit_offset:.3g} thresholds a step at dt = {dt:g} s; Loihi's bias leaves it "
            "fewer than 64 threshold units (use a smaller dt)"
        )
    # The TDE's threshold is as fine as one CCO spike's trigger (every level at once, through
    # 16-bit a_in) allows.
    unit_trigger = float(
        np.max(p[r.gated.gain] * gate.increments.sum(axis=1) * per_step(r.tde, 1.0))
    )
    vth_tde = int(min(VTH_TDE, 0.9 * A_IN_MAX / max(unit_trigger, 1e-300)))
    if vth_tde < 64:
        raise ValueError(
            f"lava-standard: g_tde_trg = {np.max(p['g_tde_trg']):g} gives a trigger of "
            f"{unit_trigger:.3g} TDE thresholds in one step at dt = {dt:g} s; Loihi's 16-bit "
            "synaptic input leaves it fewer than 64 threshold units (use a smaller dt)"
        )
    theta_t, theta_c = vth_tde << 6, vth_cco << 6
    k_tde = per_step(r.tde, theta_t)
    k_cco = per_step(r.cco, theta_c)

    # The network-wide arrays and matrices; cut into groups below.
    # level: u = I_fac / g_fac * S, S = 64 w 2^e per input spike; thresholds in the bias.
    top = float(np.max(gate.thresholds / p[r.driven.gain][:, None]))
    w_in, e_in = _mantissa(LEVEL_BIAS_MAX / top / 64.0, "input weight", floor=True)
    s = 64 * w_in * 2.0**e_in
    level_bias = _bias(-(gate.thresholds / p[r.driven.gain][:, None]).reshape(m) * s)
    cco_bias = _bias(p[r.offset] * k_cco)
    level_gate = np.zeros((size_gate, m), np.int64)
    level_gate[np.arange(m), np.arange(m)] = 1
    trigger = np.zeros((n, size_gate))
    trigger[spll_of_row, np.arange(m)] = (
        (p[r.gated.gain] * k_tde)[:, None] * gate.increments
    ).reshape(m) / 64.0
    feedback = np.zeros((n, size_gate))
    feedback[np.arange(n), relay_tde] = p[r.fed.gain] * k_cco / 64.0
    inh = inhibition_weights(network, input_rate)
    tde_inh = np.zeros((n, size_gate))
    tde_inh[np.arange(n), relay_tde] = -inh["tde"] * dt * theta_t / 64.0
    cco_inh = np.zeros((n, size_gate))
    cco_inh[np.arange(n), relay_cco] = -inh["cco"] * dt * theta_c / 64.0
    to_tde = {"gate_tde": _weights(trigger, f"trigger ({r.gated.gain})"),
              "gate_tde_refractory": _weights(tde_inh, f"{r.tde.t_refr} stand-in")}  # fmt: skip
    to_cco = {"gate_cco": _weights(feedback, r.fed.gain),
              "gate_cco_refractory": _weights(cco_inh, f"{r.cco.t_refr} stand-in")}  # fmt: skip

    lif = {"gate": {"du": 4095, "dv": 4095, "vth": 1, "bias_mant": np.zeros(size_gate, np.int64),
                    "bias_exp": np.zeros(size_gate, np.int64)}}  # fmt: skip
    members: dict[str, np.ndarray] = {}
    dense: dict = {}
    for g in range(n_groups):
        idx = np.flatnonzero(group_of == g)
        rows = (idx[:, None] * k + np.arange(k)).reshape(-1)  # their level / AND rows
        i0 = int(idx[0])
        tag = "" if n_groups == 1 else str(g)
        level, tde, cco = f"level{tag}", f"tde{tag}", f"cco{tag}"
        lif[level] = {"du": int(decay[r.fac.tau][i0]) - 1, "dv": 4095, "vth": 0,
                      "bias_mant": level_bias[0][rows],
                      "bias_exp": level_bias[1][rows]}  # fmt: skip
        lif[tde] = {"du": int(decay[r.trg.tau][i0]) - 1, "dv": int(decay[r.tde.tau][i0]),
                    "vth": vth_tde, "bias_mant": np.zeros(idx.size, np.int64),
                    "bias_exp": np.zeros(idx.size, np.int64)}  # fmt: skip
        lif[cco] = {"du": int(decay[r.cco_syn.tau][i0]) - 1, "dv": int(decay[r.cco.tau][i0]),
                    "vth": vth_cco, "bias_mant": cco_bias[0][idx],
                    "bias_exp": cco_bias[1][idx]}  # fmt: skip
        members[level], members[tde], members[cco] = idx, idx, idx
        dense[f"input_{level}"] = ("input", level, _col(np.full(rows.size, w_in)), e_in, 8)
        dense[f"{level}_gate"] = (level, "gate", level_gate[:, rows], 0, 0)
        dense[f"{tde}_gate"] = (tde, "gate", tde_gate[:, idx], 0, 0)
        dense[f"{cco}_gate"] = (cco, "gate", cco_gate[:, idx], 0, 0)
        for name, (w, e) in to_tde.items():
            dense[name.replace("tde", tde, 1)] = ("gate", tde, w[idx], e, 0)
        for name, (w, e) in to_cco.items():
            dense[name.replace("cco", cco, 1)] = ("gate", cco, w[idx], e, 0)
    _check_sums(dense)
    return LavaStandard(float(dt), n, k, lif, dense, gate, members)


def _col(values: np.ndarray) -> np.ndarray:
    return np.asarray(values, dtype=np.int64).reshape(-1, 1)


def _mantissa(value: float, what: str, floor: bool = False) -> tuple[int, int]:
    """``value ≈ w 2^e`` with ``w`` an 8-bit weight (``1..255``) and ``e`` in ``0..7`` (a
    negative exponent shifts the accumulated sum right, which only truncates more)."""
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"lava-standard: {what} {value!r} is not a positive number")
    e = max(0, math.ceil(math.log2(value / 255.0)))
    if e > 7:
        raise ValueError(f"lava-standard: {what} {value:g} exceeds 255 · 2^7")
    w = math.floor(value / 2.0**e) if floor else round(value / 2.0**e)
    return max(1, min(255, w)), e


def _weights(values: np.ndarray, what: str) -> tuple[np.ndarray, int]:
    """Integer weights of one sign (``|w| <= 255``) and the exponent that fits the largest;
    ``ValueError`` naming ``what`` where a weight that is not 0 would round to 0 (the synapse
    would vanish)."""
    big = float(np.max(np.abs(values)))
    if big == 0:
        return np.zeros(values.shape, np.int64), 0
    _, e = _mantissa(big, what)
    w = np.round(values / 2.0**e).astype(np.int64)
    lost = np.flatnonzero(((values != 0) & (w == 0)).any(axis=1))
    if lost.size:
        raise ValueError(
            f"sPLL {int(lost[0])} (of {lost.size}): the {what} weight "
            f"{float(np.max(np.abs(values[lost[0]]))):.3g} rounds to 0 in Loihi's 8-bit weights; "
            "target lava-standard cannot represent it"
        )
    return np.clip(w, -255, 255), e


def _bias(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _check_sums(dense: dict) -> None:
    """Every target's summed synaptic input must fit ``a_in``'s 16 bits."""
    for name, (_, _, w, e, bits) in dense.items():
        if bits:
            continue  # the graded input: one spike of weight w 2^e per count (checked at run)
        worst = max(np.clip(w, 0, None).sum(axis=1).max(), -np.clip(w, None, 0).sum(axis=1).min())
        if worst * 2.0**e > A_IN_MAX:
            raise ValueError(
                f"lava-standard: the synaptic sum of {name} can reach {worst * 2.0**e:g}, beyond "
                f"the 16-bit a_in of Loihi ({A_IN_MAX}); use fewer levels"
            )
