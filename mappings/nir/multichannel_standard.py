"""A multichannel network and its spiking readout for clocked NIR consumers: ``spll-hw export
--network MULTICHANNEL --to nir-standard [--readout FILE --threshold THETA] [--data DIR]``.

The folder::

    channels/G-FIRST[-LAST]/   one nir-standard export per channel group (its network.nir, step,
                               check.json on its own channels' encoded signals, loaders):
                               :mod:`spll_hw.exporters.multichannel`; a consumer runs it on the
                               group's channels side by side (a batch)
    readout/                   the readout as a graph of standard nodes (:mod:`.readout_graph`)
                               at the readout's step, its arrays (readout.npz), decide.py (the
                               first decision spike, ties and the fallback), load_consumer.py
    multichannel.json          the groups, their steps, the feature order, the readout's step
    check_inputs.npz           encoded inputs of every channel of the check's recordings
    decisions.json             spll-hw's decisions on them: the exported graphs run by spll-hw's
                               executor (what a consumer must reproduce) and golden's
    cost.json                  cores, dynamic power and energy per decision of it all on a
                               chip, from those runs (:mod:`.multichannel_cost`)
    run_multichannel.py        runs it all in Norse or snnTorch and compares (numpy, nir, torch)

**One clock for the readout.** Each group keeps the step its own ladder chose; the readout runs at
the least common multiple of the groups' steps (100 µs for the ladder's steps), and each group's
TDE spikes are summed over the readout's step (a spike in the group's step ``k`` counts in the
readout's step ``ceil(k / ratio)``: the same grid rule, coarser).

**The decisions check** runs where a BioTac folder is at hand (``--data``) and a readout is
given: the first :data:`DECISION_DURATION` s of each of the check's recordings
(:data:`~spll_hw.exporters.multichannel.CHECK_RECORDINGS`, training recordings), every channel
encoded as the readout sees it, through every group's graph and the readout graph in spll-hw's
executor (:mod:`.executor`, the consumers' rules in float64), against the golden engine's
TDE spikes through the readout's exact decision rule
(:func:`spll_hw.multichannel.decisions.engine_decisions`). ``decisions.json`` holds both; a
consumer's run (``run_multichannel.py``) is judged against the executor's.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mappings.folder import ExportFolder
from spll_hw.exporters import get
from spll_hw.exporters.checked_folder import ExportOptions
from spll_hw.exporters.multichannel import (
    CHECK_RECORDINGS,
    MANIFEST,
    GroupsExport,
    export_all_groups,
)
from spll_hw.model.grid import n_steps
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.decisions import engine_decisions
from spll_hw.multichannel.readout import START, Readout, StagedReadout, causal_trains, tde_spikes
from spll_hw.multichannel.readout_file import SavedReadout
from spll_hw.neuron_graph import NeuronGraph

from . import readout_graph, standalone_decide
from .consumers import support
from .executor import chunks_nir, input_steps, neuron_nodes
from .files import GRAPH_FILE, LOADER_FILE, read_graph, write_graph
from .multichannel_cost import COST_FILE, PartRuns, decision_costs
from .multichannel_cost import markdown as cost_markdown
from .neuron_graph import nir_graph
from .neuron_graph import readout_graph as readout_neuron_graph
from .standard import TARGET

#: Length [s] of the decisions check's runs: the longest window of the readout's curves.
DECISION_DURATION = 4.0
#: Folders and files of the export (module docstring).
READOUT_DIR = "readout"
DECISIONS = "decisions.json"
INPUTS = "check_inputs.npz"
RUNNER = "run_multichannel.py"
#: The readout's arrays and its decision rule beside its graph.
READOUT_ARRAYS = standalone_decide.READOUT_FILE
DECIDE_FILE = "decide.py"
#: How the readout's inputs are made from a recording (``multichannel.json``).
ENCODING = (
    "each channel divided by its level, its mean so far subtracted at every row (causal), then "
    "encoded by its group's encoder of multichannel.toml with center = false"
)
#: Coarsest readout step [s]: the groups' steps must have a common multiple no longer.
LONGEST_READOUT_STEP = 1e-3


def export_multichannel_standard(
    config: MultichannelConfig,
    out: str | Path,
    saved: SavedReadout | None = None,
    threshold: float = math.inf,
    *,
    data: str | Path | None = None,
    options: ExportOptions | None = None,
    duration: float = DECISION_DURATION,
) -> list[Path]:
    """Write the folder ``out`` (module docstring), the decisions check's runs ``duration`` [s]
    long; returns its files. ``ValueError`` (or
    :class:`~spll_hw.exporters.checked_folder.CheckFailed`) naming the group, the readout or
    the step where the export cannot be written; nothing is written then."""
    options = options or ExportOptions()
    levels = None
    if saved is not None:
        saved.check_network(config.channels, config.n_spll, f"multichannel network {config.source}")
        if not threshold > 0:
            raise ValueError(f"readout threshold must be > 0 (score x s), got {threshold!r}")
        levels = dict(zip(saved.channels, map(float, saved.levels), strict=True))
    with ExportFolder(out) as folder:
        stage = folder.stage()
        done = export_all_groups(get(TARGET), TARGET, config, stage, options, data, levels,
                                 duration)  # fmt: skip
        folder.files += [folder.path / f for f in done.files]
        dt = readout_step(done.steps)
        manifest = done.manifest(config, TARGET)
        manifest["readout"] = None if saved is None else {
            "folder": READOUT_DIR, "dt": dt, "levels": levels, "encoding": ENCODING,
        }  # fmt: skip
        folder.json(MANIFEST, manifest)
        records, cost = [], None
        if saved is not None:
            _write_readout(folder, saved, threshold, dt)
            if done.samples is not None:
                records, cost = _write_decisions(folder, stage, config, saved, threshold, done,
                                                 manifest, duration)  # fmt: skip
        folder.text("README.md", _readme(config, done, dt, saved, threshold, records, cost))
    return folder.files


def readout_step(steps: Sequence[float]) -> float:
    """The readout's step [s]: the least common multiple of the groups' ``steps`` [s] (in whole
    nanoseconds); ``ValueError`` where it is longer than :data:`LONGEST_READOUT_STEP`."""
    ns = [round(s * 1e9) for s in steps]
    if any(n <= 0 or abs(n - s * 1e9) > 1e-3 for n, s in zip(ns, steps, strict=True)):
        raise ValueError(f"group steps {list(steps)} s are not whole nanoseconds")
    dt = math.lcm(*ns) * 1e-9
    if dt > LONGEST_READOUT_STEP:
        raise ValueError(
            f"the groups' steps {', '.join(f'{s:g}' for s in steps)} s have no common multiple "
            f"up to {LONGEST_READOUT_STEP:g} s for the readout's clock; export with one --dt"
        )
    return dt


def _write_readout(folder: ExportFolder, saved: SavedReadout, threshold: float, dt: float) -> None:
    """The readout's folder: its graph, ``standard.json``, its arrays and the loader and
    decision rule a consumer runs it with."""
    graph = readout_graph.to_readout_nir(saved.readout, threshold, dt, START)
    write_graph(folder.file(f"{READOUT_DIR}/{GRAPH_FILE}"), graph)
    folder.json(f"{READOUT_DIR}/standard.json", {
        "format": graph.metadata["format"], "dt": dt, "consumers": support(dt),
        "classes": list(saved.readout.class_names), "threshold": threshold,
        "not_before": START,
    })  # fmt: skip
    readout_graph.write_readout(folder.file(f"{READOUT_DIR}/{READOUT_ARRAYS}"), saved.readout,
                                threshold, dt, START)  # fmt: skip
    folder.copy(f"{READOUT_DIR}/{LOADER_FILE}", Path(__file__).with_name("loader.py"))
    folder.copy(f"{READOUT_DIR}/{DECIDE_FILE}", Path(__file__).with_name("standalone_decide.py"))


def folder_readout(folder: str | Path) -> tuple[SavedReadout, float]:
    """The readout an export folder ``folder`` holds (its ``readout.npz`` and the channels'
    levels of ``multichannel.json``) and its threshold [score x s]."""
    folder = Path(folder)
    manifest = json.loads((folder / MANIFEST).read_text())
    if manifest.get("readout") is None:
        raise ValueError(f"{folder}: exported without a readout")
    r = standalone_decide.load_readout(folder / READOUT_DIR / READOUT_ARRAYS)
    names = tuple(r["class_names"])
    stages = [Readout(w, b, names) for w, b in zip(r["weights"], r["bias"], strict=True)]
    starts = tuple(map(float, r["starts"]))
    readout = stages[0] if len(stages) == 1 else StagedReadout(tuple(stages), starts)
    levels = manifest["readout"]["levels"]
    channels = tuple(manifest["channels"])
    return SavedReadout(readout, channels, np.array([levels[c] for c in channels])), r["threshold"]


def channel_counts(
    graph,
    dt: float,
    trains: Sequence[np.ndarray],
    n_tde: int,
    duration: float,
    dt_out: float,
    spike_counts: dict | None = None,
) -> np.ndarray:
    """The TDE spike counts of ``graph`` (a group's standard graph at step ``dt`` [s]) run on
    each of ``trains`` (input spike times [s]) side by side for ``duration`` [s], summed over
    steps of ``dt_out`` [s] (a multiple of ``dt``): shape ``(n_steps(duration, dt_out),
    len(trains), n_tde)``; ``spike_counts`` as :func:`~.executor.chunks_nir`'s."""
    ratio = round(dt_out / dt)
    inputs = np.stack([input_steps(t, duration, dt) for t in trains], axis=1)[:, :, None]
    out = np.zeros((n_steps(duration, dt_out), len(trains), n_tde), np.float32)  # exact counts
    first = 0
    for spikes in chunks_nir(graph, inputs, dt, spike_counts):
        steps = np.arange(first, first + spikes.shape[0])
        np.add.at(out, steps // ratio, spikes[:, :, :n_tde])
        first += spikes.shape[0]
    return out


def executor_decisions(
    stage: Path,
    config: MultichannelConfig,
    manifest: dict,
    trains: dict,
    n: int,
    duration: float,
    costed: list[PartRuns] | None = None,
) -> tuple[list[tuple[int, int, bool]], np.ndarray]:
    """The exported graphs in ``stage`` run by spll-hw's executor on ``n`` recordings
    (``trains[channel][r]``: input spike times [s]) for ``duration`` [s]: every recording's
    ``(label, step, fired)`` and the readout's input, the TDE counts per readout step in
    feature order, shape ``(steps, n, d)``. ``costed``, where given, receives every group's
    runs and the readout's, every neuron counted (:mod:`.multichannel_cost`)."""
    dt = manifest["readout"]["dt"]
    parts = []
    for group, g in zip(config.groups, manifest["groups"], strict=True):
        graph = read_graph(stage / g["folder"] / GRAPH_FILE)
        batch = [t for channel in group.channels for t in trains[channel]]  # channel-major
        counts = None if costed is None else {}
        c = channel_counts(graph, g["dt"], batch, g["n_spll"], duration, dt, counts)
        if costed is not None:
            inputs = [input_steps(t, duration, g["dt"]).sum() for t in batch]
            costed.append(_runs(g["folder"], nir_graph(graph), len(group.channels), counts,
                                inputs, graph))  # fmt: skip
        c = c.reshape(c.shape[0], len(group.channels), n, -1).transpose(0, 2, 1, 3)
        parts.append(c.reshape(c.shape[0], n, -1))
    tde = np.concatenate(parts, axis=2)
    r = standalone_decide.load_readout(stage / READOUT_DIR / READOUT_ARRAYS)
    rows = r["weights"].shape[0] * r["weights"].shape[1]  # the decision rows, S k
    graph = read_graph(stage / READOUT_DIR / GRAPH_FILE)
    counts = None if costed is None else {}
    out = np.concatenate([y[:, :, :rows] > 0 for y in chunks_nir(graph, tde, dt, counts)])
    if costed is not None:
        inputs = tde.sum(axis=0)  # (n, d): each TDE's spikes into the readout
        costed.append(_runs(READOUT_DIR, readout_neuron_graph(graph), 1, counts, inputs, graph))
    keys = standalone_decide.DECIDE_KEYS
    return standalone_decide.decide(out, tde, **{k: r[k] for k in keys}), tde


def _runs(name: str, costed: NeuronGraph, copies: int, counts: dict, inputs, graph) -> PartRuns:
    """:class:`~.multichannel_cost.PartRuns` of the executor's ``counts`` of NIR ``graph``
    (per neuron node, shape ``(runs, size)``), in the neuron order of ``costed``."""
    spikes = np.concatenate([counts[node] for node in neuron_nodes(graph)], axis=1)
    inputs = np.asarray(inputs, np.int64).reshape(spikes.shape[0], -1)  # (runs, K)
    return PartRuns(name, costed, copies, spikes.astype(np.int64), inputs)


def golden_decisions(samples, config, saved: SavedReadout, threshold: float, levels: dict,
                     duration: float):  # fmt: skip
    """The golden engine's decision of every sample's causal run (:func:`tde_spikes`) by the
    readout ``saved`` at ``threshold`` [score x s], runs of ``duration`` [s]
    (:class:`~spll_hw.multichannel.decisions.Decisions`, one column)."""
    runs = tde_spikes(samples, config, levels)
    return engine_decisions(saved.readout, runs, duration, [threshold], START)


def decision_records(samples, names, mine, golden, dt: float) -> list[dict]:
    """``decisions.json``'s list: per sample, its recording and material, the exported graphs'
    decision ``mine[r]`` (``(label, step, fired)``, steps of ``dt`` [s]) and golden's
    (``golden.at(r, 0)``), each with the class of ``names``."""
    records = []
    for r, source in enumerate(samples.first_set.sources):
        g, (label, step, fired) = golden.at(r, 0), mine[r]
        records.append({
            "recording": source, "class": samples.class_names[int(samples.labels[r])],
            "exported": {"label": int(label), "class": names[int(label)], "step": int(step),
                         "time_s": step * dt, "fired": bool(fired)},
            "golden": {"label": g.label, "class": names[g.label], "time_s": g.time,
                       "fired": g.fired},
        })  # fmt: skip
    return records


def input_arrays(trains: dict, n: int, duration: float) -> dict[str, np.ndarray]:
    """``check_inputs.npz``'s arrays: ``rR/CHANNEL`` the spike times [s] of recording ``R`` of
    ``n`` (``trains[channel][R]``), and ``duration`` [s]."""
    arrays = {f"r{r}/{c}": np.asarray(t[r], float) for r in range(n) for c, t in trains.items()}
    return arrays | {"duration": np.float64(duration)}


def _write_decisions(folder, stage, config, saved, threshold, done: GroupsExport, manifest: dict,
                     duration: float) -> tuple[list[dict], dict]:  # fmt: skip
    """``check_inputs.npz``, ``decisions.json``, the consumer's runner and ``cost.json``
    (module docstring); returns ``decisions.json``'s decisions and ``cost.json``."""
    dt = manifest["readout"]["dt"]
    samples, levels = done.samples, done.levels
    trains = {c: causal_trains(samples, group, c, levels[c])
              for group in config.groups for c in group.channels}  # fmt: skip
    costed: list[PartRuns] = []
    mine, _ = executor_decisions(stage, config, manifest, trains, len(samples), duration, costed)
    golden = golden_decisions(samples, config, saved, threshold, levels, duration)
    records = decision_records(samples, saved.readout.class_names, mine, golden, dt)
    folder.arrays(INPUTS, input_arrays(trains, len(samples), duration))
    folder.json(DECISIONS, {
        "duration_s": duration, "dt": dt, "threshold": threshold,
        "recordings": [f"{m} recording {n}" for m, n in CHECK_RECORDINGS],
        "decisions": records,
    })  # fmt: skip
    folder.copy(RUNNER, Path(__file__).with_name("standalone_multichannel.py"))
    cost = decision_costs(costed, records, duration)
    folder.json(COST_FILE, cost)
    return records, cost


def _readme(config, done: GroupsExport, dt, saved, threshold, records: list[dict],
            cost: dict | None) -> str:  # fmt: skip
    lines = [
        "# Multichannel sPLL network for clocked NIR consumers",
        "",
        f"{config.n_spll} sPLLs of {len(config.channels)} channels ({', '.join(config.channels)}),"
        f" written by spll-hw from `{config.source}` as one nir-standard export per channel "
        "group: every channel of a group runs a copy of the group's network (a consumer runs "
        "them side by side, as a batch). `multichannel.toml`: the channels' networks and "
        "encoders; `multichannel.json`: the groups, their steps and the feature order.",
        "",
        *done.table(),
    ]
    if done.samples is None:
        lines += ["", "Checked on the reference trains only: `--data DIR` (a BioTac_slide_20_50 "
                  "folder) checks every channel on its own encoded signals."]  # fmt: skip
    if saved is None:
        return "\n".join(lines) + "\n"
    lines += [
        "",
        f"`{READOUT_DIR}/`: the spiking readout ({len(saved.readout.class_names)} classes, "
        f"threshold {threshold:g} score·s, switched on at {START:g} s) as a graph of standard "
        f"nodes at dt = {dt * 1e6:g} µs; its input is every group's TDE spikes, summed over the "
        f"readout's step, in feature order. `{READOUT_DIR}/{DECIDE_FILE}` takes its first "
        "decision spike (ties and the fallback from the input counts).",
    ]
    if done.samples is not None:
        lines += [
            "",
            f"`{DECISIONS}`: spll-hw's decisions on the check's recordings (`{INPUTS}`), the "
            f"exported graphs run by spll-hw's executor and golden's. `python {RUNNER} norse` "
            "runs the same in Norse (or `snntorch` where every step is 100 µs) and counts the "
            "decisions equal to the executor's.",
            "",
            "| recording | class | exported graphs (spll-hw's executor) | golden |",
            "|---|---|---|---|",
            *(f"| {r['recording']} | {r['class']} | {r['exported']['class']} at "
              f"{r['exported']['time_s']:.3f} s | {r['golden']['class']} at "
              f"{r['golden']['time_s']:.3f} s |" for r in records),
        ]  # fmt: skip
    if cost is not None:
        lines += ["", *cost_markdown(cost)]
    return "\n".join(lines) + "\n"
