"""Network layouts and frequency placement (thesis 2.4.3, 2.5 and discussion)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from spll_hw import PARAM_NAMES, Network, SpllParams, network_frequencies

from .conftest import BIOTAC_TIME_SCALED_TOUCHSIM, VIBTAC_VARY_OFFSET_LIF


def test_frequency_spacing_formula():
    lin = network_frequencies(56.2, 668.0, 50)
    np.testing.assert_allclose(np.diff(lin), (668.0 - 56.2) / 49)
    geo = network_frequencies(30.0, 600.0, 50, beta=0.0)
    np.testing.assert_allclose(geo[1:] / geo[:-1], (600.0 / 30.0) ** (1 / 49))
    for beta in (0.0, 1.0, 10.0, 100.0, math.inf):
        f = network_frequencies(61.6, 669.0, 50, beta=beta)
        assert f[0] == pytest.approx(61.6) and f[-1] == pytest.approx(669.0)
        assert np.all(np.diff(f) > 0)
    # Larger beta moves the spacing towards linear: the midpoint rises towards the mean.
    mids = [network_frequencies(30, 700, 51, beta=b)[25] for b in (0, 1, 10, 100, 1e6)]
    assert np.all(np.diff(mids) > 0) and mids[-1] == pytest.approx(365.0, rel=1e-3)


def test_vary_offset_keeps_everything_but_the_offset():
    freqs = network_frequencies(56.2, 668.0, 50)
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, freqs)
    m = net.matrix()
    assert m.shape == (50, 15) and net.layout == "vary-offset"
    others = np.delete(m, PARAM_NAMES.index("i_cco_offset"), axis=1)
    assert np.all(np.ptp(others, axis=0) == 0)
    np.testing.assert_allclose(net.free_frequencies(), freqs, rtol=1e-12)


def test_time_scaled_divides_times_and_keeps_gains_and_offset():
    freqs = network_frequencies(44.0, 668.0, 50, beta=10.0)
    net = Network.time_scaled(BIOTAC_TIME_SCALED_TOUCHSIM, freqs, reference_frequency=50.0)
    np.testing.assert_allclose(net.free_frequencies(), freqs, rtol=1e-12)
    np.testing.assert_allclose(net.scales, freqs / 50.0)
    for p, s in zip(net.spll, net.scales, strict=True):
        assert p.g_cco == BIOTAC_TIME_SCALED_TOUCHSIM.g_cco
        assert p.i_cco_offset == net.spll[0].i_cco_offset
        assert p.tau_tde * s == pytest.approx(BIOTAC_TIME_SCALED_TOUCHSIM.tau_tde)
        assert p.t_cco_refr * s == pytest.approx(1e-3)


@pytest.mark.parametrize("groups", [1, 2, 4, 8])
def test_grouped_layout(groups):
    freqs = network_frequencies(61.6, 669.0, 50, beta=1.0)
    net = Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, groups)
    np.testing.assert_allclose(net.free_frequencies(), freqs, rtol=1e-12)
    assert len(np.unique(net.groups)) == groups
    assert np.all(np.diff(net.groups) >= 0)
    for g in range(groups):
        members = [p for p, k in zip(net.spll, net.groups, strict=True) if k == g]
        assert len({p.tau_tde for p in members}) == 1, "one time scale per group"
        assert len(members) in (50 // groups, 50 // groups + 1)


def test_grouped_extremes_are_vary_offset_and_time_scaled():
    freqs = network_frequencies(56.2, 668.0, 12)
    base = VIBTAC_VARY_OFFSET_LIF
    one = Network.grouped(base, freqs, 1, group_scales=[1.0])
    np.testing.assert_allclose(one.matrix(), Network.vary_offset(base, freqs).matrix(), rtol=1e-14)
    every = Network.grouped(base, freqs, 12)
    np.testing.assert_allclose(
        every.matrix(), Network.time_scaled(base, freqs).matrix(), rtol=1e-12
    )


def test_grouped_bad_arguments():
    freqs = network_frequencies(56.2, 668.0, 10)
    with pytest.raises(ValueError, match="n_groups"):
        Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 11)
    with pytest.raises(ValueError, match="boundaries"):
        Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 3, boundaries=[5, 5])
    with pytest.raises(ValueError, match="ascending"):
        Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs[::-1], 2)
    with pytest.raises(ValueError, match="group_scales"):
        Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 2, group_scales=[1.0, -1.0])


def test_params_toml_round_trip(tmp_path):
    path = tmp_path / "best.toml"
    path.write_text(VIBTAC_VARY_OFFSET_LIF.to_toml())
    assert SpllParams.from_toml(path) == VIBTAC_VARY_OFFSET_LIF
    path.write_text("[spll]\ntau_cco = 'x'\n")
    with pytest.raises(ValueError, match="best.toml"):
        SpllParams.from_toml(path)
    path.write_text("not = [toml")
    with pytest.raises(ValueError, match="not valid TOML"):
        SpllParams.from_toml(path)


# ------------------------------------------------------------------------------ spread
def test_spread_varies_time_constants_and_gains_lognormally_and_keeps_frequencies():
    from spll_hw.network import SPREAD_PARAMS

    freqs = network_frequencies(40.0, 600.0, 400, 10.0)
    base = Network.time_scaled(BIOTAC_TIME_SCALED_TOUCHSIM, freqs)
    sigma = 0.3
    spread = base.with_spread(sigma, seed=7)
    ratio = spread.matrix() / base.matrix()
    varied = [PARAM_NAMES.index(n) for n in SPREAD_PARAMS]
    fixed = [i for i, n in enumerate(PARAM_NAMES) if n not in SPREAD_PARAMS + ("i_cco_offset",)]
    assert np.all(ratio[:, fixed] == 1.0)
    log_ratio = np.log(ratio[:, varied])
    # 400 x 8 independent N(0, sigma^2) draws: mean within 5 standard errors, sd within 5 %
    assert abs(log_ratio.mean()) < 5 * sigma / math.sqrt(log_ratio.size)
    assert log_ratio.std() == pytest.approx(sigma, rel=0.05)
    assert abs(np.corrcoef(log_ratio.T)[np.triu_indices(len(varied), 1)]).max() < 0.2
    np.testing.assert_allclose(spread.free_frequencies(), freqs, rtol=1e-12)
    assert not np.allclose(spread.matrix()[:, PARAM_NAMES.index("i_cco_offset")],
                           base.matrix()[:, PARAM_NAMES.index("i_cco_offset")])  # fmt: skip
    assert spread.layout == base.layout
    np.testing.assert_array_equal(spread.scales, base.scales)


def test_spread_is_seeded_and_zero_is_the_network_itself():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 10))
    assert net.with_spread(0.0, seed=3) is net
    np.testing.assert_array_equal(
        net.with_spread(0.2, 1).matrix(), net.with_spread(0.2, 1).matrix()
    )
    assert not np.array_equal(net.with_spread(0.2, 1).matrix(), net.with_spread(0.2, 2).matrix())
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="spread sigma"):
            net.with_spread(bad)


def test_spread_that_cannot_keep_a_frequency_names_the_spll():
    # 600 Hz with a 1-ms refractory period: a much faster membrane needs an offset beyond the
    # double-precision guard of eq. 6 for some sPLL, and the error says which one.
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [600.0] * 20)
    with pytest.raises(ValueError, match=r"sPLL \d+ cannot keep its free frequency 600 Hz"):
        net.with_spread(8.0, seed=0)
