"""The golden model against an independent integrator (scipy solve_ivp with event detection)."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spll_hw import Network, SpllParams, simulate

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train
from .reference_integrator import reference_spll

TOLERANCE = 1e-7  # seconds, per spike


def log_uniform(lo: float, hi: float):
    return st.floats(np.log(lo), np.log(hi)).map(np.exp)


# The search space of the thesis's Table 5, plus free frequency and input rate.
spll_draws = st.fixed_dictionaries(
    {
        "tau_cco_syn": log_uniform(0.005, 0.2),
        "tau_cco": log_uniform(0.05, 0.5),
        "tau_tde_trg": log_uniform(0.0005, 0.02),
        "tau_tde_fac": log_uniform(0.0005, 0.02),
        "tau_tde": log_uniform(0.001, 0.1),
        "g_cco": log_uniform(0.1, 10),
        "g_tde_trg": log_uniform(0.1, 5),
        "g_tde_fac": log_uniform(500, 100_000),
    }
)


def assert_same_spikes(golden: np.ndarray, reference: np.ndarray, what: str) -> None:
    assert len(golden) == len(reference), f"{what}: {len(golden)} vs {len(reference)} spikes"
    if len(golden):
        worst = np.max(np.abs(golden - reference))
        assert worst < TOLERANCE, f"{what}: spike times differ by up to {worst:.3g} s"


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    values=spll_draws,
    free_freq=st.floats(30, 300),
    rate=st.floats(20, 400),
    seed=st.integers(0, 2**32 - 1),
)
def test_random_parameters_agree_with_solve_ivp(values, free_freq, rate, seed):
    params = SpllParams(**values).with_free_frequency(free_freq)
    inputs = poisson_train(rate, 0.25, seed)
    result = simulate(Network.single(params), inputs, 0.25)
    tde_ref, cco_ref = reference_spll(params, inputs, 0.25)
    assert_same_spikes(result.cco_spikes[0], cco_ref, "CCO")
    assert_same_spikes(result.tde_spikes[0], tde_ref, "TDE")


def test_degenerate_time_constants_agree_with_solve_ivp():
    """tau_syn == tau for both neurons: the thesis's singular case."""
    params = SpllParams(
        tau_cco_syn=0.02, tau_cco=0.02, tau_tde_trg=0.004, tau_tde_fac=0.01, tau_tde=0.004,
        g_cco=5.0, g_tde_trg=1.0, g_tde_fac=3000.0,
    ).with_free_frequency(80.0)  # fmt: skip
    inputs = poisson_train(150, 0.5, seed=3)
    result = simulate(params, inputs, 0.5)
    tde_ref, cco_ref = reference_spll(params, inputs, 0.5)
    assert len(tde_ref) > 5, "the case must exercise the TDE"
    assert_same_spikes(result.cco_spikes[0], cco_ref, "CCO")
    assert_same_spikes(result.tde_spikes[0], tde_ref, "TDE")


def test_thesis_parameters_agree_with_solve_ivp():
    params = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(200.0)
    inputs = poisson_train(300, 0.4, seed=0)
    result = simulate(params, inputs, 0.4)
    tde_ref, cco_ref = reference_spll(params, inputs, 0.4)
    assert len(tde_ref) >= 3, "the case must exercise the TDE"
    assert_same_spikes(result.cco_spikes[0], cco_ref, "CCO")
    assert_same_spikes(result.tde_spikes[0], tde_ref, "TDE")


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    values=spll_draws,
    free_freq=st.floats(30, 300),
    rate=st.floats(100, 400),
    levels=st.integers(1, 8),
    seed=st.integers(0, 2**32 - 1),
)
def test_the_k_level_gate_agrees_with_solve_ivp(values, free_freq, rate, levels, seed):
    """The standard-neuron sPLL's staircase gate, applied at the exact CCO spike time."""
    from spll_hw.construction import gate_levels

    params = SpllParams(**values).with_free_frequency(free_freq)
    gate = gate_levels(Network.single(params), levels, "uniform", input_rate=rate)
    inputs = poisson_train(rate, 0.25, seed)
    result = simulate(Network.single(params), inputs, 0.25, gate=gate)
    tde_ref, cco_ref = reference_spll(params, inputs, 0.25, gate=lambda x: gate(np.array([x]))[0])
    assert_same_spikes(result.cco_spikes[0], cco_ref, "CCO")
    assert_same_spikes(result.tde_spikes[0], tde_ref, "TDE")


def test_a_gate_changes_what_the_integrator_and_engine_both_compute():
    """The gated case is not the golden one in disguise: a 2-level gate moves TDE spikes."""
    from spll_hw.construction import gate_levels

    params = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(200.0)
    gate = gate_levels(Network.single(params), 2, "uniform")
    inputs = poisson_train(300, 0.4, seed=0)
    gated = simulate(params, inputs, 0.4, gate=gate)
    golden = simulate(params, inputs, 0.4)
    tde_ref, _ = reference_spll(params, inputs, 0.4, gate=lambda x: gate(np.array([x]))[0])
    assert len(tde_ref) >= 3, "the case must exercise the TDE"
    assert_same_spikes(gated.tde_spikes[0], tde_ref, "TDE")
    assert not np.array_equal(gated.tde_spikes[0], golden.tde_spikes[0])
