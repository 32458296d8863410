"""Run the exported standard sPLL network on Lava's own processes (bit-accurate, CPU).

This file is copied as ``run.py`` into the folder ``spll-hw export --to lava-standard`` writes;
it needs only numpy, lava-nc 0.10 and ``lava_compat.py`` beside it (which lets lava-nc 0.10
import on Python 3.11), not spll-hw::

    python run.py spikes.npy 1.0      # input spike times [s] (1-D .npy), duration [s]

prints JSON: ``tde_counts`` and ``cco_counts`` (spikes per sPLL), ``dt``, ``steps``. A folder
written with a clock per set of sPLLs (``clocks`` in ``params.npz``: each set at the step that
holds its refractory periods) runs each set on the input binned at its own step, one after
another, and prints each sPLL's ``dt`` and ``steps`` (:func:`count`). ::

    python run.py --check             # every input of check_inputs.npz
    python run.py --check 0 3         # only inputs 0 and 3 (check.json's order)

runs the export check's inputs (``check_inputs.npz``) on Lava and compares every sPLL's TDE and
CCO count with the one ``check.json`` records (spll-hw's numpy run of the same integers, which
Lava's bit-accurate models match exactly): prints a table, exits 0 when all are equal and 1
naming the inputs and sPLLs that are not (``check_counts.py`` beside this file compares them).
lava-nc 0.10 starts an OS process per Lava process (about 10 MB each), and a network of one set
of processes per set of decays (time-scaled and tuned layouts) has 1000-2000 of them: run.py
runs the network's independent parts one after another (:func:`split`: one per set, about 40
processes, sPLLs that share only the input), which gives the whole network's counts. Measured
on 2 cores: about 5 ms a step per part (a set of 41 processes: 1000 steps in 6 s, 5000 in
25-30 s; 272 processes at once took 82 s for 1000 steps), so an input of 1 s at 50 µs takes
about 2 minutes per set.

The network is built from ``params.npz`` with ``lava.proc.lif.process.LIF``,
``lava.proc.dense.process.Dense`` and ``lava.proc.io`` ring buffers only (and, for graded CCO
currents, ``lava.proc.graded.process.GradedVec``), and runs with
``Loihi2SimCfg(select_tag="fixed_pt")``: Lava's bit-accurate models of Loihi's neuron and
synapse. Input spikes count in the steps that spll-hw's grid rule gives (``spll_grid.py``: a
spike at ``t`` in step ``max(1, ceil(t/dt))``, one on a step's end in that step, of
``round(duration/dt)`` steps).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: Populations whose spikes run.py reads (a ring-buffer sink each).
SINKS = ("tde", "cco", "hold_")


def load_params(path: str | Path) -> dict:
    """``params.npz`` of one clock as ``{"dt", "n_spll", "lif": {pop: {...}}, "members": {pop:
    sPLLs}, "dense": {name: (source, target, weights, weight_exp, num_message_bits)}}``
    (:func:`load_clocks` reads a folder with a clock per set of sPLLs)."""
    return _clock(np.load(path), "")


def load_clocks(path: str | Path) -> list[dict]:
    """``params.npz`` as one :func:`load_params` dict per clock: the folder's one, or where
    each set of sPLLs has its own step (``clocks`` in the file, ``clock<c>.*`` its integers),
    each set's, with its step ``dt`` and its sPLLs numbered as in the whole network (``n_spll``
    the network's; the sPLLs of the other clocks hold no neurons in it)."""
    raw = np.load(path)
    if "clocks" not in raw.files:
        return [_clock(raw, "")]
    return [_clock(raw, f"clock{c}.", int(raw["n_spll"])) for c in range(int(raw["clocks"]))]


