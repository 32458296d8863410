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
                         :data:`~mappings.lava.integers.VTH_TDE` (lower where one trigger would
                         overflow ``a_in`` or the refractory unit could not hold it)
``cco``     N            ``du`` of ``tau_cco_syn``, ``dv`` of ``tau_cco``, ``vth`` up to
                         :data:`~mappings.lava.integers.VTH_CCO` (lower where the offset or the
                         unit needs it), bias = the offset
``hold_X``  N            per TDE and CCO population ``X``: ``du = dv = 4095``, ``vth = 1``; fires
                         on every step its neuron is held
``end_X``   N            ``du = 4095``, ``dv = 0`` (a counter), ``vth = R - 2``: fires on the
                         last held step
==========  ===========  ======================================================================

With ``current="graded"`` each set's CCOs have ``du = 4095`` and their currents live in a
``GradedVec`` ``cur`` (N, ``lava.proc.graded``), kept at a half ``a_in`` unit by ``on`` (N LIFs
that fire every step): :mod:`mappings.lava.graded_current`.

With ``hold="dithered"`` each held population ``X`` also has ``dither_X`` (N neurons, ``du =
4095``, ``dv = 0``, ``vth =`` :data:`~mappings.lava.integers.DITHER_VTH`), which fires on every
``n``-th of its neuron's spikes (:mod:`mappings.lava.integers`).

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

**Integers**: the refractory units (:func:`~mappings.lava.integers.refractory_unit`),
the dithered hold, the 12-bit decays, the offset's bias, the kicks and the weights are
Loihi's integer arithmetic, which :mod:`mappings.lava.integers` states and computes.

**Step**: Lava's ``LoihiProtocol`` with Loihi's arithmetic, stated in :mod:`mappings.lava.loihi`
(whose :func:`~mappings.lava.loihi.simulate_fixed` is its bit-accurate executor); the
exported ``run.py`` (:mod:`mappings.lava.standalone_run`) runs Lava itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spll_hw.construction.gate import (
    DEFAULT_GATE,
    Gate,
    GateOptions,
    gate_layout,
    gate_levels,
    target_parameters,
)
from spll_hw.model.discrete import exact_propagator, realised_tau
from spll_hw.model.holds import CounterDither
from spll_hw.model.roles import roles
from spll_hw.network import Network

from . import standalone_run
from .graded_current import carried as kicks_carried
from .graded_current import graded_current
from .integers import (
    bias,
    charges,
    check_sums,
    col,
    dense_weights,
    dropped,
    free_running_offset,
    holds,
    loihi_decays,
    longest_decays,
    mantissa,
    per_exponent,
    refractory_unit,
    spll_ranges,
    thresholds,
    unbiased_lif,
)
from .loihi import DECAY_BITS, DECAY_UNITY, is_graded

#: Default time step [s] of the backends, and the first the export tries without ``--dt``
#: (:mod:`mappings.lava.dt_choice`): at 10 µs the 12-bit decays of the longer time constants
#: round by 10-25 % (``tau_tde_fac``'s ``δ`` is 3 or 4), which costs 11 % TDE-rate error on
#: biotac-vary-offset-lif and vibtac-vary-offset-lif; at 50 µs they are 1.1 % and 3.7 % off
#: (docs/backends.md).
DEFAULT_DT = 5e-5
#: Gate levels of ``spll-hw export --to lava-standard`` (as nir-standard's, and for the same
#: reason: the 8-level gate is coarse on periodic input).
EXPORT_LEVELS = 16
#: The gate of the export: :data:`EXPORT_LEVELS` levels, placed as by default.
EXPORT_GATE = GateOptions(levels=EXPORT_LEVELS)
#: What a level neuron's ``u`` gains per input spike at most (keeps thresholds in the bias).
LEVEL_BIAS_MAX = 4095 << 7
#: A Lava process's memory [MB] (2026-11-28, docs/notes/2026-11-28-lava-standard-parts.md);
#: :func:`lava_gb` is the READMEs' model of it, ``standalone_run.seconds`` their model of time.
LAVA_PROCESS_MB = 10


def lava_gb(parts: list[int], jobs: int = 1) -> float:
    """The memory [GB] of the ``jobs`` largest of ``parts`` (Lava processes each) at once."""
    return sum(sorted(parts)[-jobs:]) * LAVA_PROCESS_MB / 1024


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

The network is {p} Lava processes in {sets} (a LIF process has one `du`, `dv`, `vth`:
run.py puts the populations that share them in one, and the synapses between the same two
with the same `weight_exp` and sign in one Dense). lava-nc's CPU runtime starts each as an OS
process: {parts}.
{cost}
{notes}
{check}"""

#: The last section of both READMEs: how to check lava-nc against ``check.json``.
CHECK_SECTION = f"""## Check lava-nc against `check.json`

