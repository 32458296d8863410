"""Energy as a range, and the time step as a design axis.

Every price of a chip (energy per event, time per event, power) may carry a low and a high end,
each with its source; a cost is reported at both ends, and one design is cheaper than another only
where that holds wherever the figures lie (:func:`spll_hw.chips.cheaper`). A clocked profile at
another step is ``NAME@STEP``; a step at which the chip cannot write the network is refused by
name, with the steps that can.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from quantize import ProfileError, load_profile, parse_profile
from quantize.resources import resource_report, sample_cost
from quantize.steps import step_problems
from spll_hw import chips, simulate
from spll_hw.config import NetworkConfig
from spll_hw.timestep import at_step, at_steps, parse_ladder, parse_step, step_label

from .test_chip_resources import CHIP, vary_offset, write

RANGED = CHIP.replace(
    'neuron_update = { value = 1e-12, source = "test" }',
    'neuron_update = { value = 1e-12, source = "test", low = 0.5e-12, low_source = "lo", '
    'high = 4e-12, high_source = "hi" }',
).replace(
    'spike = { value = 3e-12, source = "test" }',
    'spike = { value = 3e-12, source = "test", low = 1e-12, low_source = "lo", high = 3e-12, '
    'high_source = "hi" }',
)


# ----------------------------------------------------------------------------- the schema
def test_a_ranged_figure_parses_with_the_source_of_each_end():
    fig = parse_profile(RANGED, "chip.toml").chip.energy.figure("neuron_update")
    assert (fig.value, fig.low, fig.high) == (1e-12, 0.5e-12, 4e-12)
    assert (fig.low_source, fig.high_source) == ("lo", "hi")
    assert fig.at("low") == 0.5e-12 and fig.at("high") == 4e-12 and fig.at("value") == 1e-12
    chip = parse_profile(RANGED, "chip.toml").chip
    # A figure of one number is its own range.
    assert chip.at("high").energy.value("synaptic_event") == 2e-12
    assert "energy.neuron_update" not in chip.single() and "energy.message" in chip.single()


PLACED = CHIP.replace(
    'neurons_per_core = { value = 3, source = "test" }',
    'neurons_per_core = { value = 3, source = "test", low = 2, low_source = "a", high = 4, '
    'high_source = "b" }',
)
#: The profile each table's broken ranges are made from.
RANGED_TABLES = {"energy": RANGED, "resources": PLACED}


@pytest.mark.parametrize(
    ("table", "old", "new", "message"),
    [
        (
            "energy",
            ', high = 4e-12, high_source = "hi" }',
            " }",
            "gives a range without ['high', 'high_source']",
        ),
        ("energy", "low = 0.5e-12", "low = 2e-12", "must hold low <= value <= high"),
        (
            "energy",
            'low_source = "lo"',
            'low_source = " "',
            "neuron_update.low_source must say where",
        ),
        (
            "energy",
            "high = 4e-12",
            "high = -1.0",
            "neuron_update.high = -1.0 must be a finite number >= 0",
        ),
        # A count ranges in whole numbers.
        ("resources", "low = 2,", "low = 2.5,", "neurons_per_core.low must be an integer"),
        ("resources", "high = 4,", "high = 0,", "neurons_per_core.high = 0 is impossible"),
        ("resources", "low = 2,", "low = 5,", "must hold low <= value <= high"),
    ],
)
def test_a_broken_range_names_the_table_and_key(table, old, new, message):
    with pytest.raises(ProfileError, match=rf"chip\.toml \[{table}\]") as info:
        parse_profile(RANGED_TABLES[table].replace(old, new, 1), "chip.toml")
    assert message in str(info.value)


def test_a_flag_ranges_from_false_to_true_and_groups_take_no_range():
    flag = CHIP.replace(
        'realtime_paced = { value = false, source = "test" }',
        'realtime_paced = { value = false, source = "t", low = false, low_source = "a", '
        'high = true, high_source = "b" }',
    )
    fig = parse_profile(flag, "chip.toml").chip.timing.figure("realtime_paced")
    assert (fig.low, fig.value, fig.high) == (False, False, True)
    with pytest.raises(ProfileError, match="realtime_paced.high must be true or false"):
        parse_profile(flag.replace("high = true", "high = 1"), "chip.toml")
    shares = CHIP.replace(
        "[resources]\n",
        '[resources]\nconfigs_per_core = { value = 2, source = "t" }\nconfig_shares = '
        '{ value = ["decay"], source = "t", low = 1, low_source = "a", high = 2, '
        'high_source = "b" }\n',
    )
    with pytest.raises(ProfileError, match="config_shares has unknown key"):
        parse_profile(shares, "chip.toml")


def test_a_placement_range_moves_the_cores_and_bounds_the_cost(tmp_path):
    chip = parse_profile(PLACED, "chip.toml").chip
    # Prices and placement figures move apart: a price's end keeps the capacities.
    assert chip.at("low").resources.value("neurons_per_core") == 3
    assert [c.resources.value("neurons_per_core") for c in chip.placements()] == [3, 2, 4]
    path = write(tmp_path, PLACED)
    net = vary_offset(6)  # 12 compartments: 4 cores at 3 per core, 6 at 2, 3 at 4
    fit = chips.resources(chips.OnChip(net, path))
    assert (fit.cores, fit.cores_range, fit.fits) == (4, (3, 6), True)
    assert fit.cores_words() == "4 [3, 6]" and fit.data["cores_range"] == [3, 6]
    assert "3 to 6. At the low end it does not fit: needs 6 cores" in fit.markdown
    # Each end of the cost is the extreme, over the three placements, of that end's prices.
    result = simulate(net, np.linspace(1e-4, 9e-4, 7), 1e-3)
    result.info["n_input_spikes"] = 7
    cost = chips.cost(chips.OnChip(net, path), result)
    profile = load_profile(path)
    by_hand = []
    for placed in profile.chip.placements():
        report = resource_report(net, replace(profile, chip=placed))
        by_hand.append(sample_cost(report, replace(profile, chip=placed), result.tde_counts,
                                   result.cco_counts, 7, 1e-3).total_energy)  # fmt: skip
    assert cost.total_energy == pytest.approx(by_hand[0])
    # The low end needs 2 chips (6 cores of 4): static power x 2 chips.
    assert cost.static_range.high == pytest.approx(2 * cost.static_range.low)
    low = cost.dynamic_range.low + cost.static_range.low
    high = cost.dynamic_range.high + cost.static_range.high
    assert low == pytest.approx(min(by_hand)) and high == pytest.approx(max(by_hand))


def test_no_loihi2_figure_is_a_single_assumed_value():
    chip = load_profile("loihi2").chip
    assert chip.single() == [] and chip.single_assumed() == []
    for key in ("configs_per_core", "thresholds_per_core", "neurons_per_core", "multicast"):
        fig = chip.resources.figure(key)
        assert fig.ranged and fig.low_source and fig.high_source, key
    for table in (chip.timing, chip.energy):
        for key, fig in table.figures:
            if fig.ranged:
                assert fig.low_source and fig.high_source, key
                assert fig.low <= fig.value <= fig.high, key
    # The per-step energy and the static power are measured on a Loihi 2 board, not assumed.
    assert not chip.energy.figure("step").assumed
    assert not chip.energy.figure("static_power").assumed


@pytest.mark.parametrize("name", ["loihi1", "spinnaker", "dynapse2"])
def test_every_bundled_chip_prices_each_figure_as_a_sourced_range(name):
    chip = load_profile(name).chip
    assert chip.single() == []
    for table in (chip.timing, chip.energy):
        for key, fig in table.figures:
            if fig.ranged:
                assert fig.low_source and fig.high_source, key
                assert fig.low <= fig.value <= fig.high, key


def test_the_other_chips_ranges_are_the_published_ends_around_unchanged_values():
    loihi = load_profile("loihi1").chip.energy
    # Davies et al. 2018 Table 2's values kept; the ends from SANA-FE's two calibrations.
    update, synapse = loihi.figure("neuron_update"), loihi.figure("synaptic_event")
    assert (update.low, update.value, update.high) == (47.5e-12, 81e-12, 81e-12)
    assert (synapse.low, synapse.value, synapse.high) == (21.4e-12, 23.6e-12, 35.5e-12)
    # The assumed 30 mW static power lies between a measured idle chip (Blouw et al. 2019) and
    # Pohoiki Springs' static power per chip (Frady et al. 2020); it stays assumed.
    static = loihi.figure("static_power")
    assert (static.low, static.value, static.high) == (0.029, 0.03, 0.104) and static.assumed
    # SpiNNaker: its measured synaptic throughput is within 2x of the 0.1 us design target.
    spinnaker = load_profile("spinnaker").chip
    event = spinnaker.timing.figure("synaptic_event")
    assert (event.low, event.high) == (1e-7, 2e-7)
    assert spinnaker.energy.figure("message").low == spinnaker.energy.figure("message").high
    # DYNAP-SE2: no published figure was read, so each range is its one assumed number.
    for _, fig in load_profile("dynapse2").chip.energy.figures:
        assert fig.assumed and fig.low == fig.value == fig.high


# ------------------------------------------------------------------------ costs at both ends
def test_each_end_is_counts_times_that_ends_figures(tmp_path):
    profile = write(tmp_path, RANGED)
    net = vary_offset(1)
    result = simulate(net, np.linspace(1e-4, 9e-4, 7), 1e-3)
    result.info["n_input_spikes"] = 7
    cost = chips.cost(chips.OnChip(net, profile), result)
    counts = cost.figure_counts
    assert counts["neuron_update"] == 2 * 100 and counts["spike"] == int(
        result.tde_counts.sum() + result.cco_counts.sum()
    )
    for end, k in (("low", 0), ("high", 1)):
        by_hand = sum(n * cost.figure_ranges[key][k] for key, n in counts.items())
        assert getattr(cost.dynamic_range, end) == pytest.approx(by_hand)
    assert cost.dynamic_range.low < cost.dynamic_energy < cost.dynamic_range.high
    # The static power has no range here: both ends equal.
    assert cost.static_range.low == cost.static_range.high == pytest.approx(0.01 * 1e-3)
    assert str(cost.dynamic_range).startswith("[") and "J" in str(cost.dynamic_range)


def test_a_range_flips_a_ranking():
    # A pays more neuron updates, B more spikes: at the figures' values A is cheaper, but with
    # updates at their high end and spikes at their low end B is.
    ranges = {"neuron_update": (0.5e-12, 4e-12), "spike": (1e-12, 3e-12)}
    a, b = {"neuron_update": 200, "spike": 10}, {"neuron_update": 100, "spike": 60}
    values = {"neuron_update": 1e-12, "spike": 3e-12}
    assert sum(n * values[k] for k, n in a.items()) < sum(n * values[k] for k, n in b.items())
    assert chips.cheaper(a, b, ranges) is None
    # Point figures decide it; a difference that holds at every figure decides it whatever.
    points = {k: (v, v) for k, v in values.items()}
    assert chips.cheaper(a, b, points) is True and chips.cheaper(b, a, points) is False
    assert chips.cheaper({"neuron_update": 50, "spike": 10}, b, ranges) is True
    assert chips.cheaper(a, a, ranges) is None


def test_a_coarser_step_is_cheaper_at_both_ends_of_loihi2s_figures():
    net = NetworkConfig.preset("vibtac-time-scaled-lif").build()
    train = np.sort(np.random.default_rng(0).uniform(0, 1, 300))
    costs = {}
    for step in ("10us", "80us"):
        profile = f"loihi2@{step}"
        result = chips.realise(net, profile).network
        costs[step] = chips.cost(chips.OnChip(net, profile), simulate(result, train, 1.0))
    fine, coarse = costs["10us"], costs["80us"]
    assert fine.figure_counts["neuron_update"] == 8 * coarse.figure_counts["neuron_update"]
    assert fine.figure_counts["step"] == 100_000 and coarse.figure_counts["step"] == 12_500
    assert chips.cheaper(coarse.figure_counts, fine.figure_counts, coarse.figure_ranges) is True
    assert coarse.dynamic_range.high < fine.dynamic_range.low


def test_static_power_is_charged_over_the_whole_window(tmp_path):
    profile = write(tmp_path, CHIP)
    rep = resource_report(vary_offset(1), profile)
    # A free-running chip that is busy a fraction of the sample is still powered for all of it.
    cost = sample_cost(rep, profile, np.array([0]), np.array([0]), 0, 0.5)
    assert cost.time_on_chip < 0.5 and cost.window == 0.5
    assert cost.energy["static"] == pytest.approx(0.01 * 0.5)


# ------------------------------------------------------------------------------ the step
@pytest.mark.parametrize(
    ("text", "seconds"),
    [("80us", 8e-5), ("80 µs", 8e-5), ("0.08ms", 8e-5), ("8e-5", 8e-5), ("8e-5 s", 8e-5),
     ("1ms", 1e-3), ("500ns", 5e-7)],
)  # fmt: skip
def test_a_step_is_read_as_written(text, seconds):
    assert parse_step(text) == seconds


@pytest.mark.parametrize("text", ["abc", "0us", "2s", "-5us", "80 parsecs", "nan"])
def test_a_bad_step_says_how_to_write_one(text):
    with pytest.raises(ValueError, match=f"time step {text!r}"):
        parse_step(text)


def test_a_ladder_and_its_names():
    assert parse_ladder("10,20,40,80,160us") == (1e-5, 2e-5, 4e-5, 8e-5, 1.6e-4)
    assert parse_ladder("2e-5, 1e-5, 2e-5") == (1e-5, 2e-5)
    assert [step_label(s) for s in parse_ladder("10us,160us,1ms")] == ["10us", "160us", "1ms"]
    assert parse_ladder("10,20ms") == (1e-2, 2e-2)  # the last unit applies to bare numbers
    assert at_step("loihi2@10us", 8e-5) == "loihi2@80us"
    assert at_steps(["none", "loihi2", "analog"], [False, True, False], [1e-5, 8e-5]) == [
        "none", "loihi2@10us", "loihi2@80us", "analog",
    ]  # fmt: skip


def test_a_profile_at_a_step_is_the_chip_at_that_step():
    p = load_profile("loihi2@80us")
    assert p.name == "loihi2@80us" and p.dt == 8e-5 and "dt = 80us" in p.description
    assert p.decay_bits == load_profile("loihi2").decay_bits
    with pytest.raises(ProfileError, match="'analog' profile, which has no clock"):
        load_profile("analog@10us")
    with pytest.raises(ProfileError, match="unknown profile 'nochip'"):
        load_profile("nochip@10us")


def test_a_step_that_cannot_write_the_network_is_refused_with_the_steps_that_can():
    net = NetworkConfig.preset("biotac-tuned-time-scaled-lif").build()
    # 10 us: slow CCO decays round to no decay; 160 us: 79 us refractory periods round to 0.
    with pytest.raises(ValueError) as info:
        chips.realise(net, "loihi2@10us")
    text = str(info.value)
    assert "loihi2@10us cannot write this network" in text and "tau_cco = " in text
    assert "rounds to no decay" in text and "Steps that can: 40us, 80us." in text
    with pytest.raises(ValueError, match="t_cco_refr = 78.9 us is shorter than half a step"):
        chips.realise(net, "loihi2@160us")
    assert chips.realise(net, "loihi2@40us").profile.name == "loihi2@40us"
    # The shipped profile at its own step keeps clamping, as the chip is configured.
    assert chips.realise(net, "loihi2").profile.name == "loihi2"


def test_step_problems_match_the_decay_arithmetic():
    net = vary_offset(3)
    tau_cco = net.spll[0].tau_cco  # 0.314 s: below half an LSB of a 12-bit decay at 10 us
    assert 2**12 * (1 - np.exp(-1e-5 / tau_cco)) < 0.5
    problems = step_problems(net, 1e-5, 12, 8)
    assert len(problems) == 1 and problems[0].startswith("tau_cco = 314 ms rounds to no decay")
    assert "sPLL 0, 1, 2" in problems[0]
    assert step_problems(net, 4e-5, 12, 8) == []
    # An 8-bit refractory counter holds 255 steps: 1 ms at 1 us does not fit it.
    assert any("needs more than the 8-bit counter" in p for p in step_problems(net, 1e-6, 30, 8))
