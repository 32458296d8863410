"""What the exported multichannel network costs on a chip, per decision: ``cost.json`` at the
top of the folder ``spll-hw export --network MULTICHANNEL --to nir-standard --readout FILE
--data DIR`` writes, and a section of its README.

What is costed is what the folder holds: every channel group's graph of standard neurons
(:func:`~mappings.nir.neuron_graph.nir_graph`), once per channel of the group (each channel runs
a copy), and the readout's graph (:func:`~mappings.nir.neuron_graph.readout_graph`, its input
the groups' TDE spikes), each placed and priced by
:func:`spll_hw.neuron_graph.graph_resources` and :func:`spll_hw.neuron_graph.graph_cost` on
:data:`PROFILE` as a one-network folder's ``cost.json`` is. The counts are those of the
decisions check's own runs (spll-hw's executor, every neuron's spikes over the first
``duration`` s of each check recording): nothing runs twice.

Per recording: the dynamic energy per second of input (J/s, at the figures' values and as
``[low, high]`` over their ranges) summed over every copy of every group and the readout, each
clock's steps paid once (by the first part on that clock: the parts run side by side); the
**energy per decision** is that power times the recording's time to decision (the run's length
where no readout neuron fired): the chip's work up to the decision at the run's mean rate.
Cores are the groups' cores times their channels plus the readout's, each part placed on cores
of its own (an upper bound on a placement that packs them together). Static power is in each
part's profile figures but not summed here: it depends on what else the chip holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spll_hw.chips import ChipCost, format_joules
from spll_hw.exporters.cost import DEFAULT_PROFILE
from spll_hw.neuron_graph import COUNTS_KEY, NeuronGraph, graph_cost, graph_resources
from spll_hw.result import SimulationResult

#: The profile the folder is costed on.
PROFILE = DEFAULT_PROFILE
#: The file, at the top of the folder.
COST_FILE = "cost.json"
FORMAT = "spll-hw multichannel cost v1"
#: The README's section title.
TITLE = "What it costs on a chip"
#: The ``[energy]`` figure paid once per step of a clock, whatever runs on it.
STEP = "step"


@dataclass(frozen=True)
class PartRuns:
    """One costed part of the folder and the decisions check's runs of it.

    Attributes:
        name: the part's folder (``channels/1-ele1``, ``readout``).
        graph: its graph of standard neurons.
        copies: how many copies run (a group: its channels; the readout: 1).
        counts: every neuron's spikes of each run, shape ``(copies x n, graph.neurons)``, run
            ``c n + r`` the copy ``c`` on recording ``r``.
        inputs: each run's input spikes, per input of the graph, shape ``(copies x n, K)``
            (a group: ``K`` 1, its channel's encoded signal; the readout: ``K`` TDEs).
    """

    name: str
    graph: NeuronGraph
    copies: int
    counts: np.ndarray
    inputs: np.ndarray


def _run(counts: np.ndarray, inputs: np.ndarray, duration: float) -> SimulationResult:
    """A run of a graph as :func:`~spll_hw.neuron_graph.graph_cost` reads it: every neuron's
    spikes, each input's spikes and the duration [s]."""
    none = np.zeros(0, np.int64)
    info = {COUNTS_KEY: np.asarray(counts, np.int64), "n_input_spikes": np.asarray(inputs)}
    return SimulationResult(none, none, float(duration), "nir-numpy", info=info)


def _power(cost: ChipCost, duration: float, steps: bool) -> np.ndarray:
    """Dynamic energy per second [J/s]: at the figures' values, low and high; without the
    energy of the clock's steps unless ``steps``."""
    r = cost.dynamic_range
    energy = np.array([cost.dynamic_energy, r.low, r.high])
    if not steps and STEP in cost.figure_counts:
        n = cost.figure_counts[STEP]
        energy -= n * np.array([cost.figure_values[STEP], *cost.figure_ranges[STEP]])
    return energy / duration


def decision_costs(parts: list[PartRuns], decisions: list[dict], duration: float,
                   profile: str = PROFILE) -> dict:  # fmt: skip
    """``cost.json`` (module docstring) of ``parts`` run for ``duration`` [s] on the recordings
    of ``decisions`` (``decisions.json``'s list, in the runs' recording order)."""
    n = len(decisions)
    power = np.zeros((n, 3))
    entries, clocks = [], set()
    for part in parts:
        fit = graph_resources(part.graph, profile)
        mine = np.zeros((n, 3))
        rtf = 0.0
        for i in range(part.copies * n):
            cost = graph_cost(part.graph, profile, _run(part.counts[i], part.inputs[i], duration))
            mine[i % n] += _power(cost, duration, i < n and part.graph.dts not in clocks)
            rtf = max(rtf, cost.real_time_factor or 0.0)
        clocks.add(part.graph.dts)
        power += mine
        entries.append({
            "part": part.name, "copies": part.copies, "neurons": part.graph.neurons * part.copies,
            "synapses": part.graph.n_synapses * part.copies, "cores_each": fit.cores,
            "cores": fit.cores * part.copies, "fits": fit.fits, "problems": list(fit.problems),
            "dynamic_w": _watts(mine.mean(axis=0)), "real_time_factor": rtf,
        })  # fmt: skip
    runs = []
    for d, p in zip(decisions, power, strict=True):
        made = d["exported"]
        time = made["time_s"] if made["fired"] else duration
        runs.append({"recording": d["recording"], "class": made["class"], "time_s": time,
                     "fired": made["fired"], "dynamic_w": _watts(p),
                     "per_decision": _joules(p * time)})  # fmt: skip
    times = np.array([r["time_s"] for r in runs])
    return {
        "format": FORMAT, "profile": profile, "duration_s": duration,
        "cores": sum(e["cores"] for e in entries),
        "neurons": sum(e["neurons"] for e in entries),
        "fits": all(e["fits"] for e in entries), "parts": entries,
        "dynamic_w": _watts(power.mean(axis=0)),
        "mean_time_to_decision_s": float(times.mean()),
        "per_decision": _joules((power * times[:, None]).mean(axis=0)),
        "decisions": runs,
    }  # fmt: skip


def _watts(p) -> dict:
    return {"value": float(p[0]), "range": [float(p[1]), float(p[2])]}


def _joules(e) -> dict:
    return {"value": float(e[0]), "range": [float(e[1]), float(e[2])]}


def _energy(x: dict, per: str = "") -> str:
    low, high = (f"{format_joules(v)}{per}" for v in x["range"])
    return f"{format_joules(x['value'])}{per} [{low}, {high}]"


def markdown(entry: dict) -> list[str]:
    """The README's section of ``cost.json``'s ``entry``."""
    lines = [
        f"## {TITLE}",
        "",
        f"On **{entry['profile']}**, every group's graph once per channel and the readout's, "
        f"each placed on cores of its own: **{entry['cores']} cores**, {entry['neurons']} "
        f"neurons{'' if entry['fits'] else ' (does not fit: see `cost.json`)'}. Dynamic energy "
        "from every neuron's spikes in spll-hw's run of the decisions check (the figures' value "
        "[low, high]); per decision: the run's power times its time to decision. Static power "
        f"is not included. `{COST_FILE}` holds it all.",
        "",
        "| part | copies | cores | dynamic power | real-time factor |",
        "|---|---|---|---|---|",
        *(f"| {e['part']} | {e['copies']} | {e['cores']} | {_energy(e['dynamic_w'], '/s')} | "
          f"{e['real_time_factor']:.3g} |" for e in entry["parts"]),
        "",
        "| recording | decision | time to decision | energy per decision |",
        "|---|---|---|---|",
        *(f"| {r['recording']} | {r['class']} | {r['time_s']:.3f} s"
          f"{'' if r['fired'] else ' (end)'} | {_energy(r['per_decision'])} |"
          for r in entry["decisions"]),
        f"| mean | | {entry['mean_time_to_decision_s']:.3f} s | "
        f"{_energy(entry['per_decision'])} |",
    ]  # fmt: skip
    return lines