`check_inputs.npz` holds the inputs of the export's check and `check.json` the TDE and CCO
spike count of every sPLL on each, as spll-hw's numpy run of these integers counted them;
Lava's bit-accurate models count the same, exactly:

    python run.py --check             # every input
    python run.py --check 0 3         # inputs 0 and 3 of check.json

prints a table and exits 0 when every count is `check.json`'s, 1 naming the inputs and sPLLs
that are not (`check_counts.py` compares them). Inputs of one length run at once, a copy of
each part of the network per input in the same Lava processes (up to
{standalone_run.BATCH_NEURONS} neurons): six inputs of a tuned preset took a quarter of the time.
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
        """Lava processes the exported ``run.py`` starts: those of each of the network's
        independent parts (:func:`~mappings.lava.standalone_run.split`, each part's LIFs and
        ``Dense`` as :func:`~mappings.lava.standalone_run.layout` merges them, its input's ring
        buffer and its sinks)."""
        return sum(self.part_processes())

    def part_processes(self) -> list[int]:
        """Lava processes of each independent part the exported ``run.py`` runs."""
        return [standalone_run.n_processes(part) for part in standalone_run.split(self.params())]

    def part_neurons(self) -> list[int]:
        """Neurons of each independent part the exported ``run.py`` runs (its LIF processes'
        neurons, :func:`~mappings.lava.standalone_run.n_neurons`), in
        :meth:`part_processes`' order."""
        return [standalone_run.n_neurons(part) for part in standalone_run.split(self.params())]

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
        parts = self.part_processes()
        return README.format(
            n=self.n_spll,
            k=self.levels,
            hold=HOLD_WORDS[self.hold],
            graded=CURRENT_WORDS[self.current],
            dt=self.dt,
            p=self.n_processes,
            parts=_parts_words(parts),
            cost=cost_words(parts, self.part_neurons(), [round(1 / self.dt)] * len(parts)),
            sets=_plural(sum(pop.startswith("tde") for pop in self.lif), "set") + " of decays",
            notes=f"\nWhat the integers leave out:\n{notes}\n" if notes else "",
            needs=NEEDS,
            check=CHECK_SECTION,
        )


def cost_words(parts: list[int], neurons: list[int], steps: list[int]) -> str:
    """The READMEs' estimate of ``run.py`` on 1 s of input, for independent parts of ``parts``
    Lava processes and ``neurons`` neurons each, part ``k`` over ``steps[k]`` steps a second
    (``standalone_run.seconds``, :func:`lava_gb`)."""
    costs = [standalone_run.part_seconds(*part) for part in zip(parts, neurons, steps, strict=True)]
    one = (f"{standalone_run.seconds(costs, 1) / 60:.3g} min and {lava_gb(parts, 1):.1f} GB "
           "with `--jobs 1` (run.py's default)")  # fmt: skip
    if len(parts) > 1:
        one += (f", {standalone_run.seconds(costs, 2) / 60:.3g} min and "
                f"{lava_gb(parts, 2):.1f} GB with `--jobs 2` (two parts at once)")  # fmt: skip
    return (
        f"Measured on a 2-core machine, run.py takes {standalone_run.START_S:g} s to start, "
        f"then per Lava process {standalone_run.PROCESS_START_S * 1e3:.3g} ms to compile and "
        f"start its part, and a step {standalone_run.PROCESS_STEP_S * 1e3:.3g} ms per Lava "
        f"process and {standalone_run.NEURON_STEP_S * 1e6:.3g} µs per neuron, and about "
        f"{LAVA_PROCESS_MB} MB a process: 1 s of input takes about {one}. Machines differ "
        "(another 2-core one stepped twice as fast): after each part run.py prints what is "
        "left, measured on the machine it runs on."
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
        f"the input) one after another (`--jobs N`: N at a time, a worker process each), at "
        f"most {max(parts)} processes in a part"
    )


