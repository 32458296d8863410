"""The standard sPLL's constructions as graphs of standard neurons a chip costs
(:class:`spll_hw.neuron_graph.NeuronGraph`): what ``lava-standard`` and ``nir-standard`` write,
neuron for neuron and synapse for synapse.

* :func:`lava_graph`: Loihi's integers on Lava's LIF and Dense (:mod:`mappings.lava.standard`;
  with a clock per set of sPLLs, :mod:`mappings.lava.clocks`, each set on its own clock). Every
  LIF population's neurons, in the order of its ``lif`` (the order in which
  :func:`~mappings.lava.loihi.simulate_fixed` counts their spikes); a ``GradedVec`` (``cur``)
  is a neuron that sends its value every step it is not 0. Every nonzero weight of every
  ``Dense`` is a synapse (a weight split over two exponents is two). Neurons share decays where
  their ``(du, dv)`` are equal (one per LIF process) and thresholds where their ``vth`` is.
* :func:`nir_graph`: a NIR graph of ``CubaLIF``, ``LIF``, ``Linear`` and ``Affine`` nodes
  (:mod:`mappings.nir.standard`): every row of a neuron node is a neuron, in the order of the
  sorted node names (:func:`~mappings.nir.executor.neuron_nodes`, the executor's), and every
  nonzero weight of a ``Linear`` or ``Affine`` between two neuron nodes (or from the input) a
  synapse; biases are the neurons' own. Neurons share decays where their node type and time
  constants are equal, thresholds where their ``v_threshold`` is. Every row is counted, also
  the level node's rows that hold no level neuron (each relay's row: the node is one vector).

Which sPLL a neuron belongs to follows the layout of the gate
(:func:`~mappings.standard.construction.gate_layout`): a level or AND neuron its sPLL's, a
relay, hold or timer neuron the sPLL of the TDE or CCO it serves; NIR's start neuron and pulse
(the last rows of the level and gate nodes) are shared by every sPLL.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix

from spll_hw.neuron_graph import NeuronGraph, ids

from .construction import gate_layout


def graph_of(prepared) -> NeuronGraph:
    """The graph of what a construction backend prepared: a
    :class:`~mappings.lava.standard.LavaStandard`, a
    :class:`~mappings.lava.clocks.ClockedStandard` or a
    :class:`~mappings.nir.standard.StandardNir`; ``ValueError`` for anything else."""
    from mappings.lava.clocks import ClockedStandard
    from mappings.lava.standard import LavaStandard
    from mappings.nir.standard import StandardNir

    if isinstance(prepared, LavaStandard | ClockedStandard):
        return lava_graph(prepared)
    if isinstance(prepared, StandardNir):
        return nir_graph(prepared.graph)
    raise ValueError(f"no graph of standard neurons for a {type(prepared).__name__}")


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
        ids(thr), np.concatenate(population), tuple(names), *_synapses(rows, cols, in_rows, start),
    )  # fmt: skip


def nir_graph(graph) -> NeuronGraph:
    """The :class:`NeuronGraph` of a NIR graph of standard nodes written by
    :func:`~mappings.nir.standard.to_standard_nir` (module docstring); ``ValueError`` naming
    the node for a graph of another shape."""
    from mappings.nir.executor import neuron_nodes

    meta = graph.metadata
    n, k = int(np.asarray(meta["n_spll"])), int(np.asarray(meta["gate_levels"]))
    m = n * k
    names = neuron_nodes(graph)
    offset, spll, decay, thr, population = {}, [], [], [], []
    start = 0
    for index, name in enumerate(names):
        node = graph.nodes[name]
        size = int(np.asarray(node.v_threshold).shape[0])
        offset[name] = start
        row = np.arange(size)
        if size == 2 * n or size == 4 * n:  # the sPLL node or the spikes: N TDEs, N CCOs, ...
            owner = row % n
        else:  # level and gate nodes: AND / level rows, then relays and timers, then the start
            owner = np.where(row < m, row // k, (row - m) % n)
            owner[row == size - 1] = -1
        spll.append(owner)
        if type(node).__name__ == "CubaLIF":
            taus = np.stack([np.asarray(node.tau_syn, float), np.asarray(node.tau_mem, float)], 1)
            decay += [("CubaLIF", *t) for t in taus.tolist()]
        else:
            decay += [("LIF", t) for t in np.asarray(node.tau, float).tolist()]
        thr += np.asarray(node.v_threshold, float).tolist()
        population.append(np.full(size, index))
        start += size
    rows, cols, in_rows = [], [], []
    into = {b: [a for a, bb in graph.edges if bb == b] for _, b in graph.edges}
    for name, node in graph.nodes.items():
        if type(node).__name__ not in ("Linear", "Affine"):
            continue
        weight = np.asarray(node.weight)
        for post in (b for a, b in graph.edges if a == name):
            if post not in offset:
                continue  # to the output node: the host, not a synapse
            for pre in into.get(name, []):
                r, c = np.nonzero(weight)
                if type(graph.nodes[pre]).__name__ == "Input":
                    in_rows.append(offset[post] + r)
                elif pre in offset:
                    rows.append(offset[post] + r)
                    cols.append(offset[pre] + c)
                else:
                    raise ValueError(
                        f"NIR node {name!r} follows {pre!r}, not a neuron node: this graph is "
                        "not costed (a weight between neurons)"
                    )
    for a, b in graph.edges:  # a neuron node straight into another: one synapse per neuron
        if a in offset and b in offset:
            size = np.asarray(graph.nodes[b].v_threshold).size
            rows.append(offset[b] + np.arange(size))
            cols.append(offset[a] + np.arange(size))
    dt = float(np.asarray(meta["dt"]))
    refractory = str(meta.get("refractory", ""))
    return NeuronGraph(
        "nir-standard", f"{k}-level gate, {refractory} refractory, NIR CubaLIF/LIF nodes", n,
        (dt,), np.zeros(start, np.int64), np.concatenate(spll), ids(decay), ids(thr),
        np.concatenate(population), tuple(names), *_synapses(rows, cols, in_rows, start),
    )  # fmt: skip


def _synapses(rows: list, cols: list, in_rows: list, n: int) -> tuple:
    """The ``(n, n)`` matrix of synapses (one per ``rows[i][j]``, ``cols[i][j]`` pair: post,
    pre) and the synapses from the input onto each neuron (one per entry of ``in_rows``)."""
    none = [np.zeros(0, np.int64)]
    post, pre = np.concatenate(rows or none), np.concatenate(cols or none)
    matrix = coo_matrix((np.ones(post.size, np.int64), (post, pre)), shape=(n, n)).tocsr()
    return matrix, np.bincount(np.concatenate(in_rows or none), minlength=n)