def _clock(raw, prefix: str, n_spll: int | None = None) -> dict:
    """The arrays of ``raw`` named ``prefix...`` in :func:`load_params`' form."""
    params = {"dt": float(raw[f"{prefix}dt"]), "lif": {}, "members": {}, "dense": {},
              "n_spll": int(raw["n_spll"]) if n_spll is None else n_spll}  # fmt: skip
    for key in raw.files:
        if not key.startswith(prefix) or key.count(".") < prefix.count(".") + 1:
            continue
        parts = key[len(prefix) :].split(".")
        if parts[0] == "lif":
            params["lif"].setdefault(parts[1], {})[parts[2]] = raw[key]
        elif parts[0] == "members":
            params["members"][parts[1]] = raw[key]
        elif parts[0] == "dense" and parts[2] == "weights":
            src, dst, exp, bits = (str(x) for x in raw[f"{prefix}dense.{parts[1]}.meta"])
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
    population, ring-buffer sinks by population)``, connected and ready to compile."""
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
        if int(p.get("graded", 0)):  # a graded current (sends its input every step)
            from lava.proc.graded.process import GradedVec

            lif[pop] = GradedVec(shape=(p["bias_mant"].shape[0],), vth=0)
            continue
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
        if pop.startswith(SINKS):
            sinks[pop] = Sink(shape=(len(params["members"][pop]),), buffer=n_steps)
            lif[pop].s_out.connect(sinks[pop].a_in)
    return lif, sinks


def split(params: dict) -> list[dict]:
    """The network's independent parts, as few Lava processes at once as they allow: its
    connected sets of neurons (an sPLL with its levels, refractory units and rows of the gate;
    they share only the input, so each runs as it would in the whole network), each joined to
    the first part whose Lava processes already hold it (the sPLLs of one set of decays share
    their LIF processes), else a part of its own. A vary-offset network is one part, a tuned or
    time-scaled one a part per sPLL. Each part is in ``params``' form with the sPLLs' numbers
    unchanged, in the order of their first sPLL; a set of neurons without a TDE or CCO (nothing
    to read) is left out.

    A population (LIF process) and a ``Dense`` are split between parts by their neurons (the
    gate, shared by all sPLLs, is), its weights and biases sliced; a ``Dense`` left without a
    weight in a part is not in it. Weights keep their sign (one per ``Dense``), so Lava
    truncates them as in the whole network.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    sizes = {pop: p["bias_mant"].shape[0] for pop, p in params["lif"].items()}
    start = dict(zip(sizes, np.cumsum([0, *sizes.values()])[:-1].tolist(), strict=True))
    edges = [(r + start[dst], c + start[src])
             for src, dst, w, _, _ in params["dense"].values() if src != "input"
             for r, c in [np.nonzero(w)]]  # fmt: skip
    rows, cols = (np.concatenate([e[k] for e in edges] or [np.zeros(0, int)]) for k in (0, 1))
    n = sum(sizes.values())
    graph = coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    of = {pop: label[start[pop] : start[pop] + size] for pop, size in sizes.items()}
    first = {}  # each connected set with a TDE or CCO neuron: its first sPLL
    for pop, labels in of.items():
        if pop.startswith(("tde", "cco")):
            for c, spll in zip(labels, params["members"][pop], strict=True):
                first[int(c)] = min(first.get(int(c), params["n_spll"]), int(spll))
    # Its LIF processes and Dense (named by a weight into its neurons).
    touches = {c: {pop for pop, labels in of.items() if np.any(labels == c)} for c in first}
    for name, (_, dst, w, _, _) in params["dense"].items():
        for c in np.intersect1d(of[dst][np.any(w != 0, axis=1)], list(touches)):
            touches[int(c)].add(name)
    parts: list[tuple[set, list]] = []
    for c in sorted(first, key=first.get):
        home = next((part for part in parts if touches[c] <= part[0]), None)
        if home is None:
            parts.append((set(touches[c]), [c]))
        else:
            home[1].append(c)
    return [_part(params, {pop: np.isin(labels, held) for pop, labels in of.items()})
            for _, held in parts]  # fmt: skip


def n_processes(params: dict) -> int:
    """The Lava processes :func:`build` makes of ``params``: its LIF processes and ``Dense``,
    the input's ring buffer and a sink per TDE, CCO and hold population."""
    sinks = [pop for pop in params["lif"] if pop.startswith(SINKS)]
    return len(params["lif"]) + len(params["dense"]) + 1 + len(sinks)


