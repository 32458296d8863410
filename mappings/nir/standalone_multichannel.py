"""Run this multichannel export in a NIR consumer and compare its decisions with spll-hw's.

This file is copied as ``run_multichannel.py`` into the folder ``spll-hw export --network
MULTICHANNEL --to nir-standard --readout FILE`` writes; it needs numpy, nir, torch and the
consumer (Norse or snnTorch), not spll-hw::

    python run_multichannel.py norse                      # the folder's check_inputs.npz
    python run_multichannel.py norse INPUTS.npz DECISIONS.json

Every channel group's ``network.nir`` runs in the consumer at its own step on the group's
channels side by side (``channels/*/load_consumer.py``), its TDE spikes are summed over the
readout's step and, in feature order, drive the readout's graph (``readout/``), whose first
decision spike decides (``readout/decide.py``). The decisions (class and step) are compared with
``decisions.json``'s ``exported`` ones (spll-hw's executor of the same graphs); it prints a
table (the steps between the two) and exits 0 where every decision is of the same class within
:data:`SAME_TIME` of spll-hw's, 1 where one is not. ``INPUTS.npz``
holds ``duration`` [s] and the spike times [s] of every channel of every recording as
``rR/CHANNEL``; ``DECISIONS.json`` a ``decisions`` list, one per recording ``R``, in order.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: Recordings run side by side in one consumer run (memory: steps x batch x outputs).
CHUNK = 40
#: How far [s] a consumer's decision may be from spll-hw's and count as the same: snnTorch
#: computes in float32, spll-hw's executor (and Norse's loader) in float64, and a TDE spike moved
#: by a step moves a slowly rising membrane's crossing by milliseconds (docs/multichannel.md).
SAME_TIME = 0.01
#: How often [s of input] the run checks whether every recording has decided (then it stops).
CHECK_EVERY = 0.1


def _module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def decisions(consumer: str, data, recordings: list[str], folder: Path = HERE) -> list[tuple]:
    """``(label, step, fired)`` of every recording, run in ``consumer`` (module docstring).

    The groups and the readout step together, and the run stops once every recording's
    readout has decided (checked every :data:`CHECK_EVERY` seconds of input): a decision
    spike's verdict depends on the steps up to it only, so those are the decisions of the
    whole run; a recording that never decides runs to the end."""
    loader = _module(folder / "readout" / "load_consumer.py", "spll_hw_load_consumer")
    decide = _module(folder / "readout" / "decide.py", "spll_hw_decide")
    readout = decide.load_readout(folder / "readout" / "readout.npz")
    rows = int(np.prod(np.shape(readout["weights"])[:-1]))  # the decision rows, S k
    dt = float(json.loads((folder / "multichannel.json").read_text())["readout"]["dt"])
    module, _ = loader.load(consumer, folder=folder / "readout")
    every = max(1, round(CHECK_EVERY / dt))
    counts, fired = [], []  # per step: the readout's input and its decision rows' spikes

    def verdict() -> list[tuple]:
        return decide.decide(np.array(fired), np.array(counts),
                             **{key: readout[key] for key in decide.DECIDE_KEYS})  # fmt: skip

    for y in loader.each_step(module, _recorded(tde_counts(consumer, data, recordings, folder),
                                                counts)):  # fmt: skip
        fired.append(y[:, :rows] > 0)
        if len(fired) % every == 0:
            done = verdict()
            if all(made for _, _, made in done):
                return done
    return verdict()


def tde_counts(consumer: str, data, recordings: list[str], folder: Path = HERE) -> Iterator:
    """Every group's TDE spikes of ``recordings`` (keys ``rR`` of ``data``) in ``consumer``,
    summed over the readout's step, in feature order: one array ``(len(recordings), d)`` per
    readout step, the groups stepped as they are asked for."""
    manifest = json.loads((folder / "multichannel.json").read_text())
    loader = _module(folder / "readout" / "load_consumer.py", "spll_hw_load_consumer")
    duration, dt = float(data["duration"]), float(manifest["readout"]["dt"])
    streams = []
    for group in manifest["groups"]:
        where = folder / group["folder"]
        grid = _module(where / "spll_grid.py", "spll_hw_grid")
        module, step = loader.load(consumer, folder=where)
        steps = grid.n_steps(duration, step)
        x = np.stack([grid.arrival_counts(np.asarray(data[f"{r}/{c}"]), steps, step)
                      for c in group["channels"] for r in recordings], axis=1)  # fmt: skip
        outputs = loader.guarded(loader.each_step(module, x), step)
        streams.append((outputs, round(dt / step), len(group["channels"]), group["n_spll"]))
    for _ in range(grid.n_steps(duration, dt)):  # every group's spll_grid.py is the same rule
        parts = []
        for outputs, ratio, channels, n in streams:
            y = sum(next(outputs)[:, :n] for _ in range(ratio))  # (channels x recordings, n)
            parts.append(y.reshape(channels, len(recordings), n).transpose(1, 0, 2)
                         .reshape(len(recordings), channels * n))  # fmt: skip
        yield np.concatenate(parts, axis=1)


def _recorded(rows: Iterator[np.ndarray], into: list) -> Iterator[np.ndarray]:
    """``rows`` passed on, each also appended to ``into``."""
    for row in rows:
        into.append(row)
        yield row


def main(argv: list[str], folder: Path = HERE) -> int:
    if len(argv) not in (1, 3) or argv[0] not in ("norse", "snntorch"):
        print("usage: python run_multichannel.py {norse|snntorch} [INPUTS.npz DECISIONS.json]",
              file=sys.stderr)  # fmt: skip
        return 2
    inputs = Path(argv[1]) if len(argv) == 3 else folder / "check_inputs.npz"
    expected = json.loads((Path(argv[2]) if len(argv) == 3 else folder / "decisions.json")
                          .read_text())["decisions"]  # fmt: skip
    data = np.load(inputs)
    made = []
    for first in range(0, len(expected), CHUNK):
        chunk = [f"r{r}" for r in range(first, min(first + CHUNK, len(expected)))]
        made += decisions(argv[0], data, chunk, folder)
    names = json.loads((folder / "readout" / "standard.json").read_text())["classes"]
    dt = json.loads((folder / "multichannel.json").read_text())["readout"]["dt"]
    print(f"{'recording':<44} {'spll-hw':>17} {argv[0]:>17}  steps apart")
    same_class = same_step = close = 0
    for want, (label, step, _fired) in zip(expected, made, strict=True):
        mine = want["exported"]
        apart = int(step) - mine["step"]
        same_class += mine["label"] == int(label)
        same_step += mine["label"] == int(label) and apart == 0
        close += mine["label"] == int(label) and abs(apart) * dt <= SAME_TIME + 1e-12
        print(f"{want['recording'][:44]:<44} {mine['class']:>10} {mine['step']:>6} "
              f"{names[int(label)]:>10} {int(step):>6}  {apart:+d}"
              + ("" if mine["label"] == int(label) else "  another class"))  # fmt: skip
    print(f"{len(made)} decisions: {same_class} of the same class as spll-hw's, {same_step} of "
          f"them in the same step, {close} within {1e3 * SAME_TIME:g} ms")  # fmt: skip
    return 0 if close == len(made) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
