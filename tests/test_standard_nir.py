"""The standard sPLL as NIR (mappings/nir/standard.py): standard nodes only, consumers run it, its
counts against the golden model, the export target and bad input."""

from __future__ import annotations

import importlib.util
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from spll_hw import Network, network_frequencies, simulate_batch
from spll_hw.config import NetworkConfig
from spll_hw.construction.gate import GateOptions
from spll_hw.harness.metrics import rate_error
from spll_hw.model import grid

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import export_standard  # noqa: E402
from mappings.nir.consumers import run_consumer  # noqa: E402
from mappings.nir.standard import (  # noqa: E402
    EXPORT_LEVELS,
    NODE_NAMES,
    to_standard_nir,
)
from mappings.nir.standard_backend import NirNorse, NirNumpy, NirSnntorch  # noqa: E402
from spll_hw.model.holds import compensated_hold  # noqa: E402

DURATION = 0.5
STANDARD_NODES = {"Input", "Output", "Linear", "Affine", "LIF", "CubaLIF"}
#: snnTorch and Norse need torch; the test extra does not install it (about 4 GB with its CUDA
#: libraries from PyPI), benchmarks/bench_nir_consumers.py records their runs.
HAS = {m: importlib.util.find_spec(m) is not None for m in ("snntorch", "norse", "torch")}


@pytest.fixture(scope="module")
def workload():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))
    trains = [poisson_train(300.0, DURATION, seed) for seed in (0, 1)]
    return net, trains


@pytest.fixture(scope="module")
def graph_file(workload, tmp_path_factory):
    out = tmp_path_factory.mktemp("nir-standard")
    files = export_standard(workload[0], out)
    return files[0]


def test_graph_has_standard_nodes_only_and_both_parts_as_output(workload, graph_file):
    graph = nir.read(str(graph_file))
    assert {type(v).__name__ for v in graph.nodes.values()} <= STANDARD_NODES
    for name, node in graph.nodes.items():
        assert not getattr(node, "metadata", None), f"node {name} carries metadata"
    n = workload[0].n_spll
    assert list(graph.nodes[NODE_NAMES["output"]].output_type.values())[0].tolist() == [2 * n]
    assert float(graph.metadata["dt"]) == 1e-4
    spll = graph.nodes[NODE_NAMES["spll"]]
    # Written the way the consumers read it: w_in = tau_syn/dt, r = tau_mem/dt, v_leak = 0.
    np.testing.assert_allclose(spll.w_in, spll.tau_syn / 1e-4)
    np.testing.assert_allclose(spll.r, spll.tau_mem / 1e-4)
    assert np.all(spll.v_leak == 0) and np.all(spll.v_threshold == 1)
    bias = graph.nodes[NODE_NAMES["synapses"]].bias
    assert np.all(bias[n : 2 * n] > 0)  # the CCO offset, as an Affine bias
    assert np.all(bias[:n] == 0) and np.all(bias[2 * n :] == 0)


def test_every_consumer_runs_the_nodes_in_one_order(graph_file):
    """snnTorch's import runs the nodes in alphabetical order; Norse's in a walk from the input
    along the edges in the file's order (nirtorch's trace_execution), returning the value of
    the last node it runs: the same order, the output last. Each neuron node has one threshold
    (snnTorch's import refuses more)."""
    graph = nir.read(str(graph_file))
    succ: dict[str, list[str]] = {}
    for a, b in graph.edges:
        succ.setdefault(a, []).append(b)
    order: list[str] = []

    def walk(node: str) -> None:
        if node not in order:
            order.append(node)
            for nxt in succ.get(node, []):
                walk(nxt)

    walk(NODE_NAMES["input"])
    assert order == sorted(graph.nodes) and order[-1] == NODE_NAMES["output"]
    for name, node in graph.nodes.items():
        if type(node).__name__ in ("LIF", "CubaLIF"):
            assert np.unique(node.v_threshold).size == 1, name