def _part(params: dict, keep: dict) -> dict:
    """``params`` restricted to the neurons ``keep`` (per population, bool of its size)."""
    part = {"dt": params["dt"], "n_spll": params["n_spll"], "lif": {}, "members": {},
            "dense": {}}  # fmt: skip
    for pop, p in params["lif"].items():
        if keep[pop].any():
            part["lif"][pop] = {k: v[keep[pop]] if np.ndim(v) else v for k, v in p.items()}
    splls = np.unique(np.concatenate(
        [params["members"][pop][keep[pop]] for pop in part["lif"] if pop.startswith("tde")]
    ))  # fmt: skip
    for pop, idx in params["members"].items():
        if pop in part["lif"]:
            # a population of one neuron per sPLL is split by its neurons, one of a set's
            # sPLLs' levels by the sPLLs the part holds
            per_neuron = idx.size == keep[pop].size
            part["members"][pop] = idx[keep[pop]] if per_neuron else idx[np.isin(idx, splls)]
    for name, (src, dst, w, exp, bits) in params["dense"].items():
        cols = np.ones(w.shape[1], bool) if src == "input" else keep[src]
        sliced = w[keep[dst]][:, cols]
        if sliced.any():
            part["dense"][name] = (src, dst, sliced, exp, bits)
    return part


