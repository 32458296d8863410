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
    python run.py --check --jobs 2    # two parts at once (a worker process each)

runs the export check's inputs (``check_inputs.npz``) on Lava and compares every sPLL's TDE and
CCO count with the one ``check.json`` records (spll-hw's numpy run of the same integers, which
Lava's bit-accurate models match exactly): prints a table, exits 0 when all are equal and 1
naming the inputs and sPLLs that are not (``check_counts.py`` beside this file compares them).
Inputs of one length run together: a part runs as one Lava network with a copy of its neurons
per input (:func:`batched`, up to :data:`BATCH_NEURONS` neurons), so ten inputs cost little
more than one where Lava's processes, not its neurons, take the time.
lava-nc 0.10 starts an OS process per Lava process (about 10 MB each), and a network of one set
of processes per set of decays (time-scaled and tuned layouts) has 1000-2000 of them: run.py
runs the network's independent parts (:func:`split`: one per set, sPLLs that share only the
input) one after another, or ``--jobs N`` at a time, a forked worker each (the whole network's
counts for every N; on 2 cores two at once took 0.88-1.16 times as long as one after
another), and lays each part out on as few Lava processes as lava-nc's own LIF and Dense allow
(:func:`layout`: a tuned network's part is 25 instead of 41). The folder's README estimates the
time for 1 s of input (:func:`seconds`: per Lava process to start, and per Lava process and per
neuron a step); after each part run.py prints what is left, the same model scaled by the parts
run so far on this machine.

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
import multiprocessing
import sys
import time
import traceback
from multiprocessing.connection import wait
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

HERE = Path(__file__).resolve().parent
#: Populations whose spikes run.py reads (a ring-buffer sink each).
SINKS = ("tde", "cco", "hold_")
#: Most neurons :func:`layout` puts in one LIF process of several populations: a larger one
#: makes its ``Dense`` matrices larger than those they replace (measured slower on 2 cores).
MERGED_NEURONS = 64
#: lava-nc 0.10's CPU time for this file, measured from outside on a 2-core AMD EPYC machine
#: with nothing else running (2026-12-07, docs/notes/2026-12-06-lava-runtime.md; another
#: 2-core machine ran the same steps twice as fast): Python, numpy and lava-nc's import and the
#: split, once [s]; a part's compile and start, per Lava process of the part [s]; a step of a
#: part, per Lava process [s] and per neuron of its LIF processes [s]; how many times faster
#: the parts' starts go with two parts at once (``--jobs 2``; their steps took as long as one
#: after another). :func:`seconds` is the READMEs' model of it, :func:`run_all`'s estimate of
#: what is left is the same model scaled by the parts run so far.
START_S = 1.0
PROCESS_START_S = 0.047
PROCESS_STEP_S = 0.34e-3
NEURON_STEP_S = 8.8e-6
PARALLEL_START = 1.5
#: Most neurons of one Lava network that runs several inputs of one length at once, a copy of
#: a part per input (:func:`batched`): a copy adds its neurons' cost to each step but no Lava
#: process, whose cost per step is that of about 40 neurons. Measured on 6 check inputs
#: (2026-12-07, docs/notes/2026-12-07-lava-inputs-at-once.md): 4.3-4.6 times faster for
#: parts of 42-160 neurons, the same time for one of 2000 (whose neurons take the time).
BATCH_NEURONS = 4096


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
    import spll_grid  # beside this file in the export folder (on sys.path from here on)

    return spll_grid.arrival_counts(spikes, spll_grid.n_steps(duration, dt), dt)


def layout(params: dict) -> tuple[dict, list]:
    """How :func:`build` lays ``params`` out on as few of Lava's own processes as they allow:
    the LIF populations of one ``du``, ``dv`` and ``vth`` (and bias of each neuron) as one LIF
    process of at most :data:`MERGED_NEURONS` neurons (a population of more, or a graded
    current's ``GradedVec``, as one of its own), and the ``Dense`` between the
    same two of them with the same ``weight_exp``, ``num_message_bits`` and sign as one
    ``Dense``, where no two of those put a weight on the same synapse (for a negative
    ``weight_exp``, into the same neuron): each of its sums is then the one the ``Dense``
    apart made, and Lava clips and truncates its weights as theirs (by its sign). Returns
    ``(processes, dense)``: ``{name: {"pops": {pop: slice of its neurons}, "lif": {du, dv,
    vth, bias_mant, bias_exp[, graded]}}}`` (named by its first population) and ``[(source,
    target, weights, weight_exp, num_message_bits)]`` between them (``source`` ``"input"``:
    the input's ring buffer), weights of shape ``(target size, source size)``."""
    groups: dict[tuple, list[str]] = {}
    for pop, p in params["lif"].items():
        key = ("graded", pop) if int(p.get("graded", 0)) else (int(p["du"]), int(p["dv"]),
                                                               int(p["vth"]))  # fmt: skip
        n = p["bias_mant"].shape[0]
        while sum(params["lif"][q]["bias_mant"].shape[0] for q in groups.get(key, [])) + n > (
            MERGED_NEURONS if key in groups else n
        ):
            key = (*key, "more")
        groups.setdefault(key, []).append(pop)
    processes, home = {}, {"input": ("input", slice(0, 1))}
    for pops in groups.values():
        sizes = np.cumsum([0] + [params["lif"][pop]["bias_mant"].shape[0] for pop in pops])
        lif = dict(params["lif"][pops[0]])
        for key in ("bias_mant", "bias_exp"):
            lif[key] = np.concatenate([params["lif"][pop][key] for pop in pops])
        ends = zip(pops, sizes[:-1], sizes[1:], strict=True)
        where = {pop: slice(int(a), int(b)) for pop, a, b in ends}
        processes[pops[0]] = {"pops": where, "lif": lif}
        home |= {pop: (pops[0], where[pop]) for pop in pops}
    size = {name: int(proc["lif"]["bias_mant"].shape[0]) for name, proc in processes.items()}
    size["input"] = 1
    dense: list[list] = []  # [source, target, weights, exp, bits, sign]
    for src, dst, w, exp, bits in params["dense"].values():
        (a, cols), (b, rows) = home[src], home[dst]
        full = np.zeros((size[b], size[a]), dtype=np.int64)
        full[rows, cols] = w
        sign = int(np.sign(w[w != 0][0]))
        for d in dense:
            busy = d[2] != 0 if exp >= 0 else np.any(d[2] != 0, axis=1, keepdims=True)
            if d[:2] + d[3:] == [a, b, exp, bits, sign] and not np.any(busy & (full != 0)):
                d[2] = d[2] + full
                break
        else:
            dense.append([a, b, full, exp, bits, sign])
    return processes, [tuple(d[:5]) for d in dense]


def batched(processes: dict, dense: list, copies: int) -> tuple[dict, list]:
    """:func:`layout`'s ``(processes, dense)`` with ``copies`` copies of the network side by
    side in the same Lava processes, each fed by its own input: every LIF process holds its
    neurons ``copies`` times over (copy ``c`` at ``c`` times its size on), every ``Dense`` the
    block-diagonal ``kron(eye(copies), weights)`` (from the input, one column per copy), so
    each copy's sums, clipping and truncation are those of the network alone."""
    if copies == 1:
        return processes, dense
    out = {}
    for name, proc in processes.items():
        lif = {k: np.tile(v, copies) if np.ndim(v) else v for k, v in proc["lif"].items()}
        out[name] = {"pops": proc["pops"], "lif": lif}
    eye = np.eye(copies, dtype=np.int64)
    return out, [(src, dst, np.kron(eye, w), exp, bits) for src, dst, w, exp, bits in dense]


def build(params: dict, counts: np.ndarray) -> tuple[dict, dict, dict]:
    """The network's Lava processes (:func:`layout`), a copy per row of the input ``counts``
    (spikes per step, shape ``(copies, n_steps)``; :func:`batched`) fed by that row:
    ``(LIF processes by name, ring-buffer sinks by name, layout's processes)``, connected and
    ready to compile; a sink records every neuron of a process that holds a TDE, CCO or hold
    population, every copy's."""
    sys.path.insert(0, str(HERE))
    import lava_compat  # beside this file in the export folder (on sys.path from here on)

    lava_compat.install()
    from lava.proc.dense.process import Dense
    from lava.proc.io.sink import RingBuffer as Sink
    from lava.proc.io.source import RingBuffer as Source
    from lava.proc.lif.process import LIF

    copies, n_steps = counts.shape
    source = Source(data=np.asarray(counts, dtype=np.int64))
    processes, dense = batched(*layout(params), copies)
    lif = {"input": source}
    for name, proc in processes.items():
        p = proc["lif"]
        if int(p.get("graded", 0)):  # a graded current (sends its input every step)
            from lava.proc.graded.process import GradedVec

            lif[name] = GradedVec(shape=(p["bias_mant"].shape[0],), vth=0)
            continue
        lif[name] = LIF(
            shape=(p["bias_mant"].shape[0],), du=int(p["du"]), dv=int(p["dv"]),
            vth=int(p["vth"]), bias_mant=p["bias_mant"].astype(np.int64),
            bias_exp=p["bias_exp"].astype(np.int64), name=name,
        )  # fmt: skip
    for src, dst, weights, exp, bits in dense:
        synapses = Dense(weights=weights, weight_exp=exp, num_message_bits=bits)
        lif[src].s_out.connect(synapses.s_in)
        synapses.a_out.connect(lif[dst].a_in)
    del lif["input"]
    sinks = {}
    for name, proc in processes.items():
        if any(pop.startswith(SINKS) for pop in proc["pops"]):
            sinks[name] = Sink(shape=(proc["lif"]["bias_mant"].shape[0],), buffer=n_steps)
            lif[name].s_out.connect(sinks[name].a_in)
    return lif, sinks, processes


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
    """The Lava processes :func:`build` makes of ``params`` (:func:`layout`): its LIF
    processes and ``Dense``, the input's ring buffer and a sink per LIF process that holds a
    TDE, CCO or hold population."""
    processes, dense = layout(params)
    sinks = [p for p in processes.values() if any(pop.startswith(SINKS) for pop in p["pops"])]
    return len(processes) + len(dense) + 1 + len(sinks)


def n_neurons(params: dict) -> int:
    """The neurons of ``params``' LIF populations (and graded currents): those of the LIF
    processes :func:`build` makes of it, whichever :func:`layout` merges."""
    return sum(int(p["bias_mant"].shape[0]) for p in params["lif"].values())


def part_seconds(processes: int, neurons: int, steps: int) -> tuple[float, float]:
    """The model's seconds (:data:`START_S`) to compile and start a part of ``processes`` Lava
    processes and ``neurons`` neurons, and to run its ``steps`` steps, one part alone."""
    return (processes * PROCESS_START_S,
            steps * (processes * PROCESS_STEP_S + neurons * NEURON_STEP_S))  # fmt: skip


def seconds(costs: list[tuple[float, float]], jobs: int = 1) -> float:
    """What this file takes [s] for parts of these :func:`part_seconds` (start, steps),
    ``jobs`` at a time: a start, the parts' starts (:data:`PARALLEL_START` times faster where
    two or more run at once) and their steps."""
    start, steps = (sum(c[k] for c in costs) for k in (0, 1))
    return START_S + start / (PARALLEL_START if min(jobs, len(costs)) > 1 else 1.0) + steps


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


def run(params: dict, counts: np.ndarray, jobs: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Run the network over the input ``counts`` per step in its independent parts
    (:func:`split`), ``jobs`` at a time; TDE and CCO spike rasters, each of shape ``(n_spll,
    n_steps)``."""
    (rasters,) = run_all([(params, counts)], jobs)
    return rasters[0], rasters[1]


def run_all(networks: list[tuple[dict, np.ndarray]], jobs: int = 1) -> list[np.ndarray]:
    """Run each ``(params, counts)`` of ``networks`` (a network in :func:`load_params`' form
    and its input spikes per step) in its independent parts (:func:`split`), the parts of all
    of them ``jobs`` at a time (a worker process each, which runs its part's Lava processes;
    ``jobs=1`` runs them one after another in this process); each network's TDE and CCO spike
    rasters, shape ``(2, n_spll, n_steps)``. Networks of the same ``params`` object and input
    length run a part as one Lava network with a copy per input, up to
    :data:`BATCH_NEURONS` neurons (:func:`batched`). The counts are the same for every
    ``jobs`` and batch: each part's copy runs alone on its own inputs either way."""
    groups: dict[tuple, list[int]] = {}
    for n, (params, counts) in enumerate(networks):
        groups.setdefault((id(params), int(counts.size)), []).append(n)
    tasks = []  # (the networks it runs, part, their counts stacked)
    for members in groups.values():
        for part in split(networks[members[0]][0]):
            size = max(1, BATCH_NEURONS // max(1, n_neurons(part)))
            for k in range(0, len(members), size):
                batch = members[k : k + size]
                tasks.append((batch, part, np.stack([networks[n][1] for n in batch])))
    out = [np.zeros((2, p["n_spll"], int(c.size)), dtype=bool) for p, c in networks]
    jobs = max(1, min(jobs, len(tasks)))
    processes = [n_processes(part) for _, part, _ in tasks]
    costs = [part_seconds(p, n_neurons(part) * counts.shape[0], counts.shape[1])
             for p, (_, part, counts) in zip(processes, tasks, strict=True)]  # fmt: skip
    copies = max(counts.shape[0] for _, _, counts in tasks)
    print(f"{len(tasks)} parts of {sum(processes)} Lava processes, {jobs} at a time"
          + (f", up to {copies} inputs at once" if copies > 1 else "")
          + f"; the model's estimate: {seconds(costs, jobs) / 60:.3g} min",
          file=sys.stderr)  # fmt: skip
    began, done = time.perf_counter(), []

    def add(k: int, rasters: np.ndarray) -> None:
        for n, copy in zip(tasks[k][0], rasters, strict=True):
            out[n] |= copy
        done.append(k)
        _left(time.perf_counter() - began, costs, done, jobs)

    if jobs == 1:
        for k, (_, part, counts) in enumerate(tasks):
            _say(k, tasks)
            add(k, run_part(part, counts))
        return out
    for k, rasters in _parallel(tasks, jobs):
        _say(k, tasks)
        add(k, rasters)
    return out


def _left(elapsed: float, costs: list[tuple[float, float]], done: list[int], jobs: int) -> None:
    """Say on stderr how long the parts not in ``done`` will take: the model's time for them
    (:func:`seconds`) scaled by what the parts ``done`` took on this machine (``elapsed`` [s])
    against the model's time for those."""
    finished = set(done)
    rest = [c for k, c in enumerate(costs) if k not in finished]
    if len(costs) < 2 or not rest:
        return
    speed = elapsed / (seconds([costs[k] for k in done], jobs) - START_S)
    left = speed * (seconds(rest, jobs) - START_S)
    print(f"  {elapsed:.0f} s so far, about {left / 60:.3g} min left (this machine: "
          f"{speed:.2g} times the model's estimate)", file=sys.stderr)  # fmt: skip


def _parallel(tasks: list, jobs: int):
    """Run each part of ``tasks`` (``(networks, part, counts)``) in a forked worker process of
    its own, ``jobs`` at a time (Lava's runtime forks its processes, which a worker that is
    not a daemon may; forking passes the part without pickling ``run_part``, so run.py also
    runs as ``runpy``'s ``__main__``); yields ``(k, rasters)`` as parts end."""
    fork = multiprocessing.get_context("fork")
    pending, running = list(enumerate(tasks)), {}
    while pending or running:
        while pending and len(running) < jobs:
            k, (_, part, counts) = pending.pop(0)
            receive, send = fork.Pipe(duplex=False)
            worker = fork.Process(target=_work, args=(send, part, counts))
            worker.start()
            send.close()
            running[k] = (worker, receive)
        ready = wait([receive for _, receive in running.values()])
        for k in [k for k, (_, receive) in running.items() if receive in ready]:
            worker, receive = running.pop(k)
            try:
                ok, result = receive.recv()
            except EOFError:
                ok, result = False, f"its worker ended with exit status {worker.exitcode}"
            worker.join()
            if not ok:
                for other, _ in running.values():
                    other.kill()
                raise RuntimeError(f"part {k + 1}/{len(tasks)} failed: {result}")
            yield k, result


def _work(send, part: dict, counts: np.ndarray) -> None:
    """A worker of :func:`_parallel`: sends ``(True, run_part(part, counts))``, or ``(False,
    the traceback)``."""
    try:
        send.send((True, run_part(part, counts)))
    except Exception:
        send.send((False, traceback.format_exc()))


def _say(k: int, tasks: list) -> None:
    """Name part ``k`` of ``tasks`` (``(networks, part, counts)``) on stderr."""
    if len(tasks) > 1:
        part, copies = tasks[k][1], tasks[k][2].shape[0]
        held = sorted({int(i) for pop in part["lif"] if pop.startswith("tde")
                       for i in part["members"][pop]})  # fmt: skip
        inputs = f", {copies} inputs at once" if copies > 1 else ""
        print(f"part {k + 1}/{len(tasks)}: sPLLs {_ranges(held)}, {n_processes(part)} Lava "
              f"processes{inputs}", file=sys.stderr)  # fmt: skip


def count(clocks: list[dict], spikes: np.ndarray, duration: float, jobs: int = 1) -> dict:
    """The network's spikes on the input spike times ``spikes`` [s] over ``duration`` [s],
    each clock's sPLLs (:func:`load_clocks`) run on the input binned at its own step, the
    parts of all clocks ``jobs`` at a time (:func:`run_all`): ``{"tde_counts",
    "cco_counts"}`` (per sPLL) with ``"dt"`` [s] and ``"steps"``, the folder's one or, where
    it has a clock per set of sPLLs, each sPLL's."""
    return count_all(clocks, [(spikes, duration)], jobs)[0]


def count_all(clocks: list[dict], inputs: list[tuple[np.ndarray, float]], jobs: int = 1):
    """:func:`count` of each ``(spikes [s], duration [s])`` of ``inputs``, the parts of all
    inputs and clocks ``jobs`` at a time; a list of :func:`count`'s dicts."""
    n = clocks[0]["n_spll"]
    networks = [(params, input_counts(spikes, duration, params["dt"]))
                for spikes, duration in inputs for params in clocks]  # fmt: skip
    if len(clocks) > 1:
        for c, params in enumerate(clocks):
            print(f"clock {c + 1}/{len(clocks)}: sPLLs {_ranges(_held(params).tolist())} at "
                  f"dt = {params['dt']:g} s, {networks[c][1].size} steps",
                  file=sys.stderr)  # fmt: skip
    rasters = run_all(networks, jobs)
    out = []
    for i in range(len(inputs)):
        tde, cco = np.zeros(n, np.int64), np.zeros(n, np.int64)
        dt, steps = np.zeros(n), np.zeros(n, np.int64)
        for c, params in enumerate(clocks):
            k = i * len(clocks) + c
            tde += rasters[k][0].sum(axis=1)
            cco += rasters[k][1].sum(axis=1)
            held = _held(params)
            dt[held], steps[held] = params["dt"], networks[k][1].size
        one = len(clocks) == 1
        out.append({
            "tde_counts": tde.tolist(),
            "cco_counts": cco.tolist(),
            "dt": clocks[0]["dt"] if one else dt.tolist(),
            "steps": int(steps[0]) if one else steps.tolist(),
        })  # fmt: skip
    return out


def _held(params: dict) -> np.ndarray:
    """The sPLLs that ``params`` (one clock) holds, sorted."""
    return np.unique(np.concatenate(
        [idx for pop, idx in params["members"].items() if pop.startswith("tde")]
    ))  # fmt: skip


def _ranges(idx: list[int]) -> str:
    """``[0, 1, 2, 5]`` as ``0-2, 5``."""
    runs = np.split(np.asarray(idx), np.flatnonzero(np.diff(idx) != 1) + 1)
    return ", ".join(f"{r[0]}" if r.size == 1 else f"{r[0]}-{r[-1]}" for r in runs if r.size)


def run_part(params: dict, counts: np.ndarray) -> np.ndarray:
    """Run ``params`` (a part of :func:`split`, or a whole network) as one Lava network over
    the inputs ``counts`` (spikes per step, shape ``(copies, n_steps)``: a copy of the part per
    input, :func:`batched`); TDE and CCO spike rasters, shape ``(copies, 2, n_spll, n_steps)``
    (rows of sPLLs it does not hold are False)."""
    from lava.magma.core.run_conditions import RunSteps
    from lava.magma.core.run_configs import Loihi2SimCfg

    lif, sinks, processes = build(params, counts)
    (copies, n_steps), n = counts.shape, params["n_spll"]
    run_cfg = Loihi2SimCfg(select_tag="fixed_pt")
    first = next(iter(lif.values()))
    first.run(condition=RunSteps(num_steps=n_steps), run_cfg=run_cfg)
    try:  # each sink's record as (copies, the process's neurons, n_steps)
        recorded = {name: (np.asarray(sink.data.get()) != 0).reshape(copies, -1, n_steps)
                    for name, sink in sinks.items()}  # fmt: skip
    finally:
        first.stop()
    rasters = np.zeros((copies, 2, n, n_steps), dtype=bool)
    fired = {pop: recorded[name][:, where] for name in recorded
             for pop, where in processes[name]["pops"].items()}  # fmt: skip
    rows = ("tde", "cco")  # the rasters' second axis
    for pop, spikes in fired.items():
        if pop.startswith(rows):
            rasters[:, rows.index(pop[:3]), params["members"][pop]] = spikes
    # A spike in a step its refractory unit holds the neuron is not one of the network's.
    for pop, spikes in fired.items():
        if pop.startswith("hold_"):
            rasters[:, rows.index(pop[5:8]), params["members"][pop]] &= ~spikes
    return rasters


def check(selected: list[str], jobs: int = 1) -> int:
    """``run.py --check [INPUT ...]`` (module docstring), every input's parts ``jobs`` at a
    time: the exit status."""
    sys.path.insert(0, str(HERE))
    import check_counts  # beside this file in the export folder (on sys.path from here on)

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
    for i in chosen:
        print(f"input {i}: {inputs[i][0]} ({inputs[i][2]:g} s)", file=sys.stderr)
    outs = count_all(clocks, [inputs[i][1:] for i in chosen], jobs)
    counts = [(np.array(out["tde_counts"]), np.array(out["cco_counts"])) for out in outs]
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
    parser.add_argument(
        "--jobs", type=int, default=1, metavar="N",
        help="independent parts run at once, a worker process each (default 1: one after "
        "another). More overlap the parts' compile and start and take N times the memory; on "
        "2 cores two at once took from 0.88 to 1.16 times as long as one after another. The "
        "counts are the same for every N",
    )  # fmt: skip
    return parser


def main(argv: list[str]) -> int:
    parser = _arguments()
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs takes a number of parts >= 1, got {args.jobs}")
    if args.check is not None:
        if args.spikes is not None:
            parser.error("--check takes input numbers, not a spike file and a duration")
        return check(args.check, args.jobs)
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
    print(json.dumps(count(load_clocks(HERE / "params.npz"), spikes, duration, args.jobs)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