def lava_standard(
    network: Network,
    options: GateOptions = DEFAULT_GATE,
    *,
    dt: float = DEFAULT_DT,
    hold: str = HOLDS[0],
    current: str = CURRENTS[0],
) -> LavaStandard:
    """The integers of ``network`` at the step ``dt`` [s] as the standard sPLL on Lava's LIF
    and Dense processes, each TDE and CCO held by its refractory unit as ``hold`` (one of
    :data:`HOLDS`) says, each CCO's current kept as ``current`` (one of :data:`CURRENTS`).

    One LIF process has one ``du``, ``dv`` and ``vth``: sPLLs whose 12-bit decays and
    refractory steps agree share the level, TDE and CCO processes and their refractory units,
    and each other set (a time-scaled, grouped or tuned layout) gets its own (``level1``,
    ``tde1``, ``cco1``, ...; :attr:`LavaStandard.members`).

    The gate is as ``options`` says (:class:`~spll_hw.construction.gate.GateOptions`, e.g.
    ``GateOptions(levels=16)``), placed for ``network`` or given: a part
    of a network written with its rows of the whole network's gate
    (:func:`~mappings.lava.clocks.clocked_standard` writes each set of sPLLs at its own step).

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
    gate = options.gate
    if gate is not None and gate.thresholds.shape[0] != network.n_spll:
        raise ValueError(
            f"lava-standard: the gate has levels for {gate.thresholds.shape[0]} sPLLs, the "
            f"network has {network.n_spll} (pass its rows of the gate: Gate(thresholds[rows], "
            "increments[rows], ...))"
        )
    p, r = target_parameters(network, dt, "lava-standard"), roles()
    decay = loihi_decays(p, r, dt)
    kick = charges(p, r, decay, dt)
    dither = {part: holds(p[t_refr], dt, hold)
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
    if gate is None:
        gate = gate_levels(network, options.levels, options.placement, options.input_rate)
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
    vth, force = thresholds(unit, held, group_of, p, dt, carried)
    k_tde = per_kick(r.trg, r.tde, vth["tde"] << 6)
    k_cco = per_kick(r.cco_syn, r.cco, vth["cco"] << 6)

    # The network-wide arrays and matrices; cut into groups below.
    # level: u = I_fac / g_fac * S, S = 64 w 2^e per input spike; thresholds in the bias.
    top = float(np.max(gate.thresholds / p[r.driven.gain][:, None]))
    w_in, e_in = mantissa(LEVEL_BIAS_MAX / top / 64.0, "input weight", floor=True)
    s = 64 * w_in * 2.0**e_in
    level_bias = bias(-(gate.thresholds / p[r.driven.gain][:, None]).reshape(m) * s)
    cco_bias = bias(offset * (vth["cco"] << 6))
    level_gate = np.zeros((size_gate, m), np.int64)
    level_gate[np.arange(m), np.arange(m)] = 1
    trigger = np.zeros((n, size_gate))
    trigger[spll_of_row, np.arange(m)] = (
        (kick[r.gated.gain] * k_tde)[:, None] * gate.increments
    ).reshape(m) / 64.0
    feedback = np.zeros((n, size_gate))
    feedback[np.arange(n), relay_tde] = kick[r.fed.gain] * k_cco / 64.0
    what = f"trigger ({r.gated.gain})"
    gate_tde, _ = dense_weights(trigger, what)
    gate_cco, vanished = dense_weights(feedback, r.fed.gain, may_vanish=True)
    # Each TDE spike's kick into its CCO as Loihi realises it [a_in units], per sPLL (the
    # exponents of dense_weights are 0..7).
    kicks = sum(w[np.arange(n), relay_tde] << e for e, w in gate_cco.items())
    # What each held neuron's spikes reach in the gate (its relay; the CCO's AND neurons), its
    # relay (its real spikes' one) and its unit's force.
    reach = {"tde": tde_gate, "cco": cco_gate}
    relay = {"tde": relay_tde, "cco": layout.relay_cco}

    lif = {"gate": unbiased_lif(size_gate, du=4095, dv=4095, vth=1)}
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
        lif[tde] = unbiased_lif(idx.size, du=int(decay[r.trg.tau][i0]) - 1,
                                dv=int(decay[r.tde.tau][i0]), vth=int(vth["tde"][i0]))  # fmt: skip
        lif[cco] = {"du": 4095 if current == "graded" else int(decay[r.cco_syn.tau][i0]) - 1,
                    "dv": int(decay[r.cco.tau][i0]),
                    "vth": int(vth["cco"][i0]), "bias_mant": cco_bias[0][idx],
                    "bias_exp": cco_bias[1][idx]}  # fmt: skip
        members[level], members[tde], members[cco] = idx, idx, idx
        dense[f"input_{level}"] = ("input", level, col(np.full(rows.size, w_in)), e_in, 8)
        dense[f"{level}_gate"] = (level, "gate", level_gate[:, rows], 0, 0)
        dense[f"{tde}_gate"] = (tde, "gate", tde_gate[:, idx], 0, 0)
        dense[f"{cco}_gate"] = (cco, "gate", cco_gate[:, idx], 0, 0)
        dense |= per_exponent("gate", tde, gate_tde, idx)
        dense |= per_exponent("gate", cco, gate_cco, idx)
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
    check_sums(dense, lif)
    notes = dropped(trigger, gate_tde, what) + (() if not vanished.size else (
        f"{spll_ranges(vanished)}: {r.fed.gain} (at most {np.max(p[r.fed.gain][vanished]):g}) "
        f"is under half of Loihi's smallest weight into the CCO at dt = {dt:g} s, so these CCOs "
        "run without the TDE's feedback",
    )) + longest_decays(p, r, dt)  # fmt: skip
    return LavaStandard(float(dt), n, k, lif, dense, gate, members, notes, hold)
