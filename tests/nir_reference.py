"""The NIR executor's rules (mappings/nir/executor.py's docstring) in numpy, a step of the
whole batch at a time: the independent statement the Rust core's ``NirStepper`` is checked
against (tests/test_nir_engine.py)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from scipy.sparse import csr_matrix

from mappings.nir.executor import schedule


def reference_steps(
    graph, inputs: np.ndarray, dt: float, spike_counts: dict | None = None
) -> Iterator[np.ndarray]:
    """The output node's value of each step, shape ``(batch, n_out)``, as the numpy executor
    computed it before the Rust core did; ``spike_counts`` as :func:`chunks_nir`'s."""
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
