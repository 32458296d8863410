"""Cost what runs: a graph of standard neurons placed and priced on a chip
(quantize/graph_cost.py), every export folder's cost.json (spll_hw/exporters/cost.py), ``spll-hw
chips --export FOLDER`` agreeing with it, and ``chips``/``fit`` with a construction backend
costing the construction instead of the two-compartment sPLL."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.sparse import csr_matrix

from quantize import load_profile
from spll_hw import backends, chips
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.exporters.cost import write_cost
from spll_hw.neuron_graph import COUNTS_KEY, NeuronGraph, graph_cost, graph_resources
from spll_hw.result import SimulationResult
from spll_hw.simulate import poisson_spikes

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

TARGETS = ("nir", "lava", "nir-standard", "lava-standard")
#: loihi2 with three neurons per core, one core per router tile, two tiles per row: each sPLL's
#: three neurons take a core of their own, and routes between cores take hops.
SMALL_CORES = """
[profile]
base = "loihi2"
name = "loihi2-small-cores"
description = "loihi2 with three neurons per core"

[resources]
neurons_per_core = { value = 3, source = "test" }
cores_per_tile = { value = 1, source = "test" }
mesh_columns = { value = 2, source = "test" }
multicast = { value = false, source = "test" }
configs_per_core = { value = 32, source = "test" }
thresholds_per_core = { value = 8, source = "test" }
"""


@pytest.fixture(scope="module")
def four(tmp_path_factory) -> Path:
    """The default preset with 4 sPLLs: every export and check of it takes a second or two."""
    path = tmp_path_factory.mktemp("net") / "four.toml"
    path.write_text(NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).to_toml())
    return path


def _close(a, b, where: str = "") -> None:
    """``a`` and ``b`` equal as JSON values, numbers to rounding."""
    if isinstance(a, dict):
        assert sorted(a) == sorted(b), where
        for k in a:
            _close(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{where}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert a == pytest.approx(b, rel=1e-9, abs=1e-18), where
    else:
        assert a == b, where


@pytest.mark.parametrize("target", TARGETS)
def test_every_export_states_its_cost_and_chips_export_agrees(four, tmp_path, target, capsys):
    out = tmp_path / target
    args = ["export", "--network", str(four), "--to", target, "--out", str(out)]
    assert main([*args, "--check-duration", "0.3"]) == 0
    assert f"{out / 'cost.json'}" in capsys.readouterr().out  # listed among the files
    cost = json.loads((out / "cost.json").read_text())
    check = json.loads((out / "check.json").read_text())
    graph = target.endswith("standard")
    assert cost["target"] == target and cost["fits"] and cost["cores"] >= 1 and cost["chips"] == 1
    assert cost["profile"] == "loihi2"  # the default; lava's own profile is loihi2 at its dt
    expected_step = {"nir": 1e-5, "lava": 1e-5, "nir-standard": 1e-4, "lava-standard": 5e-5}
    assert cost["step_s"] == pytest.approx(expected_step[target])
    # The two-compartment sPLL: 2 neurons and 3 synapses per sPLL; a construction: many more.
    assert (cost["neurons"] > 8 and cost["synapses"] > 12) if graph else (
        cost["neurons"] == 8 and cost["synapses"] == 12)  # fmt: skip
    assert [x["label"] for x in cost["inputs"]] == [x["label"] for x in check["inputs"]]
    for x, row in zip(cost["inputs"], check["inputs"], strict=True):
        assert x["input_spikes"] == row["n_spikes"] and x["duration_s"] == row["duration_s"]
        low, high = x["dynamic_range_j"]
        assert 0 < low <= x["dynamic_j"] <= high
        # per second of input: the run's energy over its 0.3 s
        assert x["categories_j"]["static"] == pytest.approx(0.212)  # one chip, powered 1 s/s
    mean = cost["energy_per_second"]
    assert mean["dynamic_j"] == pytest.approx(np.mean([x["dynamic_j"] for x in cost["inputs"]]))
    readme = (out / "README.md").read_text()
    assert "## What it costs on loihi2" in readme and "| **mean** |" in readme
    assert "## Check against the golden model" in readme  # the check's section is kept
    # chips --export runs the folder again on its check inputs and costs it the same way.
    report = tmp_path / "report"
    assert main(["chips", "--export", str(out), "--out", str(report)]) == 0
    text = capsys.readouterr().out
    assert f"# Chips: what the export `{out}` costs" in text and "| loihi2 | yes |" in text
    again = json.loads((report / "results.json").read_text())
    assert again["target"] == target and len(again["profiles"]) == 1
    _close(again["profiles"][0], cost)


def test_export_check_again_writes_the_cost_again(four, tmp_path):
    """``export --check FOLDER --out DIR`` runs the check again and the folder's cost with it,
    into DIR (the folder keeps its own); a folder costed on other profiles names each."""
    out = tmp_path / "lava-standard"
    assert main(["export", "--network", str(four), "--to", "lava-standard", "--out", str(out),
                 "--check-duration", "0.2"]) == 0  # fmt: skip
    again = tmp_path / "again"
    assert main(["export", "--check", str(out), "--out", str(again)]) == 0
    cost = json.loads((again / "cost.json").read_text())
    assert cost == json.loads((out / "cost.json").read_text())
    assert cost["target"] == "lava-standard" and len(cost["inputs"]) == 6
    report = tmp_path / "report"
    assert main(["chips", "--export", str(out), "--profiles", "loihi2,loihi1,fixed16",
                 "--out", str(report)]) == 0  # fmt: skip
    profiles = json.loads((report / "results.json").read_text())["profiles"]
    assert [p["profile"] for p in profiles] == ["loihi2", "loihi1", "fixed16"]
    _close(profiles[0], cost)
    assert profiles[1]["neurons"] == cost["neurons"] and profiles[1]["step_s"] == 5e-5
    assert "no [resources] table" in profiles[2]["refused"]  # a profile of formats only


def test_chips_export_names_what_a_folder_lacks(four, tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["chips", "--export", str(empty), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert f"{empty / 'check.json'}: no check.json here" in err and "spll-hw export" in err
    out = tmp_path / "nir"
    assert main(["export", "--network", str(four), "--to", "nir", "--out", str(out),
                 "--check-duration", "0.2"]) == 0  # fmt: skip
    (out / "check_inputs.npz").unlink()
    assert main(["chips", "--export", str(out), "--out", str(tmp_path / "r")]) == 2
    assert f"{out / 'check_inputs.npz'}: no check inputs here" in capsys.readouterr().err
    assert main(["chips", "--export", str(out), "--network", str(four)]) == 2
    assert "--export costs FOLDER as it was written" in capsys.readouterr().err
    assert main(["chips", "--export", str(tmp_path / "nowhere")]) == 2
    assert "no such folder" in capsys.readouterr().err
    # A target that declares no cost_of (another package's) has its folder say so.
    write_cost(out, "no-such-target", NetworkConfig.load(four).build(), report=None)
    refused = json.loads((out / "cost.json").read_text())
    assert "unknown export target 'no-such-target'" in refused["refused"]
    assert "Not costed: unknown export target" in (out / "README.md").read_text()


def _hand_graph(dts=(1e-4,), clock=(0,) * 7) -> NeuronGraph:
    """Two sPLLs of three neurons (1-3, 4-6) and a neuron shared by both (0): the input drives
    1 and 4; 1 -> 2 -> 3 -> 2 in each, 0 -> 3 and 0 -> 6 across."""
    post = [2, 3, 2, 5, 6, 5, 3, 6]
    pre = [1, 2, 3, 4, 5, 6, 0, 0]
    synapses = csr_matrix((np.ones(8, np.int64), (post, pre)), shape=(7, 7))
    return NeuronGraph(
        "hand", "a test graph", 2, dts, np.array(clock), np.array([-1, 0, 0, 0, 1, 1, 1]),
        np.zeros(7, np.int64), np.zeros(7, np.int64), np.zeros(7, np.int64), ("all",),
        synapses, np.array([0, 1, 0, 0, 1, 0, 0]),
    )  # fmt: skip


SPIKES = np.array([2, 10, 7, 5, 8, 6, 4])


def _run(spikes=SPIKES, n_in: int = 20, duration: float = 0.5) -> SimulationResult:
    return SimulationResult(np.zeros(2, np.int64), np.zeros(2, np.int64), duration, "hand",
                            info={"n_input_spikes": n_in, COUNTS_KEY: spikes})  # fmt: skip


def test_a_construction_costs_its_counts_times_the_figures_by_hand(tmp_path):
    profile = tmp_path / "small.toml"
    profile.write_text(SMALL_CORES)
    graph = _hand_graph()
    fit = graph_resources(graph, str(profile))
    # The shared neuron first (core 0), then each sPLL's three neurons kept together.
    assert fit.fits and fit.cores == 3
    np.testing.assert_array_equal(fit.detail.core_of, [0, 1, 1, 1, 2, 2, 2])
    cost = graph_cost(graph, str(profile), _run())
    # By hand. Core positions (1 core per tile, 2 tiles per row): 0 (0,0), 1 (1,0), 2 (0,1).
    # Neuron 0 sends to cores 1 and 2 (one hop each), every other neuron to its own core; the
    # input (20 spikes, entering at core 0) to cores 1 and 2.
    counts = {
        "synaptic_event": 20 * 2 + (2 * 2 + 10 + 7 + 5 + 8 + 6 + 4),  # input + fan-out x spikes
        "spike": 42,
        "message": 20 * 2 + (2 * 2 + 40),
        "hop": 20 * 2 + 2 * 2,
        "chip_hop": 0,
        "neuron_update": 7 * 5000,  # 7 neurons x 0.5 s / 100 us
        "step": 5000,
    }
    chip = load_profile(profile).chip
    assert cost.figure_counts == {k: v for k, v in counts.items() if k in chip.energy}
    for end in ("value", "low", "high"):
        by_hand = sum(n * chip.energy.figure(k).at(end) for k, n in counts.items()
                      if k in chip.energy)  # fmt: skip
        energy = {"value": cost.energy, "low": cost.energy_low, "high": cost.energy_high}[end]
        dynamic = sum(
            v for k, v in energy.items() if v is not None and k not in ("static", "cores")
        )
        assert dynamic == pytest.approx(by_hand, rel=1e-12)
        assert energy["static"] == pytest.approx(chip.energy.figure("static_power").at(end) * 0.5)
    assert cost.detail.counts.crossing == {"input": 40, "neurons": 4}  # only neuron 0's leave
    assert cost.dynamic_range.low < cost.dynamic_energy < cost.dynamic_range.high


def test_each_input_of_a_graph_of_several_reaches_its_own_synapses(tmp_path):
    """The hand graph fed by two inputs (one onto neuron 1, one onto neuron 4, as a readout is
    fed by its TDEs): an input's spike is delivered to its own synapse and messaged to its own
    core, where the one-input graph delivers every input spike to both."""
    profile = tmp_path / "small.toml"
    profile.write_text(SMALL_CORES)
    one = _hand_graph()
    fan = csr_matrix((np.ones(2, np.int64), ([1, 4], [0, 1])), shape=(7, 2))
    two = dataclasses.replace(one, input_fan=fan)
    assert two.input_fan_out.tolist() == [1, 1] and one.input_fan_out.tolist() == [2]
    fit = graph_resources(two, str(profile))
    assert fit.detail.input_routes[:, 0].tolist() == [1, 1]  # a message to its own core each
    cost = graph_cost(two, str(profile), _run(n_in=np.array([12, 8])))
    internal = 2 * 2 + 10 + 7 + 5 + 8 + 6 + 4  # the neurons' spikes x their fan-out, as above
    assert cost.figure_counts["synaptic_event"] == 12 + 8 + internal
    assert cost.figure_counts["message"] == 12 + 8 + (2 * 2 + 40)
    alone = graph_cost(one, str(profile), _run(n_in=20))  # one input: 20 spikes to both
    assert alone.figure_counts["synaptic_event"] == 20 * 2 + internal
    with pytest.raises(ValueError, match="the graph has 2 input"):
        graph_cost(two, str(profile), _run(n_in=20))
    with pytest.raises(ValueError, match="rows sum to input_synapses"):
        dataclasses.replace(one, input_fan=csr_matrix((7, 2), dtype=np.int64))


def test_each_clock_runs_on_cores_of_its_own():
    """sPLL 1 (and nothing else) on a clock of 200 us: its neurons are updated half as often,
    its step counted apart, and it shares no core with the 100 us clock."""
    graph = _hand_graph(dts=(1e-4, 2e-4), clock=(0, 0, 0, 0, 1, 1, 1))
    fit = graph_resources(graph, "loihi2")
    assert fit.cores == 2 and [c["clock"] for c in fit.data["placement"]] == [0, 1]
    cost = graph_cost(graph, "loihi2", _run())
    counts = cost.detail.counts
    assert counts.neuron_updates == 4 * 5000 + 3 * 2500 and counts.steps == 5000 + 2500
    assert counts.clock_steps == (5000, 2500)
    assert cost.real_time_factor < 1


def test_a_run_counts_every_neuron_in_the_graphs_order():
    """The spikes of every neuron (info['neuron_counts']) are in the graph's order: NIR's last
    node holds the TDE and CCO spikes the network emits; Lava's TDE population fires at least
    the spikes the network emits (the held ones are dropped from those)."""
    net = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(3).build()
    train = poisson_spikes(300.0, 0.3, 1)
    nir = backends.get("nir-numpy")
    graph = nir.neuron_graph(net)
    result = nir.simulate(net, train, 0.3)
    counts = result.info[COUNTS_KEY]
    assert counts.shape == (graph.neurons,) and graph.populations[-1] == "i_spikes"
    np.testing.assert_array_equal(counts[-6:], np.r_[result.tde_counts, result.cco_counts])
    lava = backends.get("standard-fixed-point")
    graph = lava.neuron_graph(net)
    result = lava.simulate(net, train, 0.3)
    counts = result.info[COUNTS_KEY]
    tde = graph.population == graph.populations.index("tde")
    assert np.all(counts[tde] >= result.tde_counts) and counts[tde].sum() > 0
    assert np.all(graph.spll[tde] == np.arange(3))
    # A clock per sPLL: each sPLL's neurons on their own clock, counted part after part.
    scaled = NetworkConfig.preset("biotac-time-scaled-lif").with_n(2).build()
    clocked = backends.get("standard-fixed-point:clock=per-spll")
    graph = clocked.neuron_graph(scaled)
    result = clocked.simulate(scaled, train, 0.3)
    assert len(graph.dts) == 2 and result.info[COUNTS_KEY].shape == (graph.neurons,)
    assert [set(graph.spll[graph.clock == k].tolist()) for k in (0, 1)] in ([{0}, {1}], [{1}, {0}])
    steps = graph_cost(graph, "loihi2", result).detail.counts.clock_steps
    assert steps == tuple(round(0.3 / dt) for dt in graph.dts)


def test_chips_and_fit_with_a_construction_backend_cost_the_construction(four, tmp_path, capsys):
    out = tmp_path / "chips"
    args = ["chips", "--network", str(four), "--profiles", "loihi2", "--duration", "0.2"]
    assert main([*args, "--backend", "standard-fixed-point", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Costed in place of the two-compartment sPLL" in text and "dt = 50 µs" in text
    entry = json.loads((out / "results.json").read_text())["profiles"][0]
    net = NetworkConfig.load(four).build()
    backend = backends.get("standard-fixed-point")
    graph = backend.neuron_graph(net)
    placed = entry["resources"]
    assert placed["neurons"] == graph.neurons and placed["costed"].startswith("lava-standard")
    sample = backend.simulate(net, poisson_spikes(300.0, 0.2, 0), 0.2)  # chips' seed 0 sample
    by_hand = graph_cost(graph, "loihi2", sample)
    assert entry["energy_j"]["dynamic"] == pytest.approx(by_hand.dynamic_energy)
    # The two-compartment sPLL of the same sample costs otherwise: the construction was costed.
    assert main([*args, "--out", str(tmp_path / "spll")]) == 0
    spll = json.loads((tmp_path / "spll" / "results.json").read_text())["profiles"][0]
    assert spll["resources"]["neurons"] == 8 and not math.isclose(
        spll["energy_j"]["dynamic"], entry["energy_j"]["dynamic"], rel_tol=0.01
    )
    # A stepped profile builds the construction at that step.
    assert main([*args, "--steps", "25us", "--backend", "standard-fixed-point",
                 "--out", str(tmp_path / "stepped")]) == 0  # fmt: skip
    stepped = json.loads((tmp_path / "stepped" / "results.json").read_text())["profiles"][0]
    assert stepped["profile"] == "loihi2@25us" and stepped["resources"]["dt_s"] == [2.5e-5]
    capsys.readouterr()
    fit = ["fit", "--network", str(four), "--profiles", "loihi2", "--backend", "nir-numpy"]
    assert main(fit) == 0
    text = capsys.readouterr().out
    nir = backends.get("nir-numpy").neuron_graph(net)
    assert "the nir-standard construction that `nir-numpy` runs" in text
    assert f"{nir.neurons} neurons" in text and "dt = 100 µs" in text and "fits" in text
    assert chips.resources(chips.OnChip(net, "loihi2")).data["neurons"] == 8 < nir.neurons
