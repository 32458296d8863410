"""The golden model against closed-form solutions of single synapses and neurons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spll_hw import SpllParams, free_frequency, offset_for_frequency, simulate

from .conftest import VIBTAC_VARY_OFFSET_LIF


@pytest.mark.parametrize("frequency", [30.0, 56.2, 300.0, 668.0, 950.0])
def test_free_running_period_equals_equation_6(frequency):
    params = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(frequency)
    result = simulate(params, [], 2.0)
    cco = result.cco_spikes[0]
    assert result.tde_counts[0] == 0, "without input the TDE never fires"
    # First spike from rest has no refractory period before it; then every period is eq. 6.
    p = params
    first = p.tau_cco * math.log(p.i_cco_offset * p.tau_cco / (p.i_cco_offset * p.tau_cco - 1.0))
    assert cco[0] == pytest.approx(first, rel=1e-13)
    np.testing.assert_allclose(np.diff(cco), 1.0 / frequency, rtol=1e-11)
    assert params.free_frequency() == pytest.approx(frequency, rel=1e-13)


def test_offset_inverts_equation_6():
    for f in (10.0, 100.0, 999.0):
        i = offset_for_frequency(f, tau=0.05, c=2.0, v_thr=0.5, t_refr=1e-3)
        assert free_frequency(i, tau=0.05, c=2.0, v_thr=0.5, t_refr=1e-3) == pytest.approx(
            f, rel=1e-12
        )
    assert free_frequency(0.5, tau=1.0) == 0.0  # offset too small to reach threshold


def _tde_probe(params: SpllParams, t_in: float, times: np.ndarray):
    result = simulate(params, [t_in], 0.05, probe_times=times)
    return result, result.info["trace"]


@pytest.mark.parametrize("tau_tde", [0.004, 0.0012, 0.002])  # 0.002 == tau_tde_trg: degenerate
def test_synapse_and_membrane_traces_equal_closed_forms(tau_tde):
    # Small trigger gain: the TDE stays below threshold, so the CCO free-runs undisturbed.
    params = SpllParams(
        tau_cco_syn=0.01, tau_cco=0.1, tau_tde_trg=0.002, tau_tde_fac=0.008, tau_tde=tau_tde,
        g_cco=1.0, g_tde_trg=1e-4, g_tde_fac=100.0,
    ).with_free_frequency(100.0)  # fmt: skip
    t_in = 0.001
    times = np.linspace(0.0, 0.05, 2001)
    result, trace = _tde_probe(params, t_in, times)
    assert result.tde_counts[0] == 0
    t_cco, t_cco_next = result.cco_spikes[0][:2]

    # Facilitatory synapse: g e^{-(t - t_in)/tau} after the input spike (right-continuous).
    i_fac = np.where(times >= t_in, 100.0 * np.exp(-(times - t_in) / 0.008), 0.0)
    np.testing.assert_allclose(trace["i_fac"][0], i_fac, rtol=1e-13, atol=1e-300)

    # CCO membrane before its first spike: A (1 - e^{-t/tau}) with A = I_off tau / C.
    a = params.i_cco_offset * params.tau_cco
    before = times < t_cco
    np.testing.assert_allclose(
        trace["v_cco"][0][before], a * -np.expm1(-times[before] / 0.1), rtol=1e-12, atol=1e-15
    )

    # Trigger current and TDE membrane between the first two CCO spikes (thesis eqs. 10-11).
    i0 = 1e-4 * 100.0 * math.exp(-(t_cco - t_in) / 0.008)
    after = (times >= t_cco) & (times < t_cco_next)
    s = times[after] - t_cco
    np.testing.assert_allclose(trace["i_trg"][0][after], i0 * np.exp(-s / 0.002), rtol=1e-12)
    if tau_tde == 0.002:
        v = i0 * s * np.exp(-s / tau_tde)
    else:
        v = i0 * 0.002 * tau_tde / (0.002 - tau_tde) * (np.exp(-s / 0.002) - np.exp(-s / tau_tde))
    np.testing.assert_allclose(trace["v_tde"][0][after], v, rtol=1e-9, atol=1e-14 * i0)


def test_refractory_period_holds_potential_at_zero():
    params = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(200.0)
    first = simulate(params, [], 0.02).cco_spikes[0][0]
    times = np.linspace(first, first + params.t_cco_refr, 50)
    trace = simulate(params, [], 0.02, probe_times=times).info["trace"]
    assert np.all(trace["v_cco"][0] == 0.0)
    later = simulate(params, [], 0.02, probe_times=[first + 1.5 * params.t_cco_refr]).info["trace"]
    assert later["v_cco"][0][0] > 0.0
