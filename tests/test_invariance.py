"""Invariances of the golden model: time scaling, split-and-resume, batching, ordering, noise."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from spll_hw import Network, network_frequencies, simulate, simulate_batch

from .conftest import BIOTAC_TIME_SCALED_TOUCHSIM, VIBTAC_VARY_OFFSET_LIF, poisson_train


@pytest.fixture(scope="module")
def network() -> Network:
    return Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 8))


@pytest.mark.parametrize("scale", [3.7, 0.01, 250.0])
def test_time_scaling_scales_every_spike_time(network, scale):
    inputs = poisson_train(300, 1.0, seed=1)
    base = simulate(network, inputs, 1.0)
    scaled_net = Network(tuple(p.time_scaled(scale) for p in network.spll))
    scaled = simulate(scaled_net, inputs / scale, 1.0 / scale)
    np.testing.assert_array_equal(scaled.tde_counts, base.tde_counts)
    assert base.tde_counts.sum() > 100
    for a, b in zip(
        scaled.tde_spikes + scaled.cco_spikes, base.tde_spikes + base.cco_spikes, strict=True
    ):
        np.testing.assert_allclose(a * scale, b, rtol=1e-10, atol=1e-12)


def test_split_and_resume_equals_uninterrupted_run_bit_for_bit(network):
    inputs = poisson_train(300, 2.0, seed=2)
    full = simulate(network, inputs, 2.0)
    split_at = 0.8137
    first = simulate(network, inputs[inputs <= split_at], split_at)
    # The saved state survives a pickle round trip (e.g. to another process).
    state = pickle.loads(pickle.dumps(first.final_state))
    second = simulate(network, inputs[inputs > split_at], 2.0, state=state)
    assert second.duration == pytest.approx(2.0 - split_at)
    for i in range(network.n_spll):
        np.testing.assert_array_equal(
            np.concatenate([first.tde_spikes[i], second.tde_spikes[i]]), full.tde_spikes[i]
        )
        np.testing.assert_array_equal(
            np.concatenate([first.cco_spikes[i], second.cco_spikes[i]]), full.cco_spikes[i]
        )
    np.testing.assert_array_equal(first.tde_counts + second.tde_counts, full.tde_counts)


def test_batch_equals_one_by_one_and_is_thread_count_independent(network):
    inputs = [poisson_train(rate, 1.0, seed) for seed, rate in enumerate([50, 150, 300, 600, 0])]
    single = [simulate(network, x, 1.0) for x in inputs]
    for threads in (1, 2):
        batch = simulate_batch(network, inputs, 1.0, record_spikes=True, threads=threads)
        for a, b in zip(batch, single, strict=True):
            np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
            for x, y in zip(a.tde_spikes, b.tde_spikes, strict=True):
                np.testing.assert_array_equal(x, y)
    counts_only = simulate_batch(network, inputs, 1.0)
    assert counts_only[0].tde_spikes is None
    np.testing.assert_array_equal(counts_only[3].tde_rates, single[3].tde_counts / 1.0)


def test_permuting_splls_permutes_outputs(network):
    inputs = poisson_train(250, 1.0, seed=4)
    order = np.random.default_rng(0).permutation(network.n_spll)
    permuted = Network(tuple(network.spll[i] for i in order))
    a = simulate(network, inputs, 1.0)
    b = simulate(permuted, inputs, 1.0)
    np.testing.assert_array_equal(b.tde_counts, a.tde_counts[order])


def test_phase_noise_is_seeded_and_changes_spikes(network):
    inputs = poisson_train(300, 1.0, seed=5)
    a = simulate_batch(network, [inputs] * 3, 1.0, noise_sigma=5e-4, seed=7)
    b = simulate_batch(network, [inputs] * 3, 1.0, noise_sigma=5e-4, seed=7, threads=1)
    c = simulate_batch(network, [inputs] * 3, 1.0, noise_sigma=5e-4, seed=8)
    clean = simulate(network, inputs, 1.0)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x.tde_counts, y.tde_counts)
    assert not np.array_equal(a[0].tde_counts, a[1].tde_counts), "each sample has its own noise"
    assert not np.array_equal(a[0].tde_counts, c[0].tde_counts)
    assert not np.array_equal(a[0].tde_counts, clean.tde_counts)
    single = simulate(network, inputs, 1.0, noise_sigma=5e-4, seed=7)
    again = simulate(network, inputs, 1.0, noise_sigma=5e-4, seed=7)
    np.testing.assert_array_equal(single.tde_counts, again.tde_counts)


def test_time_scaled_layout_runs_the_same_spll_faster():
    """sPLL i of a time-scaled network is the base sPLL with time divided by f_i / f_ref."""
    freqs = network_frequencies(44.0, 668.0, 5, beta=10.0)
    net = Network.time_scaled(BIOTAC_TIME_SCALED_TOUCHSIM, freqs, reference_frequency=50.0)
    ref = Network.single(BIOTAC_TIME_SCALED_TOUCHSIM, free_frequency=50.0)
    base_inputs = poisson_train(60, 2.0, seed=6)
    base = simulate(ref, base_inputs, 2.0)
    for i, f in enumerate(freqs):
        s = f / 50.0
        one = Network((net.spll[i],))
        out = simulate(one, base_inputs / s, 2.0 / s)
        assert out.tde_counts[0] == base.tde_counts[0]
        np.testing.assert_allclose(out.cco_spikes[0] * s, base.cco_spikes[0], rtol=1e-10)
