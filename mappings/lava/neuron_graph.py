"""The construction ``lava-standard`` writes as a graph of standard neurons a chip costs
(:class:`spll_hw.neuron_graph.NeuronGraph`), neuron for neuron and synapse for synapse.

:func:`lava_graph`: Loihi's integers on Lava's LIF and Dense (:mod:`mappings.lava.standard`;
with a clock per set of sPLLs, :mod:`mappings.lava.clocks`, each set on its own clock). Every
LIF population's neurons, in the order of its ``lif`` (the order in which
:func:`~mappings.lava.loihi.simulate_fixed` counts their spikes); a ``GradedVec`` (``cur``) is a
neuron that sends its value every step it is not 0. Every nonzero weight of every ``Dense`` is a
synapse (a weight split over two exponents is two). Neurons share decays where their ``(du,
dv)`` are equal (one per LIF process) and thresholds where their ``vth`` is.

Which sPLL a neuron belongs to follows the layout of the gate
(:func:`~spll_hw.construction.gate.gate_layout`): a level or AND neuron its sPLL's, a
relay, hold or timer neuron the sPLL of the TDE or CCO it serves.
"""

from __future__ import annotations

import numpy as np

from spll_hw.construction.gate import gate_layout
from spll_hw.neuron_graph import NeuronGraph, ids, synapse_counts


def _lava_neurons(params) -> tuple[list, list[str]]:
    """Per LIF population of one clock's integers: (name, size, sPLL of each neuron, decay
    key, threshold); and the population names."""
    n, k = params.n_spll, params.levels
    layout = gate_layout(n, k, timers=False)
    gate_spll = np.r_[layout.spll_of_and, np.arange(n), np.arange(n)]
    out = []
    for pop, p in params.lif.items():
        size = int(np.asarray(p["bias_mant"]).shape[0])
        if pop == "gate":
            spll = gate_spll
        else:
            members = np.asarray(params.members[pop], np.int64)
            spll = np.repeat(members, size // max(1, members.size))
        if spll.shape != (size,):
            raise ValueError(f"lava-standard population {pop!r}: {size} neurons for sPLLs {spll}")
        graded = bool(int(p.get("graded", 0)))
        decay = ("graded",) if graded else ("lif", int(p["du"]), int(p["dv"]))
        out.append((pop, size, spll, decay, int(p["vth"])))
    return out


def lava_graph(params) -> NeuronGraph:
    """The :class:`NeuronGraph` of Loihi's integers ``params`` (module docstring): a
    :class:`~mappings.lava.standard.LavaStandard`, or a
    :class:`~mappings.lava.clocks.ClockedStandard` whose parts are its clocks."""
    parts = getattr(params, "parts", None)
    clocks = [(np.arange(params.n_spll), params)] if parts is None else [
        (part.spll, part.params) for part in parts]  # fmt: skip
    spll, clock, decay, thr, population, names = [], [], [], [], [], []
    rows, cols, in_rows = [], [], []
    start = 0
    for c, (whole, part) in enumerate(clocks):
        offset = {}
        for pop, size, members, key, vth in _lava_neurons(part):
            offset[pop] = start
            spll.append(np.asarray(whole)[members])
            clock.append(np.full(size, c))
            decay += [key] * size
            thr += [vth] * size
            label = pop if parts is None else f"{pop}@clock{c}"
            names.append(label)
            population.append(np.full(size, len(names) - 1))
            start += size
        for src, dst, w, _, _ in part.dense.values():
            r, col = np.nonzero(np.asarray(w))
            if src == "input":
                in_rows.append(offset[dst] + r)
            else:
                rows.append(offset[dst] + r)
                cols.append(offset[src] + col)
    dts = tuple(float(p.dt) for _, p in clocks)
    hold = getattr(params, "hold", "")
    return NeuronGraph(
        "lava-standard", f"{params.levels}-level gate, {hold} refractory hold, Loihi's LIF and "
        "Dense", params.n_spll, dts, np.concatenate(clock), np.concatenate(spll), ids(decay),
        ids(thr), np.concatenate(population), tuple(names),
        *synapse_counts(rows, cols, in_rows, start),
    )  # fmt: skip
