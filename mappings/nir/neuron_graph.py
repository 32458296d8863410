"""The construction ``nir-standard`` writes as a graph of standard neurons a chip costs
(:class:`spll_hw.neuron_graph.NeuronGraph`), neuron for neuron and synapse for synapse.

:func:`nir_graph`: a NIR graph of ``CubaLIF``, ``LIF``, ``Linear`` and ``Affine`` nodes
(:mod:`mappings.nir.standard`): every row of a neuron node is a neuron, in the order of the
sorted node names (:func:`~mappings.nir.executor.neuron_nodes`, the executor's), and every
nonzero weight of a ``Linear`` or ``Affine`` between two neuron nodes (or from the input) a
synapse; biases are the neurons' own. Neurons share decays where their node type and time
constants are equal, thresholds where their ``v_threshold`` is. Every row is counted, also the
level node's rows that hold no level neuron (each relay's row: the node is one vector).

Which sPLL a neuron belongs to follows the layout of the gate
(:func:`~spll_hw.construction.gate.gate_layout`): a level or AND neuron its sPLL's, a
relay, hold or timer neuron the sPLL of the TDE or CCO it serves; the start neuron and pulse and
the step guard's neurons (the rows of the level and gate nodes after the gate's, the last row
of the sPLL node) are shared by every sPLL.
"""

from __future__ import annotations

import numpy as np

from spll_hw.neuron_graph import NeuronGraph, ids, synapse_counts

from .executor import neuron_nodes


def nir_graph(graph) -> NeuronGraph:
    """The :class:`NeuronGraph` of a NIR graph of standard nodes written by
    :func:`~mappings.nir.standard.to_standard_nir` (module docstring); ``ValueError`` naming
    the node for a graph of another shape."""
    meta = graph.metadata
    n, k = int(np.asarray(meta["n_spll"])), int(np.asarray(meta["gate_levels"]))
    m = n * k
    names, sizes, decay, thr = _neurons(graph)
    spll = []
    for size in sizes:
        row = np.arange(size)
        if row.size in (2 * n, 4 * n + 1):  # the spikes or the sPLL node: N TDEs, N CCOs, ...
            owner = np.where(row < 4 * n, row % n, -1)  # ..., the step guard's latch (shared)
        else:  # level and gate nodes: AND / level rows, then relays and timers, then the start
            owner = np.where(row < m, row // k, (row - m) % n)  # rows and the step guard's
            owner[row >= m + 6 * n] = -1
        spll.append(owner)
    refractory = str(meta.get("refractory", ""))
    return _graph(graph, f"{k}-level gate, {refractory} refractory, NIR CubaLIF/LIF nodes", n,
                  np.concatenate(spll), names, sizes, decay, thr)  # fmt: skip


def readout_graph(graph) -> NeuronGraph:
    """The :class:`NeuronGraph` of the multichannel readout's NIR graph
    (:func:`~mappings.nir.readout_graph.to_readout_nir`): every neuron shared (it realises no
    sPLL: ``spll`` -1, ``n_spll`` 0), its input the TDE spikes of the channel groups."""
    names, sizes, decay, thr = _neurons(graph)
    return _graph(graph, "spiking readout, NIR CubaLIF/LIF nodes", 0,
                  np.full(sum(sizes), -1, np.int64), names, sizes, decay, thr)  # fmt: skip


def _neurons(graph) -> tuple[list[str], list[int], list, list]:
    """The neuron nodes in the executor's order, each one's neurons, and per neuron its decay
    key (node type and time constants) and threshold."""
    names = neuron_nodes(graph)
    sizes, decay, thr = [], [], []
    for name in names:
        node = graph.nodes[name]
        sizes.append(int(np.asarray(node.v_threshold).shape[0]))
        if type(node).__name__ == "CubaLIF":
            taus = np.stack([np.asarray(node.tau_syn, float), np.asarray(node.tau_mem, float)], 1)
            decay += [("CubaLIF", *t) for t in taus.tolist()]
        else:
            decay += [("LIF", t) for t in np.asarray(node.tau, float).tolist()]
        thr += np.asarray(node.v_threshold, float).tolist()
    return names, sizes, decay, thr


def _graph(graph, description: str, n_spll: int, spll, names, sizes, decay, thr) -> NeuronGraph:
    """The :class:`NeuronGraph` of ``graph`` with its neurons of :func:`_neurons` owned by
    ``spll``: every nonzero weight of a ``Linear`` or ``Affine`` between two neuron nodes (or
    from one of the input's channels) a synapse, a neuron node straight into another one
    synapse per neuron."""
    offset = dict(zip(names, np.cumsum([0, *sizes[:-1]]).tolist(), strict=True))
    rows, cols, in_rows, in_cols = [], [], [], []
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
                    in_cols.append(c)
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
    n = len(spll)
    dt = float(np.asarray(graph.metadata["dt"]))
    k = max((int(np.prod(x.input_type["input"])) for x in graph.nodes.values()
             if type(x).__name__ == "Input"), default=1)  # fmt: skip
    return NeuronGraph(
        "nir-standard", description, n_spll, (dt,), np.zeros(n, np.int64), spll, ids(decay),
        ids(thr), np.repeat(np.arange(len(names)), sizes), tuple(names),
        *synapse_counts(rows, cols, in_rows, n, in_cols, k),
    )  # fmt: skip