def test_numpy_consumer_counts_against_golden(workload, graph_file):
    net, trains = workload
    golden = simulate_batch(net, trains, DURATION)
    ran = run_consumer("numpy", graph_file, trains, DURATION)
    errors = [rate_error(r, g) for r, g in zip(ran, golden, strict=True)]
    assert max(errors) < 0.12, errors
    for r, g in zip(ran, golden, strict=True):
        assert abs(r.cco_counts.sum() / g.cco_counts.sum() - 1) < 0.05
        assert r.tde_counts.sum() > 0


def test_without_a_refractory_stand_in_the_graph_is_far_off(workload):
    """The refractory unit is what keeps the counts near golden: NIR has no refractory period."""
    net, trains = workload
    golden = simulate_batch(net, trains[:1], DURATION)[0]
    none = run_consumer("numpy", to_standard_nir(net, refractory="none").graph, trains[:1],
                        DURATION)[0]  # fmt: skip
    assert rate_error(none, golden) > 0.5


def test_refractory_unit_holds_each_neuron_for_its_refractory_steps_when_driven_hard(workload):
    """A network driven 9x harder than its base (the charge-balanced stand-in let TDEs fire
    above 1/t_refr there): no TDE or CCO spikes within round(t_refr/dt - 1/2) steps of its
    last."""
    net, trains = workload
    hard = Network(tuple(replace(s, g_tde_trg=9 * s.g_tde_trg) for s in net.spll))
    dt = 1e-4
    r = NirNumpy(dt=dt).simulate_batch(hard, trains[:1], DURATION, record_spikes=True)[0]
    held = compensated_hold(hard.spll[0].t_tde_refr, dt)
    steps = [np.round(s / dt).astype(int) for s in r.tde_spikes + r.cco_spikes]
    assert min(np.diff(s).min() for s in steps if len(s) > 1) == held + 1
    assert r.tde_counts.max() > 0.5 * DURATION / (held + 1) / dt  # driven near the limit


@pytest.mark.parametrize("consumer", ["snntorch", "norse"])
def test_consumer_runs_the_file_spike_for_spike_like_the_numpy_executor(
    workload, graph_file, consumer
):
    """snnTorch's import_from_nir and Norse's from_nir load the exported file unchanged."""
    if not (HAS[consumer] and HAS["torch"]):
        pytest.skip(f"{consumer}/torch not installed (benchmarks/bench_nir_consumers.py)")
    net, trains = workload
    mine = run_consumer("numpy", graph_file, trains, 0.2)
    theirs = run_consumer(consumer, graph_file, trains, 0.2)
    for a, b in zip(mine, theirs, strict=True):
        np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
        np.testing.assert_array_equal(a.cco_counts, b.cco_counts)
        assert b.tde_counts.sum() > 0 and b.backend == f"nir-{consumer}"


def test_backend_runs_batches_and_records_spikes(workload):
    net, trains = workload
    backend = NirNumpy(levels=4)
    results = backend.simulate_batch(net, trains, 0.2, record_spikes=True)
    assert [r.backend for r in results] == ["nir-numpy:levels=4"] * 2
    r = results[0]
    assert [len(s) for s in r.tde_spikes] == r.tde_counts.tolist()
    assert all(np.all(np.diff(s) > 0) for s in r.cco_spikes)
    assert r.info["dt"] == 1e-4
    with pytest.raises(ValueError, match="snnTorch's NIR import steps by"):
        NirSnntorch(dt=1e-5)
    assert NirNorse(dt=1e-5).capabilities.dt == 1e-5
    for cls in (NirSnntorch, NirNorse):  # installed here, or says how to install it
        reason = cls.unavailable()
        assert reason is None or "pip install" in reason


