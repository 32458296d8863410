"""spll-hw's executor of NIR graphs of standard nodes, by the rules clocked consumers follow.

It runs any graph of ``Input``, ``Output``, ``Linear``, ``Affine``, ``LIF`` and ``CubaLIF``
nodes (vectors only), stepping by ``dt`` as snnTorch's and Norse's imports do:

* a spike is 1 in the step it happens; a node's input is the sum of its incoming edges;
* ``Linear``: ``W x``; ``Affine``: ``W x + b`` (the bias every step);
* ``LIF``: ``v <- v + dt/tau (v_leak - v + r x)``; ``CubaLIF``:
  ``I <- I + dt/tau_syn (-I + w_in x)``, then ``v <- v + dt/tau_mem (v_leak - v + r I)``;
  a neuron spikes when ``v > v_threshold`` and is set to ``v_reset`` in the same step;
* nodes run in the order of a depth-first walk from the input along the edges in the graph's
  order; an edge into a node that is still on the walk's path (one that closes a cycle, or a
  self-loop) delivers the previous step's output, as nirtorch does.

The steps run in the Rust core (``engine/src/nir_graph.rs``: every sum and product as numpy
makes them, in the same order, so the results are numpy's to the bit;
``tests/nir_reference.py`` states the rules in numpy and ``tests/test_nir_engine.py`` checks
the two agree), this module orders the graph and hands it over. It is the pure-NIR consumer
of the test suite (``nir-numpy``, named for its first implementation) and of
:mod:`mappings.nir.consumers`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from scipy.sparse import csc_matrix

from spll_hw import _engine
from spll_hw.model.grid import arrival_counts, n_steps

#: Node types :func:`run_nir` executes.
NODE_TYPES = ("Input", "Output", "Linear", "Affine", "LIF", "CubaLIF")
#: Steps of one :func:`chunks_nir` call into the core.
CHUNK = 4096


def schedule(graph) -> tuple[list[str], set[tuple[str, str]]]:
    """Execution order of the graph's nodes and its delayed (cycle-closing) edges."""
    inputs = [k for k, v in graph.nodes.items() if type(v).__name__ == "Input"]
    if len(inputs) != 1:
        raise ValueError(f"NIR graph needs exactly one Input node, has {inputs}")
    succ: dict[str, list[str]] = {k: [] for k in graph.nodes}
    for a, b in graph.edges:
        succ[a].append(b)
    order: list[str] = []
    delayed: set[tuple[str, str]] = set()
    state: dict[str, int] = {}  # 1 on the path, 2 done

    def visit(node: str) -> None:
        state[node] = 1
        for nxt in succ[node]:
            if state.get(nxt) == 1:
                delayed.add((node, nxt))
            elif nxt not in state:
                visit(nxt)
        state[node] = 2
        order.append(node)

    visit(inputs[0])
    order.reverse()
    unreachable = sorted(set(graph.nodes) - set(order))
    if unreachable:
        raise ValueError(f"NIR graph nodes {unreachable} are not reachable from the input")
    return order, delayed


def neuron_nodes(graph) -> list[str]:
    """The names of the graph's neuron nodes (``LIF``, ``CubaLIF``), sorted: the order in which
    :func:`step_nir`'s ``spike_counts`` and :mod:`mappings.nir.neuron_graph` number neurons."""
    return sorted(k for k, v in graph.nodes.items() if type(v).__name__ in ("LIF", "CubaLIF"))


def run_nir(graph, inputs: np.ndarray, dt: float) -> np.ndarray:
    """Run ``graph`` on per-step input values.

    Args:
        graph: a ``nir.NIRGraph`` of :data:`NODE_TYPES`.
        inputs: the input node's value per step, shape ``(n_steps, n_in)`` or ``(n_steps,)``
            (spike counts for spikes), or a batch of samples run side by side, shape
            ``(n_steps, batch, n_in)``.
        dt: time step [s].

    Returns:
        The output node's value per step, shape ``(n_steps, n_out)``; for a batch
        ``(n_steps, batch, n_out)``. That is ``n_steps`` times the output's size: a long run
        at a fine step (10 s at 1 µs is 10^7 steps) is better consumed in chunks
        (:func:`chunks_nir`).
    """
    batched = np.ndim(inputs) == 3
    out = np.concatenate(list(chunks_nir(graph, inputs, dt)))  # (n_steps, batch, n_out)
    return out if batched else out[:, 0, :]


def step_nir(
    graph, inputs: np.ndarray, dt: float, spike_counts: dict | None = None
) -> Iterator[np.ndarray]:
    """:func:`run_nir` one step at a time: yields the output node's value of each step, shape
    ``(batch, n_out)`` (``batch`` 1 for unbatched ``inputs``); ``spike_counts`` as
    :func:`chunks_nir`'s."""
    for chunk in chunks_nir(graph, inputs, dt, spike_counts):
        yield from chunk


