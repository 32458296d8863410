"""Run the exported standard sPLL network on Lava's own processes (bit-accurate, CPU).

This file is copied as ``run.py`` into the folder ``spll-hw export --to lava-standard`` writes;
it needs only numpy, lava-nc 0.10 and ``lava_compat.py`` beside it (which lets lava-nc 0.10
import on Python 3.11), not spll-hw::

    python run.py spikes.npy 1.0      # input spike times [s] (1-D .npy), duration [s]

prints JSON: ``tde_counts`` and ``cco_counts`` (spikes per sPLL), ``dt``, ``steps``. ::

    python run.py --check             # every input of check_inputs.npz
    python run.py --check 0 3         # only inputs 0 and 3 (check.json's order)

runs the export check's inputs (``check_inputs.npz``) on Lava and compares every sPLL's TDE and
CCO count with the one ``check.json`` records (spll-hw's numpy run of the same integers, which
Lava's bit-accurate models match exactly): prints a table, exits 0 when all are equal and 1
naming the inputs and sPLLs that are not (``check_counts.py`` beside this file compares them).
Lava steps one to two thousand times a second, so an input of 1 s at 10 µs takes about a
minute.

The network is built from ``params.npz`` with ``lava.proc.lif.process.LIF``,
``lava.proc.dense.process.Dense`` and ``lava.proc.io`` ring buffers only, and runs with
``Loihi2SimCfg(select_tag="fixed_pt")``: Lava's bit-accurate models of Loihi's neuron and
synapse. Input spikes count in the steps that spll-hw's grid rule gives (``spll_grid.py``: a
spike at ``t`` in step ``max(1, ceil(t/dt))``, one on a step's end in that step, of
``round(duration/dt)`` steps).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def load_params(path: str | Path) -> dict:
    """``params.npz`` as ``{"dt", "n_spll", "lif": {pop: {...}}, "members": {pop: sPLLs},
    "dense": {name: (source, target, weights, weight_exp, num_message_bits)}}``."""
    raw = np.load(path)
    params = {"dt": float(raw["dt"]), "n_spll": int(raw["n_spll"]), "lif": {}, "members": {},
              "dense": {}}  # fmt: skip
    for key in raw.files:
        parts = key.split(".")
        if parts[0] == "lif":
            params["lif"].setdefault(parts[1], {})[parts[2]] = raw[key]
        elif parts[0] == "members":
            params["members"][parts[1]] = raw[key]
        elif parts[0] == "dense" and parts[2] == "weights":
            src, dst, exp, bits = (str(x) for x in raw[f"dense.{parts[1]}.meta"])
            params["dense"][parts[1]] = (src, dst, raw[key], int(exp), int(bits))
    return params


def input_counts(spikes: np.ndarray, duration: float, dt: float) -> np.ndarray:
    """Input spikes per step, shape ``(round(duration/dt),)``, by the model's grid rule
    (``spll_grid.py`` beside this file, written by the export: spll-hw's
    ``spll_hw/model/grid.py``)."""
    sys.path.insert(0, str(HERE))
    import spll_grid

    return spll_grid.arrival_counts(spikes, spll_grid.n_steps(duration, dt), dt)


def build(params: dict, counts: np.ndarray) -> tuple[dict, dict]:
    """The network's Lava processes fed by the input ``counts`` per step: ``(LIF processes by
    population, ring-buffer sinks by population)``, connected and ready to compile, with
    Python's recursion limit raised for lava-nc's compiler (:func:`allow_compile`)."""
    sys.path.insert(0, str(HERE))
    import lava_compat

    lava_compat.install()
    from lava.proc.dense.process import Dense
    from lava.proc.io.sink import RingBuffer as Sink
    from lava.proc.io.source import RingBuffer as Source
    from lava.proc.lif.process import LIF

    n_steps = int(counts.size)
    source = Source(data=np.asarray(counts, dtype=np.int64).reshape(1, n_steps))
    lif = {}
    for pop, p in params["lif"].items():
        lif[pop] = LIF(
            shape=(p["bias_mant"].shape[0],), du=int(p["du"]), dv=int(p["dv"]),
            vth=int(p["vth"]), bias_mant=p["bias_mant"].astype(np.int64),
            bias_exp=p["bias_exp"].astype(np.int64), name=pop,
        )  # fmt: skip
    for name, (src, dst, weights, exp, bits) in params["dense"].items():
        dense = Dense(weights=weights.astype(np.int64), weight_exp=exp, num_message_bits=bits,
                      name=name)  # fmt: skip
        (source if src == "input" else lif[src]).s_out.connect(dense.s_in)
        dense.a_out.connect(lif[dst].a_in)
    # One sink per TDE and CCO population (one per set of time constants) and per population
    # of their refractory units' hold neurons.
    sinks = {}
    for pop in params["lif"]:
        if pop.startswith(("tde", "cco", "hold_")):
            sinks[pop] = Sink(shape=(len(params["members"][pop]),), buffer=n_steps)
            lif[pop].s_out.connect(sinks[pop].a_in)
    allow_compile(len(lif) + len(params["dense"]) + 1 + len(sinks))
    return lif, sinks


def allow_compile(n_processes: int) -> None:
    """Raise Python's recursion limit for a network of ``n_processes`` Lava processes:
    lava-nc 0.10's compiler flattens its list of processes recursively
    (``flatten_list_recursive``, a frame per process), so a network of more than about 1000
    (a time-scaled or tuned layout: one set of processes per set of decays) fails there with
    ``RecursionError`` under the default limit."""
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 2 * n_processes + 1000))


def run(params: dict, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Run the network over the input ``counts`` per step; TDE and CCO spike rasters, each of
    shape ``(n_spll, n_steps)``."""
    from lava.magma.core.run_conditions import RunSteps
    from lava.magma.core.run_configs import Loihi2SimCfg

    lif, sinks = build(params, counts)
    n, n_steps = params["n_spll"], int(counts.size)
    run_cfg = Loihi2SimCfg(select_tag="fixed_pt")
    lif["gate"].run(condition=RunSteps(num_steps=n_steps), run_cfg=run_cfg)
    rasters = {part: np.zeros((n, n_steps), dtype=bool) for part in ("tde", "cco")}
    try:
        fired = {pop: np.asarray(sink.data.get()) != 0 for pop, sink in sinks.items()}
    finally:
        lif["gate"].stop()
    for pop, spikes in fired.items():
        if pop.startswith(("tde", "cco")):
            rasters[pop[:3]][params["members"][pop]] = spikes
    # A spike in a step its refractory unit holds the neuron is not one of the network's.
    for pop, spikes in fired.items():
        if pop.startswith("hold_"):
            rasters[pop[5:8]][params["members"][pop]] &= ~spikes
    return rasters["tde"], rasters["cco"]


