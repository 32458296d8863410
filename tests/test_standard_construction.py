"""The standard-neuron sPLL (mappings/standard): the K-level gate and its fine-clocked reference."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from mappings.standard import Gate, gate_levels
from mappings.standard.construction import _stationary_samples
from mappings.standard.reference import simulate_reference
from spll_hw import Network, network_frequencies, simulate_batch
from spll_hw.harness.metrics import rate_error

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

DURATION = 0.3


@pytest.fixture(scope="module")
def small():
    """10 sPLLs of the reference workload's network and two 300 Hz Poisson samples."""
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 10))
    trains = [poisson_train(300.0, DURATION, seed) for seed in (0, 1)]
    return net, trains


@pytest.mark.parametrize("placement", ["uniform", "quantile"])
def test_gate_levels_are_increasing_positive_and_scale_with_g_fac(small, placement):
    net, _ = small
    gate = gate_levels(net, 8, placement)
    assert gate.thresholds.shape == gate.increments.shape == (10, 8)
    assert np.all(np.diff(gate.thresholds, axis=1) > 0)
    assert np.all(gate.increments > 0)
    doubled = Network(tuple(replace(p, g_tde_fac=2 * p.g_tde_fac) for p in net.spll))
    np.testing.assert_allclose(gate_levels(doubled, 8, placement).thresholds, 2 * gate.thresholds)


@pytest.mark.parametrize("placement", ["uniform", "quantile"])
def test_staircase_error_falls_with_levels(small, placement):
    net, _ = small
    g_fac = VIBTAC_VARY_OFFSET_LIF.g_tde_fac
    x = g_fac * _stationary_samples(300.0 * VIBTAC_VARY_OFFSET_LIF.tau_tde_fac)[::50]
    errors = []
    for k in (2, 4, 8, 16):
        q = gate_levels(net, k, placement)(x, np.zeros(x.size, dtype=int))
        errors.append(np.mean(np.abs(q - x)) / np.mean(x))
    assert all(b < a for a, b in zip(errors, errors[1:], strict=False)), errors
    assert errors[-1] < 0.1


def test_reference_with_golden_product_converges_to_golden(small):
    net, trains = small
    golden = simulate_batch(net, trains, DURATION)
    coarse, fine = (
        simulate_reference(net, trains, DURATION, [None], dt=dt)[0] for dt in (4e-5, 5e-6)
    )
    err_coarse = np.mean([rate_error(r, g) for r, g in zip(coarse, golden, strict=True)])
    err_fine = np.mean([rate_error(r, g) for r, g in zip(fine, golden, strict=True)])
    assert err_fine < err_coarse
    assert err_fine < 0.04
    for r, g in zip(fine, golden, strict=True):
        np.testing.assert_allclose(r.cco_counts, g.cco_counts, atol=2)


def test_reference_gate_error_falls_with_levels(small):
    net, trains = small
    gates = [None] + [gate_levels(net, k, "uniform") for k in (2, 16)]
    product, two, sixteen = simulate_reference(net, trains, DURATION, gates, dt=1e-5)
    err2 = np.mean([rate_error(r, p) for r, p in zip(two, product, strict=True)])
    err16 = np.mean([rate_error(r, p) for r, p in zip(sixteen, product, strict=True)])
    assert err16 < err2
    assert err2 > 0.03  # two levels are a coarse multiplier ...
    assert err16 < 0.03  # ... sixteen a fine one
    assert two[0].info["gate_levels"] == 2 and product[0].info["gate_levels"] == 0


def test_gate_refuses_what_it_cannot_place(small):
    net, _ = small
    with pytest.raises(ValueError, match="g_tde_fac"):
        gate_levels(Network((replace(net.spll[0], g_tde_fac=0.0),)), 4)
    with pytest.raises(ValueError, match="K must be in"):
        gate_levels(net, 0)
    with pytest.raises(ValueError, match="placement"):
        gate_levels(net, 4, "log")
    with pytest.raises(ValueError, match="input_rate"):
        gate_levels(net, 4, input_rate=float("nan"))
    with pytest.raises(ValueError, match="strictly increasing"):
        Gate(np.array([[2.0, 1.0]]), np.ones((1, 2)))
