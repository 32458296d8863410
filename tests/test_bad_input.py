"""Bad input raises ValueError naming the problem; never a Rust panic or a crash."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import (
    Network,
    SpllParams,
    _engine,
    network_frequencies,
    offset_for_frequency,
    simulate,
    simulate_batch,
)

from .conftest import VIBTAC_VARY_OFFSET_LIF

P = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(100.0)


@pytest.mark.parametrize(
    "inputs,message",
    [
        ([0.1, float("nan")], "input spike 1 is not a finite time"),
        ([0.1, float("inf")], "not a finite time"),
        ([-0.01, 0.2], "negative time"),
        ([0.3, 0.2], "must be sorted"),
    ],
)
def test_bad_spike_times(inputs, message):
    with pytest.raises(ValueError, match=message):
        simulate(P, inputs, 1.0)
    with pytest.raises(ValueError, match=f"sample 1: .*{message}"):
        simulate_batch(P, [[0.1], inputs], 1.0)


@pytest.mark.parametrize("duration", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_duration(duration):
    with pytest.raises(ValueError, match="duration"):
        simulate(P, [0.1], duration)


def test_bad_shapes_and_noise():
    with pytest.raises(ValueError, match="1-D"):
        simulate(P, [[0.1, 0.2]], 1.0)
    with pytest.raises(ValueError, match="noise_sigma"):
        simulate(P, [0.1], 1.0, noise_sigma=-1e-3)
    with pytest.raises(ValueError, match="threads"):
        simulate_batch(P, [[0.1]], 1.0, threads=0)
    with pytest.raises(ValueError, match="probe times must be sorted"):
        simulate(P, [0.1], 1.0, probe_times=[0.5, 0.2])


@pytest.mark.parametrize("name", ["tau_cco", "tau_tde_fac", "c_tde", "v_cco_thr"])
@pytest.mark.parametrize("value", [0.0, -1e-3, float("nan")])
def test_non_positive_or_nan_parameters(name, value):
    values = VIBTAC_VARY_OFFSET_LIF.to_dict() | {name: value}
    with pytest.raises(ValueError, match=name):
        SpllParams(**values)


@pytest.mark.parametrize("column", range(15))
def test_engine_rejects_bad_matrix_rows_itself(column):
    """The Rust core validates on its own: no panic even when the Python layer is bypassed."""
    matrix = Network.single(P).matrix()
    matrix[0, column] = -1.0
    with pytest.raises(ValueError, match=_engine.PARAM_NAMES[column]):
        _engine.simulate(matrix, np.array([0.1]), 1.0, True)
    matrix[0, column] = np.nan
    with pytest.raises(ValueError, match="must be finite"):
        _engine.simulate(matrix, np.array([0.1]), 1.0, True)


def test_engine_rejects_malformed_arrays():
    with pytest.raises(ValueError, match="15 columns"):
        _engine.simulate(np.zeros((2, 3)), np.array([0.1]), 1.0, True)
    with pytest.raises(ValueError, match="contiguous"):
        _engine.simulate(Network.single(P).matrix(), np.arange(10.0)[::2], 11.0, True)
    with pytest.raises(ValueError, match="state must have shape"):
        _engine.simulate(Network.single(P).matrix(), np.array([0.1]), 1.0, True, np.zeros((1, 3)))


def test_unreachable_frequencies():
    with pytest.raises(ValueError, match="unreachable"):
        offset_for_frequency(1000.0, tau=0.1, t_refr=1e-3)
    with pytest.raises(ValueError, match="unreachable"):
        Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [100.0, 2000.0])
    with pytest.raises(ValueError, match="cannot be set with membrane time constant"):
        offset_for_frequency(10.0, tau=1e-6)
    with pytest.raises(ValueError, match="> 0 Hz"):
        offset_for_frequency(0.0, tau=0.1)


def test_resume_rejects_inconsistent_state_and_inputs():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(60, 600, 3))
    first = simulate(net, [0.1, 0.2], 0.5)
    with pytest.raises(ValueError, match="not after the resumed state's time"):
        simulate(net, [0.4, 0.6], 1.0, state=first.final_state)
    with pytest.raises(ValueError, match="run must end after it starts"):
        simulate(net, [], 0.3, state=first.final_state)
    other = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [60.0, 70.0])
    with pytest.raises(ValueError, match="saved state has 3 sPLLs but the network has 2"):
        simulate(other, [0.6], 1.0, state=first.final_state)


def test_params_from_dict_names_unknown_and_missing_keys():
    with pytest.raises(ValueError, match=r"unknown sPLL parameter\(s\) \['tau_cc'\]"):
        SpllParams.from_dict(VIBTAC_VARY_OFFSET_LIF.to_dict() | {"tau_cc": 1.0})
    values = VIBTAC_VARY_OFFSET_LIF.to_dict()
    del values["g_cco"]
    with pytest.raises(ValueError, match=r"missing sPLL parameter\(s\) \['g_cco'\]"):
        SpllParams.from_dict(values, source="best.toml")