def check(selected: list[str]) -> int:
    """``run.py --check [INPUT ...]`` (module docstring): the exit status."""
    sys.path.insert(0, str(HERE))
    import check_counts

    record = check_counts.read_check(HERE)
    inputs = check_counts.read_inputs(HERE, record)
    try:
        chosen = [int(i) for i in selected] or list(range(len(inputs)))
    except ValueError:
        chosen = [-1]
    if any(not 0 <= i < len(inputs) for i in chosen):
        print(f"--check takes input numbers 0..{len(inputs) - 1} (check.json's order), got "
              f"{' '.join(selected)}", file=sys.stderr)  # fmt: skip
        return 2
    params = load_params(HERE / "params.npz")
    counts = []
    for i in chosen:
        label, spikes, duration = inputs[i]
        print(f"input {i}: {label} ({duration:g} s)", file=sys.stderr)
        tde, cco = run(params, input_counts(spikes, duration, params["dt"]))
        counts.append((tde.sum(axis=1), cco.sum(axis=1)))
    record = record | {"inputs": [record["inputs"][i] for i in chosen]}
    return check_counts.report("lava-nc", record, counts)


def main(argv: list[str]) -> int:
    if argv[:1] == ["--check"]:
        return check(argv[1:])
    if len(argv) != 2:
        print("usage: python run.py SPIKES.npy DURATION_S  or  python run.py --check [INPUT ...]",
              file=sys.stderr)  # fmt: skip
        return 2
    spikes = np.load(argv[0])
    duration = float(argv[1])
    if not (math.isfinite(duration) and duration > 0):
        print(f"duration must be a finite time > 0 s, got {argv[1]}", file=sys.stderr)
        return 2
    params = load_params(HERE / "params.npz")
    counts = input_counts(spikes, duration, params["dt"])
    tde, cco = run(params, counts)
    print(
        json.dumps(
            {
                "tde_counts": tde.sum(axis=1).astype(int).tolist(),
                "cco_counts": cco.sum(axis=1).astype(int).tolist(),
                "dt": params["dt"],
                "steps": int(counts.size),
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
