"""Stiff and extreme parameters: finite results, no crash, invariants hold."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest

from spll_hw import Network, SpllParams, simulate

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

TIME_CONSTANTS = [1e-6, 1e-3, 10.0]
GAINS = [1e-3, 1.0, 1e6]


def check_invariants(result, params_list, duration):
    for i, p in enumerate(params_list):
        for spikes, refr in (
            (result.tde_spikes[i], p.t_tde_refr),
            (result.cco_spikes[i], p.t_cco_refr),
        ):
            assert np.all(np.isfinite(spikes))
            assert np.all((spikes >= 0) & (spikes <= duration))
            # Successive spikes of one neuron are at least a refractory period apart.
            assert np.all(np.diff(spikes) >= refr * (1 - 1e-9))
            assert len(spikes) <= duration / refr + 1


@pytest.mark.parametrize("tau_syn,tau", list(itertools.product(TIME_CONSTANTS, repeat=2)))
def test_stiff_time_constant_ratios(tau_syn, tau):
    """Every pair of synapse/membrane time constants from 1e-6 to 10 s, with every gain range."""
    splls = []
    for g_fac, g_trg, g_cco in itertools.product(GAINS, repeat=3):
        p = SpllParams(
            tau_cco_syn=tau_syn, tau_cco=tau, tau_tde_trg=tau_syn, tau_tde_fac=tau_syn,
            tau_tde=tau, g_cco=g_cco, g_tde_trg=g_trg, g_tde_fac=g_fac,
        )  # fmt: skip
        # Offset at twice the rheobase: charge time tau ln 2, reachable for every tau.
        splls.append(replace(p, i_cco_offset=2.0 / tau))
    inputs = poisson_train(800, 0.5, seed=0)  # close to 1 / t_refr
    result = simulate(Network(tuple(splls)), inputs, 0.5)
    check_invariants(result, splls, 0.5)
    # Excitatory TDE input can only advance CCO spikes: at least the free-running count.
    first = tau * np.log(2.0)
    free_count = 0 if first > 0.5 else 1 + int((0.5 - first) * splls[0].free_frequency())
    assert np.all(result.cco_counts >= free_count)
    assert free_count > 0 or tau == 10.0


def test_input_at_the_refractory_limit_and_simultaneous_spikes():
    p = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(500.0)
    inputs = np.arange(0, 1.0, p.t_tde_refr)  # 1 / t_refr
    doubled = np.sort(np.concatenate([inputs, inputs]))  # pairs of simultaneous input spikes
    for x in (inputs, doubled):
        result = simulate(p, x, 1.0)
        check_invariants(result, [p], 1.0)
    # A double spike adds the gain twice: more facilitation, at least as many TDE spikes.
    assert simulate(p, doubled, 1.0).tde_counts[0] >= simulate(p, inputs, 1.0).tde_counts[0]


def test_zero_input_never_fires_the_tde():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [40.0, 400.0, 900.0])
    result = simulate(net, [], 3.0)
    assert np.all(result.tde_counts == 0)
    np.testing.assert_allclose(result.cco_rates, [40.0, 400.0, 900.0], rtol=2e-3)


def test_thousand_second_run_keeps_full_precision():
    """Local state: after 1000 s the CCO's 40 000th spike is where k periods put it."""
    p = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(40.0)
    result = simulate(p, [], 1000.0)
    cco = result.cco_spikes[0]
    assert len(cco) == 40_000
    period = 1.0 / 40.0
    predicted = cco[0] + period * np.arange(len(cco))
    assert np.max(np.abs(cco - predicted)) < 1e-9


def test_thousand_second_run_with_input_is_finite():
    p = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(300.0)
    inputs = poisson_train(300, 1000.0, seed=9)
    result = simulate(p, inputs, 1000.0)
    check_invariants(result, [p], 1000.0)
    assert result.tde_counts[0] > 1000
    # The run's first seconds are exactly those of a short run: nothing depends on the end.
    short = simulate(p, inputs[inputs <= 2.0], 2.0)
    np.testing.assert_array_equal(result.tde_spikes[0][: short.tde_counts[0]], short.tde_spikes[0])


def test_zero_refractory_period_with_huge_gain_is_an_error_not_a_hang():
    p = SpllParams(
        tau_cco_syn=1.0, tau_cco=1.0, tau_tde_trg=10.0, tau_tde_fac=10.0, tau_tde=10.0,
        g_cco=1.0, g_tde_trg=1e6, g_tde_fac=1e6, t_tde_refr=0.0, t_cco_refr=0.0,
    ).with_free_frequency(1000.0)  # fmt: skip
    with pytest.raises(ValueError, match="faster than the simulation can resolve"):
        simulate(p, [0.001], 0.01, max_events=100_000)