def run(params: dict, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Run the network over the input ``counts`` per step, one independent part after
    another (:func:`split`); TDE and CCO spike rasters, each of shape ``(n_spll,
    n_steps)``."""
    parts = split(params)
    rasters = np.zeros((2, params["n_spll"], int(counts.size)), dtype=bool)
    for k, part in enumerate(parts):
        if len(parts) > 1:
            held = sorted({int(i) for pop in part["lif"] if pop.startswith("tde")
                           for i in part["members"][pop]})  # fmt: skip
            print(f"part {k + 1}/{len(parts)}: sPLLs {_ranges(held)}, "
                  f"{n_processes(part)} Lava processes",
                  file=sys.stderr)  # fmt: skip
        rasters |= run_part(part, counts)
    return rasters[0], rasters[1]


def count(clocks: list[dict], spikes: np.ndarray, duration: float) -> dict:
    """The network's spikes on the input spike times ``spikes`` [s] over ``duration`` [s],
    each clock's sPLLs (:func:`load_clocks`) run on the input binned at its own step:
    ``{"tde_counts", "cco_counts"}`` (per sPLL) with ``"dt"`` [s] and ``"steps"``, the folder's
    one or, where it has a clock per set of sPLLs, each sPLL's."""
    n = clocks[0]["n_spll"]
    tde, cco = np.zeros(n, np.int64), np.zeros(n, np.int64)
    dt, steps = np.zeros(n), np.zeros(n, np.int64)
    for c, params in enumerate(clocks):
        counts = input_counts(spikes, duration, params["dt"])
        held = np.unique(np.concatenate(
            [idx for pop, idx in params["members"].items() if pop.startswith("tde")]
        ))  # fmt: skip
        if len(clocks) > 1:
            print(f"clock {c + 1}/{len(clocks)}: sPLLs {_ranges(held.tolist())} at dt = "
                  f"{params['dt']:g} s, {counts.size} steps", file=sys.stderr)  # fmt: skip
        spikes_tde, spikes_cco = run(params, counts)
        tde += spikes_tde.sum(axis=1)
        cco += spikes_cco.sum(axis=1)
        dt[held], steps[held] = params["dt"], counts.size
    one = len(clocks) == 1
    return {
        "tde_counts": tde.tolist(),
        "cco_counts": cco.tolist(),
        "dt": clocks[0]["dt"] if one else dt.tolist(),
        "steps": int(steps[0]) if one else steps.tolist(),
    }


def _ranges(idx: list[int]) -> str:
    """``[0, 1, 2, 5]`` as ``0-2, 5``."""
    runs = np.split(np.asarray(idx), np.flatnonzero(np.diff(idx) != 1) + 1)
    return ", ".join(f"{r[0]}" if r.size == 1 else f"{r[0]}-{r[-1]}" for r in runs if r.size)


def run_part(params: dict, counts: np.ndarray) -> np.ndarray:
    """Run ``params`` (a part of :func:`split`, or a whole network) as one Lava network over
    the input ``counts`` per step; TDE and CCO spike rasters, shape ``(2, n_spll, n_steps)``
    (rows of sPLLs it does not hold are False)."""
    from lava.magma.core.run_conditions import RunSteps
    from lava.magma.core.run_configs import Loihi2SimCfg

    lif, sinks = build(params, counts)
    n, n_steps = params["n_spll"], int(counts.size)
    run_cfg = Loihi2SimCfg(select_tag="fixed_pt")
    first = next(iter(lif.values()))
    first.run(condition=RunSteps(num_steps=n_steps), run_cfg=run_cfg)
    rasters = {part: np.zeros((n, n_steps), dtype=bool) for part in ("tde", "cco")}
    try:
        fired = {pop: np.asarray(sink.data.get()) != 0 for pop, sink in sinks.items()}
    finally:
        first.stop()
    for pop, spikes in fired.items():
        if pop.startswith(("tde", "cco")):
            rasters[pop[:3]][params["members"][pop]] = spikes
    # A spike in a step its refractory unit holds the neuron is not one of the network's.
    for pop, spikes in fired.items():
        if pop.startswith("hold_"):
            rasters[pop[5:8]][params["members"][pop]] &= ~spikes
    return np.stack([rasters["tde"], rasters["cco"]])


def check(selected: list[str]) -> int:
    """``run.py --check [INPUT ...]`` (module docstring): the exit status."""
    sys.path.insert(0, str(HERE))
    import check_counts

    try:
        record = check_counts.read_check(HERE)
    except FileNotFoundError as exc:
        print(exc, file=sys.stderr)
        return 2
    inputs = check_counts.read_inputs(HERE, record)
    try:
        chosen = [int(i) for i in selected] or list(range(len(inputs)))
    except ValueError:
        chosen = [-1]
    if any(not 0 <= i < len(inputs) for i in chosen):
        print(f"--check takes input numbers 0..{len(inputs) - 1} (check.json's order), got "
              f"{' '.join(selected)}", file=sys.stderr)  # fmt: skip
        return 2
    clocks = load_clocks(HERE / "params.npz")
    counts = []
    for i in chosen:
        label, spikes, duration = inputs[i]
        print(f"input {i}: {label} ({duration:g} s)", file=sys.stderr)
        out = count(clocks, spikes, duration)
        counts.append((np.array(out["tde_counts"]), np.array(out["cco_counts"])))
    record = record | {"inputs": [record["inputs"][i] for i in chosen]}
    return check_counts.report("lava-nc", record, counts)


def _arguments() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="run.py",
        description="Run this exported sPLL network on lava-nc (Lava's bit-accurate models of "
        "Loihi's LIF and Dense); prints JSON with tde_counts and cco_counts per sPLL.",
    )
    parser.add_argument("spikes", nargs="?", help="input spike times [s], a 1-D .npy file")
    parser.add_argument("duration", nargs="?", help="duration of the input [s]")
    parser.add_argument(
        "--check", nargs="*", metavar="INPUT",
        help="run the export check's inputs (check_inputs.npz; all, or these numbers of "
        "check.json's order) and compare every count with check.json: exit 0 when all are "
        "equal, 1 naming those that are not",
    )  # fmt: skip
    return parser


def main(argv: list[str]) -> int:
    parser = _arguments()
    args = parser.parse_args(argv)
    if args.check is not None:
        if args.spikes is not None:
            parser.error("--check takes input numbers, not a spike file and a duration")
        return check(args.check)
    if args.duration is None:
        parser.error("give a spike file and a duration [s], or --check")
    try:
        duration = float(args.duration)
    except ValueError:
        duration = math.nan
    if not (math.isfinite(duration) and duration > 0):
        parser.error(f"duration must be a finite time > 0 s, got {args.duration}")
    try:
        spikes = np.load(args.spikes)
    except (OSError, ValueError) as exc:
        parser.error(f"cannot read the spike times {args.spikes}: {exc}")
    print(json.dumps(count(load_clocks(HERE / "params.npz"), spikes, duration)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
