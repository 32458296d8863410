"""Run this folder's check inputs through a NIR consumer and compare its spike counts with
``check.json``, sPLL by sPLL.

This file is copied as ``check_consumer.py`` into the folder ``spll-hw export --to
nir-standard`` writes; it needs numpy, nir, torch and the consumer (Norse or snnTorch), and
``spll_grid.py`` beside it, not spll-hw::

    python check_consumer.py norse        # or: python check_consumer.py snntorch

It loads ``network.nir`` with the folder's ``load_consumer.py`` (the consumer's own NIR
import at the file's ``dt``: ``norse.torch.from_nir(graph, dt=dt)``;
``snntorch.import_nir.import_from_nir(graph)``, which assumes 100 µs), feeds it each train of
``check_inputs.npz`` binned by spll-hw's grid rule (a spike at
``t`` counts in step ``max(1, ceil(t/dt))``, of ``round(duration/dt)`` steps), counts the TDE and
CCO spikes of every sPLL, prints a table and exits 0 when every count is the one
``check.json`` records for the folder (spll-hw's executor of the same stepping) within
:data:`TOLERANCE`, 1 naming the inputs and sPLLs further off, 2 when it cannot run (a consumer
that ``standard.json`` does not list as running the file's ``dt``, a missing package, a run
whose output is the step guard's).
"""

from __future__ import annotations

import json
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: How far a consumer's counts may be from check.json's (``check_counts.Tolerance``: per input
#: and part, the sum of the differences as a fraction of the total; per sPLL, spikes or a
#: fraction of its count): snnTorch computes in float32, check.json in float64, and a threshold
#: crossing that rounds the other way moves a few spikes (measured: docs/backends.md); Norse's
#: loader computes in float64 and counts as check.json does.
TOLERANCE = (0.01, 12, 0.06)


def _folder_module(folder: Path, name: str):
    """The module ``name`` the export folder ships beside this file (``load_consumer``,
    ``check_counts``, ``spll_grid``)."""
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
    return __import__(name)


def counts_per_input(consumer: str, folder: Path, check: dict) -> list[tuple[np.ndarray, ...]]:
    """Per input of ``check.json``, the consumer's TDE and CCO spike counts per sPLL, shape
    ``(N,)`` each; inputs of one length run as one batch, each batch in a module of its own,
    loaded by the folder's ``load_consumer.py`` at the file's step."""
    loader = _folder_module(folder, "load_consumer")
    check_counts = _folder_module(folder, "check_counts")
    spll_grid = _folder_module(folder, "spll_grid")
    n = int(json.loads((folder / "standard.json").read_text())["n_spll"])
    dt = loader.file_step(folder)
    inputs = check_counts.read_inputs(folder, check)
    n_steps = [spll_grid.n_steps(duration, dt) for _, _, duration in inputs]
    counts: list = [None] * len(inputs)
    for length in dict.fromkeys(n_steps):
        idx = [i for i, k in enumerate(n_steps) if k == length]
        steps = np.stack([spll_grid.arrival_counts(inputs[i][1], length, dt) for i in idx], 1)
        module, step = loader.load(consumer, folder=folder)
        out = loader.run(module, steps, step).sum(axis=0)  # (B, 2N)
        for b, i in enumerate(idx):
            counts[i] = (out[b, :n].astype(np.int64), out[b, n:].astype(np.int64))
    return counts


def runnable(folder: Path) -> dict[str, str]:
    """``standard.json``'s consumers that run the file at its ``dt`` and this script knows,
    with the line it gives each."""
    known = _folder_module(folder, "load_consumer").CONSUMERS
    info = json.loads((folder / "standard.json").read_text())
    return {name: line for name, line in info["consumers"].items()
            if name in known and line.startswith("runs it")}  # fmt: skip


def versions(consumer: str, package: str) -> str:
    """The versions of the packages that ran the check (``package``: the consumer's)."""
    names = ("torch", package, "nir", "numpy")
    found = []
    for name in names:
        try:
            found.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            found.append(f"{name} (version unknown)")
    return ", ".join(found)


def main(argv: list[str], folder: Path = HERE) -> int:
    loader = _folder_module(folder, "load_consumer")
    if len(argv) != 1 or argv[0] not in loader.CONSUMERS:
        print(f"usage: python check_consumer.py {{{'|'.join(loader.CONSUMERS)}}}",
              file=sys.stderr)  # fmt: skip
        return 2
    consumer = argv[0]
    can = runnable(folder)
    if consumer not in can:
        line = json.loads((folder / "standard.json").read_text())["consumers"].get(consumer)
        runs = ", ".join(can) or "none that check_consumer.py runs (spll-hw export --check does)"
        print(f"{consumer} {line or 'is not listed in standard.json'}; this folder's "
              f"consumers: {runs}", file=sys.stderr)  # fmt: skip
        return 2
    check_counts = _folder_module(folder, "check_counts")
    try:
        check = check_counts.read_check(folder)
    except FileNotFoundError as exc:
        print(exc, file=sys.stderr)
        return 2
    try:
        counts = counts_per_input(consumer, folder, check)
    except ImportError as exc:
        print(f"{consumer} needs torch, nir and {loader.CONSUMERS[consumer]}: {exc}",
              file=sys.stderr)  # fmt: skip
        return 2
    except (ValueError, loader.StepGuardTripped) as exc:
        print(f"{consumer}: {exc}", file=sys.stderr)
        return 2
    package = loader.CONSUMERS[consumer]
    print(f"{consumer} ({versions(consumer, package)}) on the {len(counts)} inputs of "
          "check_inputs.npz:")  # fmt: skip
    return check_counts.report(consumer, check, counts, check_counts.Tolerance(*TOLERANCE))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