def test_the_numpy_consumer_steps_in_the_memory_of_its_spikes(workload, graph_file):
    """run_consumer("numpy") runs step_nir step by step: the same counts and spike times
    (step k reported at (k+1) dt) as run_nir's whole output, without holding every step (a
    10-s check at 1 µs held 48 GB and was killed)."""
    import tracemalloc

    from mappings.nir.consumers import load_graph
    from mappings.nir.executor import input_steps, run_nir, step_nir

    net, trains = workload
    graph = load_graph(graph_file)
    dt, n = float(graph.metadata["dt"]), net.n_spll
    steps = np.stack([input_steps(x, 0.2, dt) for x in trains], axis=1)[:, :, None]
    dense = run_nir(graph, steps, dt)  # (T, B, 2N)
    np.testing.assert_array_equal(np.array(list(step_nir(graph, steps, dt))), dense)
    ran = run_consumer("numpy", graph_file, trains, 0.2, record_spikes=True)
    t = (np.arange(dense.shape[0]) + 1) * dt
    for b, r in enumerate(ran):
        np.testing.assert_array_equal(r.tde_counts, dense[:, b, :n].sum(0))
        np.testing.assert_array_equal(r.cco_counts, dense[:, b, n:].sum(0))
        for i in range(n):
            np.testing.assert_array_equal(r.tde_spikes[i], t[dense[:, b, i] > 0])
            np.testing.assert_array_equal(r.cco_spikes[i], t[dense[:, b, n + i] > 0])
    # 4 s of input (4e4 steps): its output alone would be 4e4 * 2 * 2N * 8 bytes (15 MB)
    long = [np.arange(0.01, 4, 0.01)] * 2
    tracemalloc.start()
    run_consumer("numpy", graph_file, long, 4.0)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 4e4 * 2 * 2 * n * 8 / 4, peak


def test_export_target_writes_graph_levels_and_instructions(workload, tmp_path):
    net, _ = workload
    files = export_standard(net, tmp_path, dt=5e-5)
    assert [f.name for f in files] == [
        "network.nir", "standard.json", "README.md", "spll_grid.py", "check_consumer.py",
        "check_counts.py", "load_consumer.py",
    ]  # fmt: skip
    # the grid rule the README's loader snippet bins input with is the model's own
    assert (tmp_path / "spll_grid.py").read_text() == Path(grid.__file__).read_text()
    assert "from spll_grid import arrival_counts, n_steps" in (tmp_path / "README.md").read_text()
    info = json.loads((tmp_path / "standard.json").read_text())
    assert info["dt"] == 5e-5 and info["gate"]["levels"] == EXPORT_LEVELS
    assert np.array(info["gate"]["thresholds_A"]).shape == (net.n_spll, EXPORT_LEVELS)
    assert float(nir.read(str(files[0])).metadata["dt"]) == 5e-5
    with pytest.raises(ValueError, match="drop --profile"):
        export_standard(net, tmp_path, profile="loihi2")


def test_a_membrane_time_constant_shorter_than_dt_is_written_as_its_exact_decay(workload):
    """tau_tde = 50 µs at dt = 100 µs: written as tau' = dt / (1 - e^(-dt/tau)) > dt, so the
    consumers' Euler decay 1 - dt/tau' is e^-2, in (0, 1), to the float32 value the file
    holds (tau' to 6e-8 of itself: the decay to (1 - e^-2) 6e-8 / e^-2 = 3.8e-7)."""
    net, trains = workload
    fast = Network((replace(net.spll[0], tau_tde=5e-5),))
    graph = to_standard_nir(fast, dt=1e-4).graph
    tau_mem = graph.nodes[NODE_NAMES["spll"]].tau_mem
    assert tau_mem[0] == np.float32(tau_mem[0])
    np.testing.assert_allclose(1 - 1e-4 / tau_mem[0], np.exp(-2.0), rtol=4e-7)
    assert run_consumer("numpy", graph, trains[:1], 0.1)[0].cco_counts.sum() > 0


