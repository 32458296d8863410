"""Grouped time-scaled layouts under a group budget, and the analog profile's constraints."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import quantize
from quantize.analog import check_group_budget
from spll_hw import PARAM_NAMES, Network, network_frequencies
from spll_hw.layouts import circuit_count, grouped_layout, layout_cost, partition

from .conftest import VIBTAC_VARY_OFFSET_LIF

F_REF = 50.0


def brute_force(values: np.ndarray, n_groups: int, objective: str) -> float:
    """Best cost over every assignment of the values to ``n_groups`` non-empty groups (not
    only contiguous ones), each group at its optimal centre."""
    x = np.log(values)
    best = np.inf
    for labels in itertools.product(range(n_groups), repeat=len(x)):
        labels = np.array(labels)
        if len(set(labels)) != n_groups:
            continue
        parts = [x[labels == g] for g in range(n_groups)]
        if objective == "squared":
            cost = sum(float(np.sum((p - p.mean()) ** 2)) for p in parts)
        else:
            cost = max(float(p.max() - p.min()) / 2 for p in parts)
        best = min(best, cost)
    return best


@pytest.mark.parametrize("objective", ["squared", "max"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_partition_is_optimal_against_brute_force(objective, seed):
    rng = np.random.default_rng(seed)
    values = np.sort(np.exp(rng.uniform(0, 3, 7)))
    for n_groups in range(1, 5):
        part = partition(values, n_groups, objective)
        assert part.cost == pytest.approx(brute_force(values, n_groups, objective), abs=1e-12)
        assert len(part.centres) == n_groups and len(part.boundaries) == n_groups - 1
        # The reported cost is the cost of the reported layout.
        assert layout_cost(values, part.centres[part.groups], objective) == pytest.approx(
            part.cost, abs=1e-12
        )


def test_grouped_layout_beats_every_other_boundary_choice():
    freqs = network_frequencies(56.2, 668.0, 8, beta=10.0)
    scales = freqs / F_REF
    layout = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, 3, F_REF)
    costs = []
    for cut in itertools.combinations(range(1, 8), 2):
        net = Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 3, F_REF, boundaries=cut)
        costs.append(layout_cost(scales, net.scales))
    assert layout.cost == pytest.approx(min(costs), rel=1e-12)
    assert layout.cost <= min(costs) * (1 + 1e-12)
    net = layout.network
    assert net.layout == "grouped" and len(np.unique(net.groups)) == 3
    np.testing.assert_allclose(net.free_frequencies(), freqs, rtol=1e-10)


def test_grouped_layout_is_no_worse_than_equal_counts_on_the_thesis_network():
    freqs = network_frequencies(56.2, 668.0, 50)
    for g in (2, 4, 8):
        best = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, g, F_REF)
        equal = Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, g, F_REF)
        assert best.cost <= layout_cost(freqs / F_REF, equal.scales) + 1e-12
        assert circuit_count(best.network) == g


def test_one_group_is_vary_offset_and_n_groups_is_time_scaled():
    freqs = network_frequencies(56.2, 668.0, 12)
    one = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, 1, F_REF)
    scale = np.exp(np.mean(np.log(freqs / F_REF)))
    assert one.group_scales[0] == pytest.approx(scale, rel=1e-15)
    vary = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF.time_scaled(one.group_scales[0]), freqs)
    np.testing.assert_array_equal(one.network.matrix(), vary.matrix())
    midpoint = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, 1, F_REF, objective="max")
    assert midpoint.group_scales[0] == pytest.approx(np.sqrt(freqs[0] * freqs[-1]) / F_REF)
    full = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, 12, F_REF)
    scaled = Network.time_scaled(VIBTAC_VARY_OFFSET_LIF, freqs, F_REF)
    np.testing.assert_array_equal(full.group_scales, freqs / F_REF)
    np.testing.assert_allclose(full.network.matrix(), scaled.matrix(), rtol=1e-12)
    assert full.cost == 0.0


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, f, 7), "between 1 and 6"),
        (lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, f, 0), "between 1 and 6"),
        (lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, f[::-1], 2), "ascending"),
        (lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, [], 1), "at least one"),
        (lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, f, 2, -1.0), "reference"),
        (
            lambda f: grouped_layout(VIBTAC_VARY_OFFSET_LIF, f, 2, objective="l1"),
            "unknown objective",
        ),  # fmt: skip
        (lambda f: partition(-f, 2), "finite and > 0"),
        (lambda f: partition(f, 2.5), "must be an integer"),
    ],
)
def test_bad_layout_requests(call, message):
    with pytest.raises(ValueError, match=message):
        call(network_frequencies(60.0, 600.0, 6))


def test_group_budget_is_an_error_not_a_truncation():
    freqs = network_frequencies(56.2, 668.0, 20)
    scaled = Network.time_scaled(VIBTAC_VARY_OFFSET_LIF, freqs, F_REF)
    assert circuit_count(scaled) == 20
    assert circuit_count(Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, freqs)) == 1
    with pytest.raises(ValueError, match="needs 20 distinct sPLL circuits.*at most 8"):
        quantize.quantize(scaled, "analog")
    with pytest.raises(ValueError, match="at most 3.*spll-hw fit --layouts grouped:auto"):
        check_group_budget(Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 4), 3)
    with pytest.raises(ValueError, match="needs 20 .* of its 4 group.*set spread = 0"):
        check_group_budget(Network.grouped(VIBTAC_VARY_OFFSET_LIF, freqs, 4).with_spread(0.1), 8)
    fits = grouped_layout(VIBTAC_VARY_OFFSET_LIF, freqs, 8, F_REF).network
    assert quantize.quantize(fits, "analog").n_spll == 20


def test_analog_offset_levels_and_seeded_mismatch():
    freqs = network_frequencies(56.2, 668.0, 40)
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, freqs)
    profile = quantize.load_profile("analog")
    q = quantize.quantize(net, profile)
    offsets = q.network.matrix()[:, PARAM_NAMES.index("i_cco_offset")]
    assert len(np.unique(offsets)) == profile.offset_levels
    # Every offset moved to a level between its neighbours' requests: order is kept.
    assert np.all(np.diff(offsets) >= 0)
    again = quantize.quantize(net, profile)
    np.testing.assert_array_equal(q.network.matrix(), again.network.matrix())
    other = quantize.quantize(net, profile, seed=profile.seed + 1)
    assert not np.array_equal(q.network.matrix(), other.network.matrix())
    tau = PARAM_NAMES.index("tau_tde")
    ratio = np.log(q.network.matrix()[:, tau] / net.matrix()[:, tau])
    assert np.std(ratio) == pytest.approx(profile.tau_sigma, rel=0.35)
    # No mismatch and enough levels: the realised network is the requested one.
    exact = quantize.AnalogProfile("exact", "no constraints", 0.0, 0.0, 40, 1, 0)
    np.testing.assert_array_equal(quantize.quantize(net, exact).network.matrix(), net.matrix())
    assert q.report.saturated() == []
    assert any("share 16 levels" in w for w in q.report.warnings)
    with pytest.raises(ValueError, match="seed applies to analog profiles only"):
        quantize.quantize(net, "loihi2", seed=1)


def test_offset_levels_keep_zero_offsets():
    from quantize.analog import offset_levels

    snapped = offset_levels(np.array([0.0, 1.0, 2.0, 4.0, 8.0]), 3)
    assert snapped[0] == 0.0 and len(np.unique(snapped)) == 3
    with pytest.raises(ValueError, match="cannot provide both zero and non-zero"):
        offset_levels(np.array([0.0, 1.0]), 1)
