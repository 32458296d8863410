"""The numpy executor of NIR graphs of standard nodes, by the rules clocked consumers follow.

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

It needs only ``nir``, ``numpy``, ``scipy`` and the model's grid: the pure-NIR consumer of the
test suite (``nir-numpy``) and of :mod:`mappings.nir.consumers`.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
from scipy.sparse import csr_matrix

from spll_hw.model.grid import arrival_counts, n_steps

#: Node types :func:`run_nir` executes.
NODE_TYPES = ("Input", "Output", "Linear", "Affine", "LIF", "CubaLIF")


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
        at a fine step (10 s at 1 µs is 10^7 steps) is better consumed step by step
        (:func:`step_nir`).
    """
    batched = np.ndim(inputs) == 3
    out = np.array(list(step_nir(graph, inputs, dt)))  # (n_steps, batch, n_out)
    return out if batched else out[:, 0, :]


def step_nir(
    graph, inputs: np.ndarray, dt: float, spike_counts: dict | None = None
) -> Iterator[np.ndarray]:
    """:func:`run_nir` one step at a time: yields the output node's value of each step, shape
    ``(batch, n_out)`` (``batch`` 1 for unbatched ``inputs``). Memory: the nodes' states,
    not the steps. ``spike_counts``, where given, is filled with each neuron node's spikes so
    far by name (:func:`neuron_nodes`), shape ``(batch, size)``."""
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite time > 0 s, got {dt!r}")
    for name, node in graph.nodes.items():
        if type(node).__name__ not in NODE_TYPES:
            raise ValueError(f"node {name!r} is a {type(node).__name__}; run_nir runs {NODE_TYPES}")
    order, delayed = schedule(graph)
    preds: dict[str, list[str]] = {k: [] for k in graph.nodes}
    for a, b in graph.edges:
        preds[b].append(a)
    x = np.asarray(inputs, dtype=float)
    x = x.reshape(x.shape[0], -1, x.shape[-1]) if x.ndim == 3 else x.reshape(x.shape[0], 1, -1)
    outputs = [k for k, v in graph.nodes.items() if type(v).__name__ == "Output"]
    if len(outputs) != 1:
        raise ValueError(f"NIR graph needs exactly one Output node, has {outputs}")
    node_params = {k: _params(v, dt) for k, v in graph.nodes.items()}
    states: dict[str, list[np.ndarray]] = {}
    current: dict[str, np.ndarray] = {}
    previous: dict[str, np.ndarray] = {}
    for step in range(x.shape[0]):
        for name in order:
            kind, prm = node_params[name]
            if kind == "Input":
                current[name] = x[step]
                continue
            total = None
            for src in preds[name]:
                value = previous.get(src) if (src, name) in delayed else current[src]
                if value is None:
                    continue
                total = value if total is None else total + value
            current[name] = _step(kind, prm, total, states, name, x.shape[1])
            if spike_counts is not None and kind in ("LIF", "CubaLIF"):
                so_far = spike_counts.get(name)
                spike_counts[name] = current[name] if so_far is None else so_far + current[name]
        yield current[outputs[0]]
        previous = dict(current)


def _params(node, dt: float):
    kind = type(node).__name__
    f = lambda a: np.asarray(a, dtype=float)  # noqa: E731
    if kind in ("Linear", "Affine"):
        # Sparse: the weights are mostly zeros, and a small dense product costs a BLAS call.
        prm = {"w": csr_matrix(f(node.weight))}
        prm["b"] = f(node.bias) if kind == "Affine" else None
        return kind, prm
    if kind == "LIF":
        return kind, {
            "a": dt / f(node.tau), "r": f(node.r), "leak": f(node.v_leak),
            "thr": f(node.v_threshold), "reset": f(node.v_reset),
        }  # fmt: skip
    if kind == "CubaLIF":
        return kind, {
            "a_syn": dt / f(node.tau_syn), "w_in": f(node.w_in), "a": dt / f(node.tau_mem),
            "r": f(node.r), "leak": f(node.v_leak), "thr": f(node.v_threshold),
            "reset": f(node.v_reset),
        }  # fmt: skip
    return kind, {}


def _step(kind: str, prm: dict, x, states: dict, name: str, batch: int) -> np.ndarray:
    """One step of node ``name``; ``x``: its summed input, shape ``(batch, n_in)`` (None:
    none yet); returns its output, shape ``(batch, n_out)``."""
    if kind == "Output":
        return x
    if kind in ("Linear", "Affine"):
        y = (prm["w"] @ x.T).T if x is not None else np.zeros((batch, prm["w"].shape[0]))
        return y + prm["b"] if prm["b"] is not None else y
    size = prm["thr"].shape[0]
    x = np.zeros((batch, size)) if x is None else x
    if name not in states:
        states[name] = [np.zeros((batch, size)), np.zeros((batch, size))]
    syn, v = states[name]
    if kind == "CubaLIF":
        syn += prm["a_syn"] * (prm["w_in"] * x - syn)
        drive = syn
    else:
        drive = x
    v += prm["a"] * (prm["leak"] - v + prm["r"] * drive)
    spike = v > prm["thr"]
    np.copyto(v, prm["reset"], where=spike)
    return spike.astype(float)


def input_steps(spikes: np.ndarray, duration: float, dt: float) -> np.ndarray:
    """Input spike counts per step (the input node's values), shape ``(round(duration/dt),)``
    float: the model's grid (:func:`spll_hw.model.grid.arrival_counts`)."""
    return arrival_counts(spikes, n_steps(duration, dt), dt).astype(float)
