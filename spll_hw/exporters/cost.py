"""Every export folder states what it costs on a chip: ``cost.json`` beside ``check.json``, and a
section of the folder's README.

What is costed is what the folder runs, as its exporter declares
(:func:`~spll_hw.exporters.costs_as`, a :class:`~spll_hw.exporters.FolderCost`):

* ``--to nir`` and ``--to lava``: the two-compartment sPLL (a TDE and a CCO per sPLL),
  placed and priced by :func:`spll_hw.chips.resources` and :func:`spll_hw.chips.cost`; on the
  folder's profile at its step (``lava``: its ``--profiles``, default ``loihi2``, at its ``dt``,
  ``NAME@STEP`` where that is not the profile's own; a TOML file's as the folder's
  ``profile.toml`` defines it, :attr:`~spll_hw.exporters.FolderCost.source`), or for the
  continuous-time NIR graph on :data:`DEFAULT_PROFILE` at that profile's own step;
* ``--to nir-standard`` and ``--to lava-standard``: the graph of standard neurons the folder
  writes, every neuron and synapse at the folder's own step
  (:class:`~spll_hw.neuron_graph.NeuronGraph`), placed and priced by
  :func:`spll_hw.neuron_graph.graph_resources` and :func:`~spll_hw.neuron_graph.graph_cost` on
  :data:`DEFAULT_PROFILE`'s figures.

The counts are those of the export's own check (:mod:`.check`), input by input: the TDE and
CCO spikes of the folder's run and, for a graph, the spikes of every neuron of it (the check's
run counts them: nothing runs twice). Energy is stated **per second of input** (J/s: the
sample's energy over its duration) on each of the check's inputs and as their mean: dynamic
energy as ``[low, high]`` over the figures' ranges and at their values, the part resting on
assumed figures, static energy apart, the energy of every category and how often each figure
is paid. ``spll-hw chips --export FOLDER`` (:func:`folder_report`) runs the folder again on its
``check_inputs.npz`` and costs it the same way, on other profiles too: it agrees with
``cost.json``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import chips
from ..files import write_json, write_text
from ..network import Network
from ..neuron_graph import COUNTS_KEY, graph_cost, graph_resources
from ..result import SimulationResult
from ..timestep import at_step
from . import FolderCost, cost_reader, reader
from .check import train_key
from .check_files import (
    CHECK_FILE,
    INPUTS_FILE,
    README_FILE,
    read_inputs,
    read_network,
    stored_target,
    without_block,
)

#: The file every export folder states its cost in.
COST_FILE = "cost.json"
FORMAT = "spll-hw export cost v1"
#: The profile a folder is costed on where it holds none of its own.
DEFAULT_PROFILE = "loihi2"
#: Markers around the README's cost section (a new costing replaces it).
SECTION = ("<!-- spll-hw cost -->", "<!-- /spll-hw cost -->")


@dataclass(frozen=True)
class Sample:
    """One of the check's inputs and the folder's run of it: ``label``, ``train`` (its key in
    ``check_inputs.npz``) and the run's ``result`` (its ``info["n_input_spikes"]``, and for a
    graph ``info[COUNTS_KEY]``)."""

    label: str
    train: str
    result: SimulationResult


def _result(tde, cco, duration: float, spikes: np.ndarray, backend: str, counts=None):
    info = {"n_input_spikes": int(np.count_nonzero(np.asarray(spikes) <= duration))}
    if counts is not None:
        info[COUNTS_KEY] = np.asarray(counts, dtype=np.int64)
    return SimulationResult(np.asarray(tde, dtype=np.int64), np.asarray(cco, dtype=np.int64),
                            float(duration), backend, info=info)  # fmt: skip


def report_samples(report) -> list[Sample]:
    """The samples of a :class:`~.check.CheckReport`: its inputs, their TDE and CCO counts
    and every neuron's where the check's run counted them."""
    counts = list(report.neuron_counts) + [None] * len(report.trains)
    return [
        Sample(x.label, train_key(i), _result(row["tde_counts"], row["cco_counts"], x.duration,
                                              x.spikes, report.backend, counts[i]))
        for i, (x, row) in enumerate(zip(report.trains, report.inputs, strict=True))
    ]  # fmt: skip


def rerun(folder: str | Path, target: str, network: Network) -> list[Sample]:
    """The folder of ``target`` run again, by its target's rules
    (:func:`~spll_hw.exporters.reader`), on every input of its ``check_inputs.npz``;
    ``FileNotFoundError`` naming the file where there is none."""
    folder = Path(folder)
    stored = read_inputs(folder)
    if not stored:
        raise FileNotFoundError(
            f"{folder / INPUTS_FILE}: no check inputs here: costing a folder runs what it holds "
            "on the inputs of its check (spll-hw export writes them; spll-hw export --check "
            "FOLDER writes them again)"
        )
    if any(math.isnan(d) for _, _, d, *_ in stored):
        raise ValueError(f"{folder / INPUTS_FILE}: written by an older spll-hw without the "
                         "inputs' lengths; run spll-hw export --check FOLDER first")  # fmt: skip
    run = reader(target)(folder, network)
    samples: list[Sample | None] = [None] * len(stored)
    for duration in dict.fromkeys(d for _, _, d, *_ in stored):
        idx = [i for i, (_, _, d, *_) in enumerate(stored) if d == duration]
        for i, r in zip(idx, run.simulate([stored[i][3] for i in idx], duration), strict=True):
            samples[i] = Sample(stored[i][0], train_key(i), _result(
                r.tde_counts, r.cco_counts, duration, stored[i][3], run.backend.spec,
                r.info.get(COUNTS_KEY)))  # fmt: skip
    return samples


def profile_name(costed: FolderCost, profile: str | None = None) -> str:
    """The profile a folder is costed on: ``profile`` (default the folder's own, else
    :data:`DEFAULT_PROFILE`); the two-compartment sPLL at the folder's step where the profile
    is clocked at another (``NAME@STEP``). A graph states its own step. The folder's own
    definition (:attr:`FolderCost.source`, at the folder's step) is named as it names
    itself."""
    if profile is None and costed.source is not None:
        return chips.describe(costed.source).name
    name = profile or costed.profile or DEFAULT_PROFILE
    if costed.graph is not None or costed.dt is None:
        return name
    own = chips.describe(name).dt
    if own is None or math.isclose(own, costed.dt, rel_tol=1e-9):
        return name
    return at_step(name, costed.dt)


#: What :func:`_per_second` states of a sample, and ``cost.json`` of their mean.
PER_SECOND = ("dynamic_j", "dynamic_range_j", "dynamic_assumed_j", "static_j", "static_range_j",
              "categories_j", "figure_counts")  # fmt: skip


def _per_second(cost: chips.ChipCost, duration: float) -> dict:
    """A sample's energies [J] over its ``duration`` [s]: J per second of input."""
    d, s = cost.dynamic_range, cost.static_range
    return {
        "dynamic_j": cost.dynamic_energy / duration,
        "dynamic_range_j": [d.low / duration, d.high / duration],
        "dynamic_assumed_j": cost.assumed_dynamic_energy / duration,
        "static_j": None if cost.static_energy is None else cost.static_energy / duration,
        "static_range_j": None if s is None else [s.low / duration, s.high / duration],
        "categories_j": {k: None if v is None else v / duration for k, v in cost.energy.items()},
        "figure_counts": {k: v / duration for k, v in cost.figure_counts.items()},
    }


def _mean(values: list):
    """The mean of equal-shaped JSON values: numbers, lists and dicts elementwise."""
    first = values[0]
    if first is None or isinstance(first, str):
        return first
    if isinstance(first, dict):
        return {k: _mean([v[k] for v in values]) for k in first}
    if isinstance(first, list):
        return [_mean([v[i] for v in values]) for i in range(len(first))]
    return float(np.mean(values))


def cost_entry(
    costed: FolderCost,
    target: str,
    network: Network,
    samples: list[Sample],
    profile: str | None = None,
) -> tuple[dict, str]:
    """``cost.json`` of a folder of ``target`` (module docstring) on ``profile`` (default
    :func:`profile_name`'s) from the runs ``samples``, and the placement as Markdown. A profile
    that cannot cost it (no ``[resources]``, a step it cannot write) gives an entry with
    ``refused``."""
    name = profile_name(costed, profile)
    # the folder's own definition where it carries one, else the profile by its name
    source = costed.source if profile is None and costed.source is not None else name
    head = {"format": FORMAT, "target": target, "profile": name, "costed": costed.what}
    graph = costed.graph
    try:  # a network that does not fit is costed on the placement it would need
        if graph is None:
            on_chip = chips.OnChip(network, source)
            fit = chips.resources(on_chip)
            costs = [chips.cost(on_chip, s.result) for s in samples]
        else:
            fit = graph_resources(graph, source)
            costs = [graph_cost(graph, source, s.result) for s in samples]
    except ValueError as exc:
        return head | {"refused": str(exc)}, f"refused: {exc}"
    sizes = {"neurons": fit.data["neurons"], "synapses": fit.data["synapses"]}
    if graph is None:
        step = chips.describe(source).dt
        sizes["compartments"] = fit.data["compartments"]
    else:
        step = graph.dts[0] if len(graph.dts) == 1 else list(graph.dts)
    inputs = []
    for s, c in zip(samples, costs, strict=True):
        duration = s.result.duration
        inputs.append({"label": s.label, "train": s.train, "duration_s": duration,
                       "input_spikes": s.result.info["n_input_spikes"],
                       **_per_second(c, duration), "counts": c.data["counts"],
                       "step_latency_s": c.step_latency,
                       "real_time_factor": c.real_time_factor})  # fmt: skip
    mean = {k: _mean([x[k] for x in inputs]) for k in PER_SECOND} if inputs else None
    entry = head | {
        "step_s": step, **sizes, "cores": fit.cores,
        "cores_range": list(fit.cores_range or (fit.cores, fit.cores)), "chips": fit.chips,
        "fits": fit.fits,
        "problems": list(fit.problems), "energy_per_second": mean,
        "real_time_factor": max((c.real_time_factor or 0.0 for c in costs), default=None),
        "inputs": inputs,
        "assumed": list(dict.fromkeys([*fit.assumed, *(k for c in costs for k in c.assumed)])),
        "resources": fit.data,
    }  # fmt: skip
    return entry, fit.markdown


def write_cost(
    folder: str | Path,
    target: str,
    network: Network,
    report,
    profile: str | None = None,
    into: str | Path | None = None,
) -> list[Path]:
    """Cost the folder of ``target`` on the runs of its check ``report`` (a
    :class:`~.check.CheckReport`; every neuron's spikes where it counted them, else the folder
    is run again on its check's inputs) and write ``cost.json`` and the README's section (a
    target that declares no ``cost_of``, another package's, says so in them) into the folder,
    or into ``into`` where given (``spll-hw export --check FOLDER --out DIR``, which leaves
    the folder as it is). The files written."""
    folder = Path(folder)
    target_folder = folder if into is None else Path(into)
    try:
        cost_of = cost_reader(target)
    except ValueError as exc:
        entry = {"format": FORMAT, "target": target, "profile": profile or DEFAULT_PROFILE,
                 "refused": str(exc)}  # fmt: skip
    else:
        costed = cost_of(folder, network)
        samples = report_samples(report)
        if costed.graph is not None and any(COUNTS_KEY not in s.result.info for s in samples):
            samples = rerun(folder, target, network)
        entry, _ = cost_entry(costed, target, network, samples, profile)
    write_json(target_folder / COST_FILE, entry)
    readme = target_folder / README_FILE
    text = readme.read_text() if readme.is_file() else f"# sPLL network exported to {target}\n"
    section = "\n".join([SECTION[0], markdown(entry), SECTION[1]])
    write_text(readme, f"{without_block(text, SECTION).rstrip(chr(10))}\n\n{section}\n")
    return [target_folder / COST_FILE, readme]


def _range(values, per: str = "/s") -> str:
    if values is None:
        return "-"
    return f"[{chips.format_joules(values[0])}{per}, {chips.format_joules(values[1])}{per}]"


def markdown(entry: dict, folder: str = "<this folder>") -> str:
    """One folder cost (:func:`cost_entry`) as the README's section."""
    if "refused" in entry:
        return f"## What it costs on {entry['profile']}\n\nNot costed: {entry['refused']}"
    mean = entry["energy_per_second"] or {}
    lines = [
        f"## What it costs on {entry['profile']}",
        "",
        f"Costed: {entry['costed']}, at {_step(entry['step_s'])} on {entry['profile']}'s "
        f"figures: {entry['neurons']} neurons, "
        f"{entry['synapses']} synapses, {entry['cores']} core(s) on {entry['chips']} chip(s) "
        f"({'fits' if entry['fits'] else 'does not fit: ' + '; '.join(entry['problems'])}). "
        "Energy per second of input (J/s), on the check's inputs, the figures of the profile "
        "at the low and the high end of their ranges (at their values):",
        "",
        "| input | input spikes | dynamic [low, high] (value) | static [low, high], apart |",
        "|---|---:|---:|---:|",
    ]
    for x in entry["inputs"]:
        lines.append(f"| {x['label']} | {x['input_spikes']} | {_range(x['dynamic_range_j'])} "
                     f"({chips.format_joules(x['dynamic_j'])}/s) | "
                     f"{_range(x['static_range_j'])} |")  # fmt: skip
    if mean:
        lines.append(f"| **mean** | | **{_range(mean['dynamic_range_j'])}** "
                     f"({chips.format_joules(mean['dynamic_j'])}/s) | "
                     f"{_range(mean['static_range_j'])} |")  # fmt: skip
        parts = sorted(((v, k) for k, v in mean["categories_j"].items()
                        if v and k not in chips.STATIC_CATEGORIES), reverse=True)  # fmt: skip
        total = sum(v for v, _ in parts) or 1.0
        lines += ["", "Of the mean dynamic energy: " + ", ".join(
            f"{k} {100 * v / total:.0f} %" for v, k in parts[:4]) + "."]  # fmt: skip
    lines += ["", f"`{COST_FILE}` holds every category and count; `spll-hw chips --export "
              f"{folder}` costs the folder again (`--profiles` on other chips)."]  # fmt: skip
    return "\n".join(lines)


def _step(step) -> str:
    if step is None:
        return "unclocked"
    if isinstance(step, list):
        return "dt = " + ", ".join(f"{x * 1e6:.4g} µs" for x in step)
    return f"dt = {step * 1e6:.4g} µs"


def folder_report(folder: str | Path, profiles: list[str] | None = None) -> tuple[str, dict]:
    """``spll-hw chips --export FOLDER``: the folder costed from its files on each of
    ``profiles`` (default: :func:`profile_name`'s), its runs made again on its check's
    inputs (:func:`rerun`): Markdown and the JSON payload (``profiles``: one
    :func:`cost_entry` each, the first equal to the folder's ``cost.json`` where the profile
    is its own)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"--export {folder}: no such folder")
    target = stored_target(folder)
    if target is None:
        raise FileNotFoundError(
            f"{folder / CHECK_FILE}: no check.json here: --export costs a folder that spll-hw "
            "export wrote (check.json names its target, check_inputs.npz holds the inputs "
            "that are run again, params.toml the network)"
        )
    network = read_network(folder)
    costed = cost_reader(target)(folder, network)
    samples = rerun(folder, target, network)
    entries, sections = [], []
    for profile in profiles or [None]:
        entry, placement = cost_entry(costed, target, network, samples, profile)
        entries.append(entry)
        sections += [markdown(entry, str(folder)), "", placement, ""]
    rows = [_row(e) for e in entries]
    head = [
        f"# Chips: what the export `{folder}` costs",
        "",
        f"Target {target}; costed: {costed.what}; run again on the {len(samples)} inputs of "
        f"its check (`{INPUTS_FILE}`). Energy per second of input, mean over the inputs.",
        "",
        "| profile | fits | neurons | synapses | cores | chips | dynamic energy / s [low, high] "
        "(at the figures' values) | of it on assumed figures | static energy / s [low, high], "
        "apart | real-time factor |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        *rows,
        "",
    ]
    payload = {"folder": str(folder), "target": target, "profiles": entries}
    return "\n".join(head + sections).rstrip(), payload


def _row(e: dict) -> str:
    if "refused" in e:
        return f"| {e['profile']} | refused: {e['refused']} | | | | | | | | |"
    m = e["energy_per_second"]
    if not m:
        return (f"| {e['profile']} | no | {e['neurons']} | {e['synapses']} | {e['cores']} | "
                f"{e['chips']} | - | - | - | - |")  # fmt: skip
    share = 0 if not m["dynamic_j"] else 100 * m["dynamic_assumed_j"] / m["dynamic_j"]
    rtf = "-" if e["real_time_factor"] is None else f"{e['real_time_factor']:.3g}"
    return (
        f"| {e['profile']} | {'yes' if e['fits'] else 'no'} | {e['neurons']} | {e['synapses']} "
        f"| {e['cores']} | {e['chips']} | {_range(m['dynamic_range_j'])} "
        f"({chips.format_joules(m['dynamic_j'])}/s) | {share:.0f} % | "
        f"{_range(m['static_range_j'])} | {rtf} |"
    )
