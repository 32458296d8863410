"""Run this folder's check inputs through a NIR consumer and compare its spike counts with
``check.json``, sPLL by sPLL.

This file is copied as ``check_consumer.py`` into the folder ``spll-hw export --to
nir-standard`` writes; it needs numpy, nir, torch and the consumer (Norse or snnTorch), and
``spll_grid.py`` beside it, not spll-hw::

    python check_consumer.py norse        # or: python check_consumer.py snntorch

It loads ``network.nir`` with the consumer's own NIR import (``norse.torch.from_nir(graph,
dt=dt)`` with the file's ``dt``; ``snntorch.import_nir.import_from_nir(graph)``, which assumes
100 µs), feeds it each train of ``check_inputs.npz`` binned by spll-hw's grid rule (a spike at
``t`` counts in step ``max(1, ceil(t/dt))``, of ``round(duration/dt)`` steps), counts the TDE and
CCO spikes of every sPLL, prints a table and exits 0 when every count is the one
``check.json`` records for the folder (spll-hw's numpy executor of the same stepping) within
:data:`TOLERANCE`, 1 naming the inputs and sPLLs further off, 2 when it cannot run (a consumer
that ``standard.json`` does not list as running the file's ``dt``, a missing package).
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: Consumers this script runs, with the package each needs beside torch and nir.
CONSUMERS = {"norse": "norse", "snntorch": "snntorch"}
#: How far a consumer's counts may be from check.json's (``check_counts.Tolerance``: per input
#: and part, the sum of the differences as a fraction of the total; per sPLL, spikes or a
#: fraction of its count): the consumers compute in float32, check.json in float64, and a
#: threshold crossing that rounds the other way moves a few spikes (measured: docs/backends.md).
TOLERANCE = (0.01, 12, 0.06)


def load_module(consumer: str, graph, dt: float):
    """The torch module of ``consumer``'s NIR import of ``graph`` (a ``nir.NIRGraph`` written
    for time step ``dt`` [s]); what the imports print and log is dropped."""
    with contextlib.redirect_stdout(io.StringIO()), _quiet_logging():
        if consumer == "snntorch":
            from snntorch.import_nir import import_from_nir

            return import_from_nir(graph)
        import norse.torch

        return norse.torch.from_nir(graph, dt=dt)


def run_module(module, steps: np.ndarray) -> np.ndarray:
    """Step ``module`` once per row of ``steps`` (input spike counts, shape ``(T, B)``) from
    its initial state; its outputs, shape ``(T, B, n_out)`` (1 where a neuron spiked). Torch
    runs on one thread meanwhile: the graph's small products are fastest so (3 ms a step
    against 70-110 ms with two threads on a busy 2-core machine)."""
    import torch

    x = torch.as_tensor(np.asarray(steps), dtype=torch.float32)[:, :, None]  # (T, B, 1)
    out = []
    state = None
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with torch.no_grad(), contextlib.redirect_stdout(io.StringIO()):
            for k in range(x.shape[0]):
                result = module(x[k]) if state is None else module(x[k], state)
                y, state = result[0], result[-1]
                out.append(y.reshape(x.shape[1], -1).numpy())
    finally:
        torch.set_num_threads(threads)
    return np.array(out)


@contextlib.contextmanager
def _quiet_logging():
    """Norse logs a warning per node it reads approximately; the counts say how it ran."""
    previous = logging.root.manager.disable
    logging.disable(logging.WARNING)
    try:
        yield
    finally:
        logging.disable(previous)


def counts_per_input(consumer: str, folder: Path, check: dict) -> list[tuple[np.ndarray, ...]]:
    """Per input of ``check.json``, the consumer's TDE and CCO spike counts per sPLL, shape
    ``(N,)`` each; inputs of one length run as one batch, each batch in a module of its own."""
    import nir

    sys.path.insert(0, str(folder))
    import check_counts
    import spll_grid

    graph = nir.read(folder / "network.nir")
    dt = float(np.asarray(graph.metadata["dt"]))
    n = int(np.asarray(graph.metadata["n_spll"]))
    inputs = check_counts.read_inputs(folder, check)
    n_steps = [spll_grid.n_steps(duration, dt) for _, _, duration in inputs]
    counts: list = [None] * len(inputs)
    for length in dict.fromkeys(n_steps):
        idx = [i for i, k in enumerate(n_steps) if k == length]
        steps = np.stack([spll_grid.arrival_counts(inputs[i][1], length, dt) for i in idx], 1)
        out = run_module(load_module(consumer, graph, dt), steps).sum(axis=0)  # (B, 2N)
        for b, i in enumerate(idx):
            counts[i] = (out[b, :n].astype(np.int64), out[b, n:].astype(np.int64))
    return counts


def runnable(folder: Path) -> dict[str, str]:
    """``standard.json``'s consumers that run the file at its ``dt`` and this script knows,
    with the line it gives each."""
    info = json.loads((folder / "standard.json").read_text())
    return {name: line for name, line in info["consumers"].items()
            if name in CONSUMERS and line.startswith("runs it")}  # fmt: skip


def versions(consumer: str) -> str:
    """The versions of the packages that ran the check."""
    from importlib.metadata import PackageNotFoundError, version

    names = ("torch", CONSUMERS[consumer], "nir", "numpy")
    found = []
    for name in names:
        try:
            found.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            found.append(f"{name} (version unknown)")
    return ", ".join(found)


def main(argv: list[str], folder: Path = HERE) -> int:
    if len(argv) != 1 or argv[0] not in CONSUMERS:
        print(f"usage: python check_consumer.py {{{'|'.join(CONSUMERS)}}}", file=sys.stderr)
        return 2
    consumer = argv[0]
    can = runnable(folder)
    if consumer not in can:
        line = json.loads((folder / "standard.json").read_text())["consumers"].get(consumer)
        runs = ", ".join(can) or "none that check_consumer.py runs (spll-hw export --check does)"
        print(f"{consumer} {line or 'is not listed in standard.json'}; this folder's "
              f"consumers: {runs}", file=sys.stderr)  # fmt: skip
        return 2
    sys.path.insert(0, str(folder))
    import check_counts

    try:
        check = check_counts.read_check(folder)
    except FileNotFoundError as exc:
        print(exc, file=sys.stderr)
        return 2
    try:
        counts = counts_per_input(consumer, folder, check)
    except ImportError as exc:
        print(f"{consumer} needs torch, nir and {CONSUMERS[consumer]}: {exc}", file=sys.stderr)
        return 2
    print(f"{consumer} ({versions(consumer)}) on the {len(counts)} inputs of check_inputs.npz:")
    return check_counts.report(consumer, check, counts, check_counts.Tolerance(*TOLERANCE))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
