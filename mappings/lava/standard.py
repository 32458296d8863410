"""The standard sPLL on Lava's own processes: its integer parameters, the builder of
``spll-hw export --to lava-standard``.

Lava's ``lava.proc.lif.process.LIF`` with its bit-accurate model ``PyLifModelBitAcc`` (tag
``fixed_pt``) and ``lava.proc.dense.process.Dense`` with ``PyDenseModelBitAcc`` are the Loihi
neuron and synapse, bit for bit. The standard sPLL (:mod:`spll_hw.construction.gate`)
needs nothing else:

==========  ===========  ======================================================================
population  size         LIF parameters (one ``du``, ``dv``, ``vth`` per process)
==========  ===========  ======================================================================
``level``   M = N K      ``du`` of ``tau_tde_fac`` (``u`` is a copy of ``I_fac``), ``dv = 4095``
                         (``v`` follows ``u``), ``vth = 0``; the level threshold is the neuron's
                         negative bias ``-thresholds[i, k]`` in ``u`` units
``gate``    M + 2N       ``du = 4095``, ``dv = 4095`` (memoryless), ``vth = 1`` (``v > 64``):
                         rows ``0..M-1`` the AND neurons (level + CCO, weight 1 each), rows
                         ``M..M+2N-1`` relays of each TDE's and CCO's own spikes (weight 2)
``tde``     N            ``du`` of ``tau_tde_trg``, ``dv`` of ``tau_tde``, ``vth`` up to
                         :data:`VTH_TDE` (lower where one trigger would overflow ``a_in`` or
                         the refractory unit could not hold it)
``cco``     N            ``du`` of ``tau_cco_syn``, ``dv`` of ``tau_cco``, ``vth`` up to
                         :data:`VTH_CCO` (lower where the offset or the unit needs it), bias =
                         the offset
``hold_X``  N            per TDE and CCO population ``X``: ``du = dv = 4095``, ``vth = 1``; fires
                         on every step its neuron is held
``end_X``   N            ``du = 4095``, ``dv = 0`` (a counter), ``vth = R - 2``: fires on the
                         last held step
==========  ===========  ======================================================================

With ``current="graded"`` each set's CCOs have ``du = 4095`` and their currents live in a
``GradedVec`` ``cur`` (N, ``lava.proc.graded``), kept at a half ``a_in`` unit by ``on`` (N LIFs
that fire every step): :mod:`mappings.lava.graded_current`.

With ``hold="dithered"`` each held population ``X`` also has ``dither_X`` (N neurons, ``du =
4095``, ``dv = 0``, ``vth =`` :data:`DITHER_VTH`), which fires on every ``n``-th of its neuron's
spikes (below).

A LIF process of Lava has one ``du``, ``dv`` and ``vth`` (``Var`` of shape ``(1,)`` in
``lava.proc.lif.process.LIF``): where sPLLs' decays or refractory steps differ (grouped,
time-scaled or tuned layouts), each set gets its own ``level``, ``tde``, ``cco`` and units
(``level0``, ``tde0``, ``hold_tde0``, ... ; :attr:`LavaStandard.members` says which sPLLs each
holds), up to one set per sPLL. Each set costs about 40 Lava processes
(:attr:`LavaStandard.n_processes`), which lava-nc's CPU runtime starts as OS processes; the
exported ``run.py`` runs the sets one after another (they share only the input).

Connections (``Dense``, 8-bit weights of one sign each, one ``weight_exp`` per ``Dense``):
input -> level (graded: the input spike count of the step), level -> gate, tde -> gate,
cco -> gate, gate -> tde (the trigger: AND neuron k adds ``g_tde_trg · increments[i, k]``),
gate -> cco (the TDE relay's ``g_cco``), and the refractory units'. The trigger and ``g_cco``
give each target neuron the exponent that fits its own largest weight: one ``Dense`` per
exponent (``gate_tde_e3``, ...) where an sPLL set's weights span more than 8 bits. Where one
neuron's own weights span more (a trigger's levels placed on the network's band: 1.6 a_in units
beside 3120), each of its weights takes the exponent that fits itself, in that exponent's
``Dense``: Loihi sums every ``Dense`` into the neuron's 16-bit ``a_in`` (the sum of them all
must fit, as one's must). A trigger weight under half of Loihi's smallest (one ``a_in`` unit,
``64`` in ``u``) rounds to 0 as every weight rounds to its nearest: that level adds nothing to
the TDE. A ``g_cco`` weight under half of it even at the CCO's largest threshold vanishes: the
sPLL runs without feedback. :attr:`LavaStandard.notes` says both (the export's check against
golden measures what they cost); an sPLL whose trigger vanishes at every level is refused.

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

**Dithered hold** (``hold="dithered"``, :data:`HOLDS`). Whole steps restart a neuron up to half
a step late or early every cycle, which a TDE that bursts every few steps accumulates. With
this hold each neuron's period is ``R = base`` steps but every ``n``-th spike ``R + 1`` or ``R -
1`` (:func:`~spll_hw.model.holds.counter_dither`: the mean nearest ``t_refr / dt -
1/2``). ``dither_X`` counts the neuron's network spikes through its relay (weight ``255 // (n -
1)``, step ``s+2``) and fires on the ``n``-th, which resets it; its spike reaches ``end_X`` in
step ``s+3``, ``-1`` (one count more to go: the hold lasts ``R + 1``, ``R >= 3``) or ``+1`` (one
less: ``R - 1``, ``R >= 4``), and the force, ended by ``end_X``, lasts as long;
:func:`_fires_last` proves both holds. The export tries it after the compensated hold at each
step (:mod:`mappings.lava.dt_choice`).

The force and its removal pass through 16-bit ``a_in`` in one step (``4096 F`` beside the
trigger), which bounds ``F`` and with it the thresholds: at 10 µs the TDE's ``vth`` drops
below :data:`VTH_TDE` on hard-driven networks (24421 on biotac-vary-offset-lif).

**Integers** (``q`` = 12 decay bits as Loihi): a time constant ``tau`` is
``δ = round(4096 (1 - e^{-dt/tau}))``; ``u`` decays by ``δ`` (``du = δ - 1``, Lava adds
Loihi's offset 1), ``v`` by ``δ`` (``dv = δ``; 0, no leak, where ``tau`` is too long for 12
bits, as the CCO's 0.314 s at 10 µs). A kicked synapse too long for them takes ``δ = 1``,
Loihi's longest, and the gains into it keep their kicks' charge (:func:`loihi_decays`,
:func:`_charges`). The offset ``I`` into a CCO of threshold ``θ = vth · 64`` is the per-step
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

**Step**: Lava's ``LoihiProtocol`` with Loihi's arithmetic, stated in :mod:`mappings.lava.loihi`
(whose :func:`~mappings.lava.loihi.simulate_fixed` is its bit-accurate numpy executor); the
exported ``run.py`` (:mod:`mappings.lava.standalone_run`) runs Lava itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from spll_hw.construction.gate import (
    DEFAULT_INPUT_RATE,
    DEFAULT_LEVELS,
    DEFAULT_PLACEMENT,
    Gate,
    gate_layout,
    gate_levels,
    target_parameters,
)
from spll_hw.model.discrete import decay_constant, exact_propagator, membrane_gain, realised_tau
from spll_hw.model.holds import CounterDither, compensated_hold, counter_dither
from spll_hw.model.roles import roles
from spll_hw.network import Network

from . import standalone_run
from .graded_current import carried as kicks_carried
from .graded_current import graded_current
from .loihi import A_IN_MAX, DECAY_BITS, DECAY_UNITY, is_graded, most_kicks, split_weight

#: Default time step [s] of the backends, and the first the export tries without ``--dt``
#: (:mod:`mappings.lava.dt_choice`): at 10 µs the 12-bit decays of the longer time constants
#: round by 10-25 % (``tau_tde_fac``'s ``δ`` is 3 or 4), which costs 11 % TDE-rate error on
#: biotac-vary-offset-lif and vibtac-vary-offset-lif; at 50 µs they are 1.1 % and 3.7 % off
#: (docs/backends.md).
DEFAULT_DT = 5e-5
#: Gate levels of ``spll-hw export --to lava-standard`` (as nir-standard's, and for the same
#: reason: the 8-level gate is coarse on periodic input).
EXPORT_LEVELS = 16
#: Thresholds of the TDE and CCO processes (17-bit ``vth``; ``θ = vth · 64``).
VTH_TDE = 2**16
VTH_CCO = 2**17 - 1
#: What a level neuron's ``u`` gains per input spike at most (keeps thresholds in the bias).
LEVEL_BIAS_MAX = 4095 << 7
#: Largest force ``F`` of a refractory unit (``2^18 F`` in ``u``; its removal, ``-F keep``,
#: fits 16-bit a_in up to 8).
MAX_FORCE = 7
#: lava-nc 0.10's CPU runtime per Lava process (one OS process each), measured with the
#: exported run.py on 2 cores (2026-11-28): a set of 41 processes (one sPLL of
#: biotac-tuned-vary-offset-lif) ran 1000 steps in 6 s and 5000 in 25-30 s, the 45 of
#: biotac-vary-offset-peak (50 sPLLs, one set) 5000 in 46 s using about 0.4 GB. run.py runs a
#: network's sets one after another (:func:`~mappings.lava.standalone_run.split`).
LAVA_PROCESS_MB = 10
LAVA_PROCESS_STEP_S = 0.15e-3
#: Threshold of a refractory unit's dither counter (``v > 255 · 64``): a counter of period
#: ``n`` (2..16) counts ``255 // (n - 1)`` a spike, so that its ``n``-th spike, not its
#: ``n-1``-th, crosses (:func:`refractory_unit`).
DITHER_VTH = 255
#: The refractory holds of :func:`lava_standard` (``hold``): ``round(t_refr/dt - 1/2)`` steps
#: after every spike, or those a counter dithers, whose mean over a neuron's spikes is nearer
#: ``t_refr/dt - 1/2`` (:func:`~spll_hw.model.holds.counter_dither`).
HOLDS = ("compensated", "dithered")
#: Each CCO's synaptic current as :func:`lava_standard` (``current``) keeps it: the CCO LIF's
#: own ``u``, or a ``GradedVec`` that passes it to the CCO every step at ``2^-s`` of an ``a_in``
#: unit (:mod:`mappings.lava.graded_current`).
CURRENTS = ("lif", "graded")
#: Each hold in the folder's README.
HOLD_WORDS = {
    "compensated": "refractory periods are held `round(t_refr/dt - 1/2)` steps",
    "dithered": "refractory periods are held `floor` or `ceil` of `t_refr/dt - 1/2` steps,\n"
    "the other one spike in n (a counter, `dither_*`), so that the mean hold is nearest\n"
    "`t_refr/dt - 1/2`",
}
#: What each of :data:`CURRENTS` adds to the READMEs' list of Lava processes.
CURRENT_WORDS = {
    "lif": "",
    "graded": "\nEach CCO's current is a `lava.proc.graded` GradedVec's, kept at 2^-s of an a_in "
    "unit and\npassed to the CCO every step (Loihi's decay of a LIF's `u` truncates up to a "
    "unit a step).",
}
#: Longest refractory period in steps (the end counter's 17-bit ``vth = steps - 1``).
MAX_REFRACTORY_STEPS = 2**17

#: How to install what the folder's ``run.py`` needs (both READMEs).
NEEDS = (
    "Needs numpy and lava-nc 0.10 only (`lava_compat.py` lets lava-nc 0.10 import on Python "
    "3.11;\ninstall it with `pip install --ignore-requires-python lava-nc==0.10.0`):"
)

#: The export folder's ``README.md`` (:meth:`LavaStandard.readme` fills it in).
README = """# sPLL network on Lava's own processes