def chunks_nir(
    graph, inputs: np.ndarray, dt: float, spike_counts: dict | None = None, chunk: int = CHUNK
) -> Iterator[np.ndarray]:
    """:func:`run_nir` ``chunk`` steps at a time, by the Rust core (``spll_hw._engine``'s
    ``NirStepper``, the samples in parallel, the GIL released): yields the output node's values
    of each run of steps, shape ``(steps, batch, n_out)``. Memory: the nodes' states and one
    chunk, not every step. ``spike_counts``, where given, is filled with each neuron node's
    spikes so far by name (:func:`neuron_nodes`), shape ``(batch, size)``, after every chunk."""
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite time > 0 s, got {dt!r}")
    for name, node in graph.nodes.items():
        if type(node).__name__ not in NODE_TYPES:
            raise ValueError(f"node {name!r} is a {type(node).__name__}; run_nir runs {NODE_TYPES}")
    order, delayed = schedule(graph)
    outputs = [k for k, v in graph.nodes.items() if type(v).__name__ == "Output"]
    if len(outputs) != 1:
        raise ValueError(f"NIR graph needs exactly one Output node, has {outputs}")
    x = np.asarray(inputs, dtype=float)
    x = x.reshape(x.shape[0], -1, x.shape[-1]) if x.ndim == 3 else x.reshape(x.shape[0], 1, -1)
    position = {name: k for k, name in enumerate(order)}
    preds: dict[str, list[tuple[int, bool]]] = {k: [] for k in graph.nodes}
    for a, b in graph.edges:
        preds[b].append((position[a], (a, b) in delayed))
    sizes = {order[0]: x.shape[2]}
    nodes = []
    for name in order:
        node = graph.nodes[name]
        known = [sizes[order[p]] for p, _ in preds[name] if order[p] in sizes]
        size_in = _size_in(node, known, sizes.get(name))
        spec = _node_spec(node, dt)
        sizes[name] = _size_out(spec) or size_in
        nodes.append((type(node).__name__, size_in, preds[name], *spec))
    stepper = _engine.NirStepper(nodes, position[outputs[0]], x.shape[1])
    for start in range(0, x.shape[0], chunk):
        yield stepper.run(np.ascontiguousarray(x[start : start + chunk]))
        if spike_counts is not None:
            spikes = stepper.spikes()
            spike_counts.update({order[k]: counts for k, counts in spikes.items()})


def _size_in(node, sources: list[int], given: int | None) -> int:
    """The size of a node's input: that of its sources (the input's own where given), else
    what its coefficients say (a node fed only by edges that close cycles)."""
    if given is not None:
        return given
    if sources:
        return sources[0]
    kind = type(node).__name__
    if kind in ("Linear", "Affine"):
        return int(np.shape(node.weight)[1])
    if kind in ("LIF", "CubaLIF"):
        return int(np.size(node.v_threshold))
    raise ValueError(f"NIR graph: a {kind} node without inputs")


def _node_spec(node, dt: float) -> tuple[list[np.ndarray], tuple | None]:
    """The coefficient arrays and matrix (CSC ``(starts, rows, n_rows)``) of one node as the
    core takes them (``a = dt / tau``; coefficients broadcast to the node's size)."""
    kind = type(node).__name__
    if kind in ("Linear", "Affine"):
        # Sparse: the weights are mostly zeros, and the inputs (spikes) too.
        w = csc_matrix(np.asarray(node.weight, dtype=float))
        w.sort_indices()
        arrays = [w.data.astype(float)]
        if kind == "Affine":
            arrays.append(_vector(node.bias, w.shape[0]))
        return arrays, (w.indptr.astype(np.int64), w.indices.astype(np.int64), w.shape[0])
    if kind in ("LIF", "CubaLIF"):
        n = int(np.size(node.v_threshold))
        lif = [
            dt / _vector(node.tau if kind == "LIF" else node.tau_mem, n),
            _vector(node.r, n),
            _vector(node.v_leak, n),
            _vector(node.v_threshold, n),
            _vector(node.v_reset, n),
        ]
        if kind == "CubaLIF":
            lif = [dt / _vector(node.tau_syn, n), _vector(node.w_in, n), *lif]
        return lif, None
    return [], None


def _size_out(spec: tuple[list[np.ndarray], tuple | None]) -> int | None:
    arrays, matrix = spec
    if matrix is not None:
        return matrix[2]
    return arrays[-1].size if arrays else None


def _vector(values, n: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=float), (n,)))


def input_steps(spikes: np.ndarray, duration: float, dt: float) -> np.ndarray:
    """Input spike counts per step (the input node's values), shape ``(round(duration/dt),)``
    float: the model's grid (:func:`spll_hw.model.grid.arrival_counts`)."""
    return arrival_counts(spikes, n_steps(duration, dt), dt).astype(float)
