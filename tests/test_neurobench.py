"""NeuroBench's metrics counted natively (spll_hw.harness.neurobench), checked by hand on a
2-sPLL network and against the chip's exact event counts.

NeuroBench's own ``Benchmark`` is not run here: it needs torch, whose PyPI wheel alone is
539 MB (4 GB with its CUDA libraries, docs/testing.md), so these hand counts are the proof."""

from __future__ import annotations

import numpy as np
import pytest

import quantize
from quantize.footprint import parameter_bits, storage_bits
from spll_hw import Network, SpllParams, chips, network_frequencies, simulate
from spll_hw.harness import neurobench as nb

BASE = SpllParams(
    tau_cco_syn=7.50e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=3000.0,
)  # fmt: skip
TWO = Network.vary_offset(BASE, network_frequencies(80.0, 400.0, 2))


def test_two_spll_network_by_hand():
    """2 sPLLs, 1 ms windows at dt = 0.1 ms (K = 10 steps). Sample 1: 3 input spikes, TDE
    spikes 1 + 1, CCO spikes 2 + 3; sample 2: 1 input spike, no TDE spike, 1 CCO spike."""
    m = nb.metrics(TWO, [3, 1], [2, 0], [5, 1], window=1e-3, dt=1e-4)
    # weights: input -> TDE 2 x 1, CCO -> TDE 2 x 2, TDE -> CCO 2 x 2 = 10, 6 of them non-zero
    assert m.connection_sparsity == pytest.approx(1 - 6 / 10)
    assert m.dense_synops == 10 * 10  # every weight at every step
    assert m.effective_acs == ((2 * 3 + 2) + (2 * 1 + 0)) / 2  # n per input + one per TDE spike
    assert m.gate_macs == (5 + 1) / 2  # one per CCO spike
    assert m.activation_sparsity == pytest.approx(1 - ((2 + 5) + (0 + 1)) / 2 / (4 * 10))
    assert m.activation_exact  # refractory 1 ms >= dt: no neuron spikes twice in a step
    assert m.neuron_updates == 4 * 10
    assert m.footprint == 2 * (15 + 7) * 4  # float32 parameters and state
    assert m.widths == "float32" and m.dt_source == "profile" and m.samples == 2
    assert m.time_to_decision == 1e-3
    slow = nb.metrics(TWO, [3], [2], [5], window=1e-3, dt=None, time_on_chip=2.5e-3)
    assert slow.dt == nb.REFERENCE_DT and slow.dt_source == "reference"
    assert slow.dense_synops == 100 * 10 and slow.time_to_decision == 2.5e-3


def test_activation_sparsity_is_a_bound_when_a_neuron_can_fire_twice_in_a_step():
    m = nb.metrics(TWO, [3], [2], [5], window=1e-3, dt=2e-3)  # dt > 1 ms refractory
    assert not m.activation_exact and "≥" in nb.markdown([("a", "b", m)])


def test_metrics_need_one_count_per_sample():
    with pytest.raises(ValueError, match="one value per sample"):
        nb.metrics(TWO, [3, 1], [2], [5, 1], window=1e-3)


def test_loihi2_word_widths_by_hand():
    """loihi2: 5 decays x 12 bits, 2 weights x (8 + 4 exponent bits for 0..13), trigger 8 + 5
    (shift 0..24), no current shifts (0..0), bias 13 + 3, 2 refractory x 8, 2 thresholds x 17;
    state 5 words x 24 + 2 counters x 8."""
    profile = quantize.load_profile("loihi2")
    params = 5 * 12 + 2 * (8 + 4) + (8 + 5) + 0 + (13 + 3) + 2 * 8 + 2 * 17
    assert storage_bits(profile) == (params, 5 * 24 + 2 * 8) == (163, 136)
    assert set(parameter_bits(profile)) == set(quantize.FIXED_PARAM_NAMES)
    assert storage_bits(quantize.load_profile("analog")) is None
    info = chips.describe("loihi2")
    assert info.storage_bits == (163, 136)
    m = nb.metrics(TWO, [3], [2], [5], window=1e-3, dt=info.dt, storage_bits=info.storage_bits,
                   widths="loihi2")  # fmt: skip
    assert m.footprint == 2 * (163 + 136) / 8 and m.widths == "loihi2"


def test_counts_from_a_run_agree_with_the_chip_and_with_the_spike_times():
    """On a golden run: effective ACs are the chip's input and feedback deliveries, gate MACs
    its trigger deliveries; activation sparsity from counts equals the one from the spike
    times binned into loihi2's steps (no neuron fires twice in one step)."""
    spikes = np.sort(np.random.default_rng(0).uniform(0, 0.2, 80))
    result = simulate(TWO, spikes, 0.2)
    info = chips.describe("loihi2")
    m = nb.from_results(TWO, [result], 0.2, info)
    counts = chips.cost(chips.OnChip(TWO, "loihi2"), result).detail.counts
    assert result.cco_counts.sum() > 0 and result.tde_counts.sum() > 0
    assert m.effective_acs == counts.input_deliveries + counts.feedback_deliveries
    assert m.gate_macs == counts.trigger_deliveries
    steps = round(0.2 / info.dt)
    active = sum(
        np.unique(np.ceil(np.asarray(t) / info.dt - 1e-9)).size
        for t in (*result.tde_spikes, *result.cco_spikes)
    )
    assert m.activation_sparsity == pytest.approx(1 - active / (2 * 2 * steps))
    assert m.dt == 1e-5 and m.footprint == 2 * 299 / 8