def test_a_synaptic_kick_delivers_its_exact_charge_whatever_tau_syn_over_dt():
    """tau_tde_trg = 50 µs at dt = 100 µs (once refused: a current held at its step-start
    value would charge 2.31 times as much): the consumers add the synapse's value of each step
    to the membrane, so a kick's weight summed over its decay, w / (1 - e^(-dt/tau)), must be
    the continuous-time charge g tau / (C v_thr) (a membrane that does not leak)."""
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 1))
    s = replace(net.spll[0], tau_tde_trg=5e-5, tau_tde=1e3, tau_cco_syn=5e-5, tau_cco=1e3)
    built = to_standard_nir(Network((s,)), GateOptions(2), dt=1e-4)
    w = built.graph.nodes[NODE_NAMES["synapses"]].weight
    kept = 1 - np.exp(-1e-4 / 5e-5)
    # AND neuron k of the one sPLL -> its TDE (row 0); the TDE's relay (row K) -> its CCO (1)
    np.testing.assert_allclose(
        w[0, :2] / kept,
        s.g_tde_trg * built.gate.increments[0] * 5e-5 / (s.c_tde * s.v_tde_thr),
        rtol=1e-6,
    )
    np.testing.assert_allclose(w[1, 2] / kept, s.g_cco * 5e-5 / (s.c_cco * s.v_cco_thr), rtol=1e-6)


def test_the_offset_drives_each_cco_from_the_first_step():
    """The offset reaches the CCO through its synapse, which starts at 0; the start pulse tops it
    up in step 1, so a free-running CCO keeps golden's phase: without it the slowest CCO of
    vibtac-time-scaled-peak (tau_cco_syn 10 ms) first fired at 22.8 ms instead of 13.5 ms, and
    every spike after stayed that far behind."""
    net = NetworkConfig.preset("vibtac-time-scaled-peak").build()
    two = Network((net.spll[0], net.spll[49]))  # tau_cco_syn 10 and 2.1 ms
    dt, silent = 2e-5, [np.array([])]
    golden = simulate_batch(two, silent, 0.2, record_spikes=True)[0]
    ran = NirNumpy(dt=dt).simulate_batch(two, silent, 0.2, record_spikes=True)[0]
    for mine, ref in zip(ran.cco_spikes, golden.cco_spikes, strict=True):
        assert len(mine) == len(ref) > 10, (len(mine), len(ref))
        # The first on the end of golden's step; the rest drift by the whole-step hold's
        # fraction of a step per period (14 ms, about 700 steps, on sPLL 0).
        assert 0 <= mine[0] - ref[0] <= dt, (mine[0], ref[0])
        np.testing.assert_allclose(mine, ref, atol=5 * dt)


def test_the_compensated_hold_restarts_fast_tdes_near_the_golden_time():
    """Two fast sPLLs of biotac-time-scaled-pacinian (t_tde_refr 157 and 108 µs, TDEs firing
    every few steps): held round(t_refr / dt) steps after a spike on the step's end, each cycle
    ran half a step slow (TDE-rate error 16.7 % at 20 µs, 43 % at 100 µs); held
    round(t_refr / dt - 1/2) steps, 10.2 % and 27.7 %."""
    np.testing.assert_array_equal(
        compensated_hold(np.array([0.74, 0.75, 1.52, 2.0, 10.0]) * 1e-4, 1e-4), [0, 0, 1, 2, 10]
    )
    net = NetworkConfig.preset("biotac-time-scaled-pacinian").build()
    fast = Network((net.spll[35], net.spll[42]))
    train = [poisson_train(300.0, 1.0, 0)]
    golden = simulate_batch(fast, train, 1.0)[0]
    for dt, limit in ((2e-5, 0.13), (1e-4, 0.33)):
        ran = NirNumpy(dt=dt).simulate_batch(fast, train, 1.0)[0]
        assert rate_error(ran, golden) < limit, (dt, ran.tde_counts, golden.tde_counts)


def test_networks_it_cannot_represent_are_refused_by_name(workload):
    net, _ = workload
    no_fac = Network((replace(net.spll[0], g_tde_fac=0.0),))
    with pytest.raises(ValueError, match="g_tde_fac .* standard"):
        to_standard_nir(no_fac)
    with pytest.raises(ValueError, match="refractory"):
        to_standard_nir(net, refractory="hold")