{n} sPLLs as the standard-neuron construction ({k} gate levels) on `lava.proc.lif` LIF,
`lava.proc.dense` Dense and `lava.proc.io` ring buffers, with their bit-accurate fixed-point
models, dt = {dt:g} s; {hold}.{graded}
{needs}

    python run.py spikes.npy 1.0     # input spike times [s] (.npy), duration [s]

prints JSON with `tde_counts` and `cco_counts` per sPLL. `params.npz`: the integers
(`lif.POP.*`: du, dv, vth, bias_mant, bias_exp; `dense.NAME.weights` / `.meta`: source, target,
weight_exp, num_message_bits); `standard.json`: what they stand for; `spll_grid.py`: the step
each input spike counts in (spll-hw's grid rule).

The network is {p} Lava processes in {sets} (a LIF process has one `du`, `dv`, `vth`).
lava-nc's CPU runtime starts each as an OS process:
{parts}.
Measured on 2 cores, a Lava process takes about 10 MB and 0.15 ms a step, so this takes about
{mem:.1f} GB and {sec:.2g} s a step ({minutes:.0f} min for 1 s at this dt).
{notes}
{check}"""

#: The last section of both READMEs: how to check lava-nc against ``check.json``.
CHECK_SECTION = """## Check lava-nc against `check.json`

`check_inputs.npz` holds the inputs of the export's check and `check.json` the TDE and CCO
spike count of every sPLL on each, as spll-hw's numpy run of these integers counted them;
Lava's bit-accurate models count the same, exactly:

    python run.py --check             # every input
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
            ``bias_mant``, ``bias_exp`` (int arrays of the population's size); a population
            with ``graded`` = 1 (``cur``, :mod:`~mappings.lava.graded_current`) is a
            ``GradedVec``, its LIF fields 0.
        dense: name -> ``(source, target, weights (target, source) int array, weight_exp,
            num_message_bits)``; source ``"input"`` is the spike generator.
        gate: the gate the integers realise.
        members: population -> the sPLLs (indices) it holds, for every population but
            ``gate``; a level population holds their K level neurons each, in order.
        notes: what the integers leave out of the network (sPLLs whose ``g_cco`` vanishes).
        hold: the refractory units' rule (:data:`HOLDS`).
    """

    dt: float
    n_spll: int
    levels: int
    lif: dict
    dense: dict
    gate: Gate
    members: dict
    notes: tuple[str, ...] = ()
    hold: str = HOLDS[0]

    @property
    def current(self) -> str:
        """How the CCOs' currents are kept (:data:`CURRENTS`): ``graded`` where a population
        is a ``GradedVec``."""
        return CURRENTS[1] if any(map(is_graded, self.lif.values())) else CURRENTS[0]

    @property
    def n_processes(self) -> int:
        """Lava processes of the whole network in the exported ``run.py``: the LIFs and
        ``Dense``, the input's ring buffer and one sink per TDE, CCO and hold population."""
        return standalone_run.n_processes(self.params())

    def params(self) -> dict:
        """These integers in the form the exported ``run.py`` reads from ``params.npz``
        (:func:`~mappings.lava.standalone_run.load_params`)."""
        return {"dt": self.dt, "n_spll": self.n_spll, "lif": self.lif,
                "members": self.members, "dense": self.dense}  # fmt: skip

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

    def open_loop(self) -> np.ndarray:
        """The sPLLs whose CCO gets nothing from its TDE, sorted indices, shape ``(k,)``: no
        weight from the TDE's relay in the gate (its row of
        :func:`~spll_hw.construction.gate.gate_layout`) reaches a population of the sPLL
        other than its TDE's (whose refractory unit it starts): a ``g_cco`` under half of
        Loihi's smallest weight rounds to 0 (:attr:`notes`), and that CCO runs free. The
        export check judges such an sPLL failed (:mod:`spll_hw.exporters.check`)."""
        relay = gate_layout(self.n_spll, self.levels, timers=False).relay_tde
        fed = np.zeros(self.n_spll, dtype=bool)
        for src, dst, weights, _, _ in self.dense.values():
            if src != "gate" or dst.startswith("tde") or dst not in self.members:
                continue
            members = np.asarray(self.members[dst])
            weights = np.asarray(weights)
            if weights.shape[0] == members.size:  # one row per sPLL (not a level population)
                fed[members] |= weights[np.arange(members.size), relay[members]] != 0
        return np.flatnonzero(~fed)

    def difference(self, other) -> str | None:
        """Where these integers first differ from ``other``'s (``"params.npz
        lif.tde.du"``, say), or ``None`` where they are the same: every array of
        :meth:`arrays` of equal shape, element for element, and an equal :meth:`info` (the
        gate's levels, placement, thresholds and increments); read back from a folder
        (:func:`~mappings.lava.export.read_standard`), integers equal those written."""
        return difference(self, other)

    def info(self) -> dict:
        """The export folder's ``standard.json``: the gate levels and each population's
        decays and threshold."""
        return {
            "dt": self.dt,
            **gate_info(self.n_spll, self.levels, self.gate, self.hold, self.current),
            "populations": {
                k: {"du": int(v["du"]), "dv": int(v["dv"]), "vth": int(v["vth"])}
                | ({"graded": True} if is_graded(v) else {})
                for k, v in self.lif.items()
            },
            "lava_processes": self.n_processes,
            "notes": list(self.notes),
        }

    def readme(self) -> str:
        """The export folder's ``README.md``: what it holds and how to run it."""
        notes = "".join(f"\n* {note}" for note in self.notes)
        parts = [standalone_run.n_processes(part) for part in standalone_run.split(self.params())]
        sec = sum(parts) * LAVA_PROCESS_STEP_S
        return README.format(
            n=self.n_spll,
            k=self.levels,
            hold=HOLD_WORDS[self.hold],
            graded=CURRENT_WORDS[self.current],
            dt=self.dt,
            p=self.n_processes,
            parts=_parts_words(parts),
            mem=max(parts) * LAVA_PROCESS_MB / 1024,
            sec=sec,
            minutes=sec / self.dt / 60,
            sets=_plural(sum(pop.startswith("tde") for pop in self.lif), "set") + " of decays",
            notes=f"\nWhat the integers leave out:\n{notes}\n" if notes else "",
            needs=NEEDS,
            check=CHECK_SECTION,
        )


def gate_info(n_spll: int, levels: int, gate: Gate, hold: str, current: str) -> dict:
    """``standard.json``'s fields of the network's size, its gate, its refractory hold and how
    its CCOs' currents are kept."""
    return {
        "n_spll": n_spll,
        "gate_levels": levels,
        "gate_placement": gate.placement,
        "refractory_hold": hold,
        "cco_current": current,
        "thresholds_A": gate.thresholds.tolist(),
        "increments_A": gate.increments.tolist(),
    }


def difference(mine, theirs) -> str | None:
    """Where the integers ``mine`` first differ from ``theirs`` (each a :class:`LavaStandard`
    or a :class:`~mappings.lava.clocks.ClockedStandard`: their ``arrays()`` as written to
    ``params.npz``, then their ``info()`` as written to ``standard.json``), or ``None``."""
    a, b = mine.arrays(), theirs.arrays()
    if sorted(a) != sorted(b):
        return f"params.npz: arrays {sorted(a)} against {sorted(b)}"
    for key in sorted(a):
        if a[key].shape != b[key].shape or not np.array_equal(a[key], b[key]):
            return f"params.npz {key}"
    a, b = mine.info(), theirs.info()
    return next((f"standard.json {k}" for k in sorted(a.keys() | b.keys())
                 if a.get(k) != b.get(k)), None)  # fmt: skip


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'s' if n != 1 else ''}"


def _parts_words(parts: list[int]) -> str:
    """How ``run.py`` runs a network whose independent parts have ``parts`` Lava processes
    each: the README's clause."""
    if len(parts) == 1:
        return "`run.py` runs them together (the sPLLs are one connected network)"
    return (
        f"`run.py` runs the network's {len(parts)} independent parts (sPLLs that share only "
        f"the input) one after another, at most {max(parts)} processes at once"
    )


def lava_standard(
    network: Network,
    *,
    dt: float = DEFAULT_DT,
    levels: int = DEFAULT_LEVELS,
    placement: str = DEFAULT_PLACEMENT,
    input_rate: float = DEFAULT_INPUT_RATE,
    hold: str = HOLDS[0],
    gate: Gate | None = None,
    current: str = CURRENTS[0],
) -> LavaStandard:
    """The integers of ``network`` as the standard sPLL on Lava's LIF and Dense processes,
    each TDE and CCO held by its refractory unit as ``hold`` (one of :data:`HOLDS`) says.

    One LIF process has one ``du``, ``dv`` and ``vth``: sPLLs whose 12-bit decays and
    refractory steps agree share the level, TDE and CCO processes and their refractory units,
    and each other set (a time-scaled, grouped or tuned layout) gets its own (``level1``,
    ``tde1``, ``cco1``, ...; :attr:`LavaStandard.members`).

    The gate is ``levels`` levels placed by ``placement`` for ``network``
    (:func:`~spll_hw.construction.gate.gate_levels`), or ``gate`` where given (one row per
    sPLL of ``network``): a part of a network written with its rows of the whole network's
    gate (:func:`~mappings.lava.clocks.clocked_standard` writes each set of sPLLs at its own
    step).

    Raises:
        ValueError: naming the sPLL, the parameter and the target ``lava-standard`` when the
            network cannot be represented: a decay outside 12 bits at this ``dt``, a
            refractory period of one step or beyond :data:`MAX_REFRACTORY_STEPS`, a trigger
            weight under Loihi's smallest, or a bias or synaptic sum outside Loihi's words.
    """
    if hold not in HOLDS:
        raise ValueError(f"lava-standard: hold must be one of {HOLDS}, got {hold!r}")
    if current not in CURRENTS:
        raise ValueError(f"lava-standard: current must be one of {CURRENTS}, got {current!r}")
    if gate is not None and gate.thresholds.shape[0] != network.n_spll:
        raise ValueError(
            f"lava-standard: the gate has levels for {gate.thresholds.shape[0]} sPLLs, the "
            f"network has {network.n_spll} (pass its rows of the gate: Gate(thresholds[rows], "
            "increments[rows], ...))"
        )
    p, r = target_parameters(network, dt, "lava-standard"), roles()
    decay = loihi_decays(p, r, dt)
    kick = _charges(p, r, decay, dt)
    dither = {part: _holds(p[t_refr], dt, hold)
              for part, t_refr in (("tde", r.tde.t_refr), ("cco", r.cco.t_refr))}  # fmt: skip
    steps = {part: d.base for part, d in dither.items()}
    # One LIF process has one du, dv and vth: sPLLs whose decays and refractory (base) steps
    # agree share processes.
    keys = np.stack([*decay.values(), steps["tde"], steps["cco"]], axis=1)
    _, group_of = np.unique(keys, axis=0, return_inverse=True)
    group_of = group_of.reshape(-1)
    n_groups = int(group_of.max()) + 1
    for part, name in (("tde", r.tde.t_refr), ("cco", r.cco.t_refr)):
        bad = np.flatnonzero((steps[part] == 1) | (steps[part] > MAX_REFRACTORY_STEPS))
        if bad.size:
            i, count = int(bad[0]), int(steps[part][bad[0]])
            raise ValueError(
                f"sPLL {i}: {name} = {p[name][i]:g} s is {count} steps at dt = {dt:g} s; target "
                f"lava-standard's refractory unit holds 2..{MAX_REFRACTORY_STEPS} steps (or "
                f"none, under one step; use a "
                f"{f'dt <= {p[name][i] / 2:.2g} s' if count == 1 else 'larger dt'})"
            )
    gate = gate_levels(network, levels, placement, input_rate) if gate is None else gate
    n, k = network.n_spll, gate.n_levels
    layout = gate_layout(n, k, timers=False)
    m, size_gate, spll_of_row = layout.n_and, layout.size, layout.spll_of_and
    relay_tde, tde_gate, cco_gate = layout.relay_tde, layout.from_tde, layout.from_cco

    # Per-step potential of a kick into a synapse [A] (its value in the step it arrives), in
    # units of each membrane's θ (per sPLL).
    def per_kick(synapse, membrane, theta):
        # The exact one-step propagator k of the realised decays: u = k I, decaying with the
        # synapse, charges the membrane as the current would between steps (the NIR graph's
        # exact charge; a current's step-start value held over the step would deliver
        # dt / (tau (1 - e^(-dt/tau))) times its charge, 1.17 at tau = 3.3 dt).
        tau_s = realised_tau(decay[synapse.tau], dt, DECAY_BITS)
        tau_m = realised_tau(decay[membrane.tau], dt, DECAY_BITS)
        k_exact = exact_propagator(tau_s, tau_m, p[membrane.c], dt)[1]
        return k_exact / p[membrane.v_thr] * theta

    # What each sPLL's offset, feedback and trigger (every level at once) put in per unit of
    # its CCO's or TDE's vth: its set's thresholds are as fine as these allow.
    offset = free_running_offset(p, decay[r.cco.tau], dt)
    unit = {
        "offset": offset,
        "feedback": kick[r.fed.gain] * per_kick(r.cco_syn, r.cco, 1.0),
        "trigger": kick[r.gated.gain] * gate.increments.sum(axis=1) * per_kick(r.trg, r.tde, 1.0),
    }
    # Per sPLL and hold it may take: (steps, keep_u, keep_v, fewest steps between its input's
    # spikes); a dithered neuron's base hold and its adjusted one.
    shortest = {part: d.base + np.minimum(d.step, 0) for part, d in dither.items()}
    held = {
        part: np.stack([
            np.stack([hold, DECAY_UNITY - decay[syn.tau], DECAY_UNITY - decay[mem.tau],
                      shortest[source] + 1], axis=1)
            for hold in (steps[part], steps[part] + dither[part].step)
        ], axis=1)
        for part, source, syn, mem in (
            ("tde", "cco", r.trg, r.tde), ("cco", "tde", r.cco_syn, r.cco)
        )
    }  # fmt: skip
    # A graded CCO current carries its accumulated kicks in the CCO's a_in, not one kick.
    carried = kicks_carried(held["cco"]) if current == "graded" else np.ones(network.n_spll)
    vth, force = _thresholds(unit, held, group_of, p, dt, carried)
    k_tde = per_kick(r.trg, r.tde, vth["tde"] << 6)
    k_cco = per_kick(r.cco_syn, r.cco, vth["cco"] << 6)

    # The network-wide arrays and matrices; cut into groups below.
    # level: u = I_fac / g_fac * S, S = 64 w 2^e per input spike; thresholds in the bias.
    top = float(np.max(gate.thresholds / p[r.driven.gain][:, None]))
    w_in, e_in = _mantissa(LEVEL_BIAS_MAX / top / 64.0, "input weight", floor=True)
    s = 64 * w_in * 2.0**e_in
    level_bias = _bias(-(gate.thresholds / p[r.driven.gain][:, None]).reshape(m) * s)
    cco_bias = _bias(offset * (vth["cco"] << 6))
    level_gate = np.zeros((size_gate, m), np.int64)
    level_gate[np.arange(m), np.arange(m)] = 1
    trigger = np.zeros((n, size_gate))
    trigger[spll_of_row, np.arange(m)] = (
        (kick[r.gated.gain] * k_tde)[:, None] * gate.increments
    ).reshape(m) / 64.0
    feedback = np.zeros((n, size_gate))
    feedback[np.arange(n), relay_tde] = kick[r.fed.gain] * k_cco / 64.0
    what = f"trigger ({r.gated.gain})"
    gate_tde, _ = _weights(trigger, what)
    gate_cco, vanished = _weights(feedback, r.fed.gain, may_vanish=True)
    # Each TDE spike's kick into its CCO as Loihi realises it [a_in units], per sPLL (the
    # exponents of _weights are 0..7).
    kicks = sum(w[np.arange(n), relay_tde] << e for e, w in gate_cco.items())
    # What each held neuron's spikes reach in the gate (its relay; the CCO's AND neurons), its
    # relay (its real spikes' one) and its unit's force.
    reach = {"tde": tde_gate, "cco": cco_gate}
    relay = {"tde": relay_tde, "cco": layout.relay_cco}

    lif = {"gate": _lif(size_gate, du=4095, dv=4095, vth=1)}
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
        lif[tde] = _lif(idx.size, du=int(decay[r.trg.tau][i0]) - 1,
                        dv=int(decay[r.tde.tau][i0]), vth=int(vth["tde"][i0]))  # fmt: skip
        lif[cco] = {"du": 4095 if current == "graded" else int(decay[r.cco_syn.tau][i0]) - 1,
                    "dv": int(decay[r.cco.tau][i0]),
                    "vth": int(vth["cco"][i0]), "bias_mant": cco_bias[0][idx],
                    "bias_exp": cco_bias[1][idx]}  # fmt: skip
        members[level], members[tde], members[cco] = idx, idx, idx
        dense[f"input_{level}"] = ("input", level, _col(np.full(rows.size, w_in)), e_in, 8)
        dense[f"{level}_gate"] = (level, "gate", level_gate[:, rows], 0, 0)
        dense[f"{tde}_gate"] = (tde, "gate", tde_gate[:, idx], 0, 0)
        dense[f"{cco}_gate"] = (cco, "gate", cco_gate[:, idx], 0, 0)
        dense |= _per_exponent("gate", tde, gate_tde, idx)
        dense |= _per_exponent("gate", cco, gate_cco, idx)
        if current == "graded":
            cur = graded_current(cco, tag, int(decay[r.cco_syn.tau][i0]), kicks[idx],
                                 carried[idx] - 1, relay_tde[idx], size_gate)  # fmt: skip
            lif |= cur.lif
            dense |= cur.dense
            members |= {pop: idx for pop in cur.lif}
        for part, name in (("tde", tde), ("cco", cco)):
            if steps[part][i0] == 0:
                continue  # a refractory period under one step: nothing to hold
            unit = refractory_unit(
                name, int(steps[part][i0]), DECAY_UNITY - int(lif[name]["du"]) - 1,
                int(force[part][g]), reach[part][:, idx], relay[part][idx],
                CounterDither(*(x[idx] for x in dither[part])),
            )  # fmt: skip
            lif |= unit.lif
            dense |= unit.dense
            members |= {pop: idx for pop in unit.lif}
    _check_sums(dense, lif)
    notes = _dropped(trigger, gate_tde, what) + (() if not vanished.size else (
        f"{spll_ranges(vanished)}: {r.fed.gain} (at most {np.max(p[r.fed.gain][vanished]):g}) "
        f"is under half of Loihi's smallest weight into the CCO at dt = {dt:g} s, so these CCOs "
        "run without the TDE's feedback",
    )) + _longest_decays(p, r, dt)  # fmt: skip
    return LavaStandard(float(dt), n, k, lif, dense, gate, members, notes, hold)


def _holds(t_refr: np.ndarray, dt: float, hold: str) -> CounterDither:
    """The refractory holds [steps] of periods ``t_refr`` [s] at ``dt`` [s] by rule ``hold``
    (:data:`HOLDS`), as counters' rules (undithered: ``step`` 0)."""
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
    from spll_hw.model.frequency import free_frequency

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


def _longest_decays(p: dict, r, dt: float) -> tuple[str, ...]:
    """A note per kicked synapse too long for 12 bits at ``dt`` [s] on some sPLLs, which takes
    Loihi's longest decay with its charge kept (:func:`loihi_decays`, :func:`_charges`), or
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


def _per_exponent(src: str, dst: str, weights: dict, idx: np.ndarray) -> dict:
    """The ``Dense`` from ``src`` to the neurons ``idx`` of ``dst`` (:func:`_weights`'s
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
    :func:`_charges` keeps its kicks' charge; the gate's ``tau_tde_fac``, whose value and not
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


def _charges(p: dict, r, decay: dict, dt: float) -> dict[str, np.ndarray]:
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


def _thresholds(
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
            (1; more where a graded current passes through it, :func:`_carried`).

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
    units, in :class:`LavaStandard`'s forms (:func:`refractory_unit`)."""

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
    lif = {end: _lif(size, du=4095, dv=0, vth=steps - 2), hold: _lif(size, du=4095, dv=4095, vth=1)}
    if dither is not None and dither.step.any():
        # The counter counts the neuron's spikes that are the network's (its relay, step s+1)
        # and fires on the period-th (s+2), taking one count off end_X or adding one (s+3).
        count = f"dither_{held}"
        weight = np.where(dither.step != 0, DITHER_VTH // np.maximum(dither.period - 1, 1), 0)
        lif[count] = _lif(size, du=4095, dv=0, vth=DITHER_VTH)
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


def _lif(size: int, du: int, dv: int, vth: int) -> dict:
    """A LIF process's parameters without bias."""
    zeros = np.zeros(size, np.int64)
    return {"du": du, "dv": dv, "vth": vth, "bias_mant": zeros, "bias_exp": zeros.copy()}


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


def _weights(
    values: np.ndarray, what: str, may_vanish: bool = False
) -> tuple[dict[int, np.ndarray], np.ndarray]:
    """Integer weights of one sign (``|w| <= 255``) of target neurons (rows, shape ``(rows,
    sources)``, in ``a_in`` units): ``{exponent: weights}``, each weight 0 but in its
    exponent's matrix, and the rows (sPLLs) whose weights all round to 0.

    Each row takes the exponent that fits its own largest weight, unless one of its weights
    would round to 0 there (the row spans more than 8 bits): then each of that row's weights
    takes the exponent that fits itself, and Loihi sums the ``Dense`` of the exponents into
    the neuron's ``a_in``. A weight under half an ``a_in`` unit rounds to 0 even so, as every
    weight of exponent 0 rounds to the nearest unit (:func:`_dropped` finds them). Rows within
    8 bits keep their one exponent: the integers of networks that fit are those they were.

    Raises:
        ValueError: naming ``what`` and the sPLLs where every weight of a row rounds to 0
            (its synapses would vanish), unless ``may_vanish``.
    """
    big = np.max(np.abs(values), axis=1)
    row_exp = np.array([_mantissa(float(b), what)[1] if b > 0 else 0 for b in big], np.int64)
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


def _dropped(values: np.ndarray, weights: dict[int, np.ndarray], what: str) -> tuple[str, ...]:
    """A note on the weights of ``values`` (rows sPLLs, ``a_in`` units) that :func:`_weights`
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


def _check_sums(dense: dict, lif: dict) -> None:
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
