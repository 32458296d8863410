"""The standard NIR graph in the float32 values its file holds (mappings/nir/standard.py,
``hold_weights``): a refractory unit's hold leaves its neuron's synapse as it found it, so a
free-running CCO at 1 µs keeps golden's period (issue 59: the former weights left up to 4e-5
thresholds in a CCO's synapse after each spike, and vibtac-time-scaled-peak's check was 57.9 %
off golden at 1 µs instead of 9.3 %)."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import Network, simulate_batch
from spll_hw.config import NetworkConfig
from spll_hw.construction.gate import gate_layout, refractory_timers

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir.consumers import run_consumer  # noqa: E402
from mappings.nir.standard import NODE_NAMES, to_standard_nir  # noqa: E402

DT = 1e-6


@pytest.fixture(scope="module")
def slowest():
    """sPLL 0 of vibtac-time-scaled-peak (70.5 Hz; tau_cco_syn 10 ms, the CCO's offset 8e-5
    thresholds a step at 1 µs) alone, and its graph at 1 µs."""
    net = NetworkConfig.preset("vibtac-time-scaled-peak").build()
    one = Network((net.spll[0],))
    return one, to_standard_nir(one, dt=DT)


def test_a_hold_leaves_the_synapse_as_it_found_it_in_float32(slowest):
    """The TDE's and CCO's synapse stepped in float64 (Norse's loader, spll-hw's executor) with
    the file's float32 weights and time constants through one hold (709 steps at 1 µs): the
    held current stays near 2 thresholds and what is left after it is under 1e-9 thresholds
    (rounding timer b's weight to the hold grid alone leaves up to 1.2e-7; the former weights
    2 (1-a), 2, -2 (1-a) left 3.8e-5 in the CCO's)."""
    net, built = slowest
    graph = built.graph
    w = np.asarray(graph.nodes[NODE_NAMES["synapses"]].weight)
    a = DT / np.asarray(graph.nodes[NODE_NAMES["spll"]].tau_syn)[:2]
    assert np.all(w == w.astype(np.float32)) and np.all(a < 1e-2)
    layout = gate_layout(1, built.gate.n_levels)
    steps = refractory_timers(net, DT).steps
    assert list(steps) == [709, 709]
    for unit, relay in enumerate((layout.relay_tde[0], layout.relay_cco[0])):
        relay_w, a_w, b_w = w[unit, [relay, layout.refr_a[unit], layout.refr_b[unit]]]
        current, held = 0.0, []
        for step in range(1, steps[unit] + 2):  # relay in step 1, timer a 1..steps, b 1..steps+1
            x = (relay_w if step == 1 else 0.0) + (a_w if step <= steps[unit] else 0.0) + b_w
            current = (1 - a[unit]) * current + x
            held.append(current)
        assert min(held[:-1]) > 1.9, (unit, min(held[:-1]))
        assert abs(held[-1]) < 1e-9, (unit, held[-1])


def test_a_free_running_cco_keeps_goldens_period_at_1us(slowest):
    """The CCO of sPLL 0 without input, its graph's float32 values run by spll-hw's executor:
    its spikes within 3 steps of golden's (the former weights made its second spike 2.6 ms
    early, 25.05 ms against golden's 27.66, and every period 27 % short)."""
    net, built = slowest
    silent, duration = [np.array([])], 0.03
    golden = simulate_batch(net, silent, duration, record_spikes=True)[0].cco_spikes[0]
    mine = run_consumer("numpy", built.graph, silent, duration, record_spikes=True)[0]
    assert len(mine.cco_spikes[0]) == len(golden) == 2, (mine.cco_spikes[0], golden)
    np.testing.assert_allclose(mine.cco_spikes[0], golden, atol=3 * DT)


def test_hold_weights_of_a_large_group_are_each_synapses_own_in_bounded_memory():
    """hold_weights searches HOLD_ROWS synapses at a time: 4000 synapses (a group of 2000 sPLLs)
    get the weights each gets alone, and the search's arrays stay within 100 MB (all at once:
    5 arrays of 4000 x 4097 float64, about 650 MB)."""
    import tracemalloc

    from mappings.nir.standard import HOLD_ROWS, hold_weights

    rng = np.random.default_rng(3)
    n = 4000
    a = rng.uniform(1e-4, 0.2, n)
    steps = rng.integers(0, 800, n)
    tracemalloc.start()
    got = hold_weights(a, steps)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 100e6, f"hold_weights of {n} synapses peaked at {peak / 1e6:.0f} MB"
    for i in (0, HOLD_ROWS - 1, HOLD_ROWS, n // 2, n - 1):
        alone = hold_weights(a[i : i + 1], steps[i : i + 1])
        for want, have in zip(alone, got, strict=True):
            assert have[i] == want[0], i
