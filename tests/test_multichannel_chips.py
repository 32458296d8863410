"""A multichannel network on the chips: one network of several inputs, its placement per
channel, the messages its channels' spikes make, and the cost of one classification."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from quantize import load_profile
from quantize.resources import event_counts, resource_report
from spll_hw import backends, chips, simulate
from spll_hw.cli.main import main
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.multichannel.chips import classification_cost, placement, whole_network
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels

from .test_chip_resources import CHIP, vary_offset, write
from .test_multichannel_data import write_recording
from .test_multichannel_network import LOW

#: Bundled profiles with a [resources] table, apart from DYNAP-SE2 (which refuses the preset).
PLACED = ("loihi1", "loihi2", "spinnaker")


@pytest.fixture(scope="module")
def preset():
    return MultichannelConfig.load("biotac-multichannel-lif")


def test_whole_network_joins_every_channels_network_in_feature_order(preset):
    network, inputs = whole_network(preset)
    assert network.n_spll == preset.n_spll == 402 and inputs.shape == (402,)
    assert list(np.bincount(inputs)) == [50] + [16] * 22
    pac = preset.groups[0].network.build()
    ele = preset.groups[1].network.build()
    assert network.spll[:50] == pac.spll and network.spll[50:66] == network.spll[66:82] == ele.spll


@pytest.mark.parametrize("name", PLACED)
def test_every_spll_is_placed_once_within_the_cores_limits(preset, name):
    place = placement(preset, name)
    data, res = place.fit.data, load_profile(name).chip.resources
    assert place.fit.fits and data["inputs"] == 23
    tdes = sorted(i for core in data["placement"] for i in core["tde"])
    ccos = sorted(i for core in data["placement"] for i in core["cco"])
    assert tdes == ccos == list(range(402))
    for core in data["placement"]:
        assert core["compartments"] <= res.value("neurons_per_core")
        for key, used in (
            ("configs_per_core", "configs"),
            ("thresholds_per_core", "thresholds"),
            ("synapses_per_core", "synapses"),
            ("fan_in_per_core", "fan_in"),
        ):
            if key in res:
                assert core[used] <= res.value(key), (key, core["core"])  # fmt: skip
        channels = {int(place.inputs[i]) for i in core["tde"]}
        assert core["fan_in"] == len(channels) + len(core["tde"]) + len(core["cco"])
    # the per-channel view counts the same sPLLs
    per_channel = {c: [0, 0] for c in preset.channels}
    for held in place.cores:
        for channel, (t, k) in held.items():
            per_channel[channel][0] += t
            per_channel[channel][1] += k
    assert per_channel == {c: [n, n] for c, n in zip(preset.channels, [50] + [16] * 22,
                                                     strict=True)}  # fmt: skip
    split = sum(len(set(core["tde"]) - set(core["cco"])) for core in data["placement"])
    assert place.split == split


def test_dynapse2_refuses_the_network_and_says_why(preset):
    place = placement(preset, "dynapse2")
    assert not place.fit.fits and place.fit.cores == 0 and place.cores == ()
    assert "66 distinct sPLL circuits" in place.fit.problems[0]
    # advice a multichannel file can follow, not fit's single-network grouped:auto
    assert "give the [[channel]] tables layouts with fewer circuits" in place.fit.problems[0]
    assert "grouped:auto" not in place.markdown() + str(place.fit.data)
    assert "nothing placed" in place.markdown()


def multi_input_chip(tmp_path, per_core: int, multicast: str = "false") -> str:
    text = (
        CHIP.replace("neurons_per_core = { value = 3", f"neurons_per_core = {{ value = {per_core}")
        .replace("cores_per_chip = { value = 4", "cores_per_chip = { value = 8")
        .replace("mesh_columns = { value = 1", "mesh_columns = { value = 2")
        .replace("[timing]", f'multicast = {{ value = {multicast}, source = "t" }}\n\n[timing]')
    )
    return write(tmp_path, text)


def test_a_channels_sPLLs_stay_together_when_that_saves_input_axons(tmp_path):
    # Two channels of the same two sPLLs, two sPLLs per core: sorted by configuration the two
    # channels would share both cores (4 input axons); kept together, one core each (2).
    net = vary_offset(2)
    both = type(net)(net.spll + net.spll, "custom")
    rep = resource_report(both, multi_input_chip(tmp_path, 4), inputs=[0, 0, 1, 1])
    assert rep.n_cores == 2 and list(rep.tde_core) == [0, 0, 1, 1]
    assert [c.fan_in for c in rep.cores] == [1 + 2 + 2, 1 + 2 + 2]
    assert rep.input_routes[:, 0].tolist() == [1, 1] and rep.input_messages == 2
    # one input: the placement of before, one input axon per core
    alone = resource_report(both, multi_input_chip(tmp_path, 4))
    assert alone.n_inputs == 1 and alone.input_routes[:, 0].tolist() == [2]


def walk(rep, tde, cco, spikes_of, columns, multicast):
    """Every spike of every input and every sPLL, one by one: deliveries, messages, crossings
    and hops, each input's spikes to the cores holding its own TDEs."""
    out = {"deliveries": 0, "messages": 0, "crossing": 0, "hops": 0}

    def route(a, b):
        (x0, y0), (x1, y1) = (a % columns, a // columns), (b % columns, b // columns)
        edges = [((x, y0), (x + 1, y0)) for x in range(min(x0, x1), max(x0, x1))]
        return edges + [((x1, y), (x1, y + 1)) for y in range(min(y0, y1), max(y0, y1))]

    for k, n_spikes in enumerate(spikes_of):
        mine = np.flatnonzero(rep.input_of == k)
        cores = sorted({int(rep.tde_core[i]) for i in mine})
        paths = [route(0, c) for c in cores]
        for _ in range(n_spikes):
            out["deliveries"] += mine.size
            out["messages"] += 1 if multicast else len(cores)
            out["crossing"] += 1 if multicast else len(cores)
            out["hops"] += len({e for p in paths for e in p}) if multicast else sum(map(len, paths))
    for i in range(rep.n_spll):
        for count, src, dst in ((cco[i], rep.cco_core[i], rep.tde_core[i]),
                                (tde[i], rep.tde_core[i], rep.cco_core[i])):  # fmt: skip
            out["deliveries"] += count
            out["messages"] += count
            out["crossing"] += count * int(src != dst)
            out["hops"] += count * len(route(int(src), int(dst)))
    return out


@pytest.mark.parametrize(("per_core", "multicast"), [(3, "false"), (5, "true"), (4, "false")])
def test_cross_core_messages_equal_a_walk_over_every_channels_spikes(tmp_path, per_core, multicast):
    net = vary_offset(3)
    joined = type(net)(net.spll * 3, "custom")
    inputs = np.repeat([0, 1, 2], 3)
    rep = resource_report(joined, multi_input_chip(tmp_path, per_core, multicast), inputs=inputs)
    rng = np.random.default_rng(3)
    trains = [np.sort(rng.uniform(0, 0.2, size)) for size in (40, 7, 0)]
    tde, cco = np.zeros(9, np.int64), np.zeros(9, np.int64)
    for k, train in enumerate(trains):
        r = simulate(net, train, 0.2)
        tde[inputs == k], cco[inputs == k] = r.tde_counts, r.cco_counts
    spikes = [t.size for t in trains]
    counts = event_counts(rep, tde, cco, spikes, 0.2, 1e-5)
    expect = walk(rep, tde, cco, spikes, 2, multicast == "true")
    assert counts.synaptic_events == expect["deliveries"]
    assert counts.total("messages") == expect["messages"]
    assert sum(counts.crossing.values()) == expect["crossing"]
    assert counts.total("hops") == expect["hops"]
    assert counts.input_spikes == 47 and counts.per_input == (40, 7, 0)
    assert (rep.tde_core != rep.cco_core).any() or per_core != 3  # some sPLL is split
    with pytest.raises(ValueError, match="3 input\\(s\\): give the input spikes of each"):
        event_counts(rep, tde, cco, 47, 0.2, 1e-5)


@pytest.mark.parametrize(
    ("inputs", "message"),
    [([0, 0], "shape \\(3,\\)"), ([0, -1, 1], "integer >= 0"), ([0, 2, 2], "inputs \\[1\\]")],
)
def test_bad_inputs_are_named(inputs, message):
    with pytest.raises(ValueError, match=message):
        resource_report(vary_offset(3), "loihi2", inputs=inputs)


def test_one_channels_classification_costs_what_its_network_costs(tmp_path):
    for material in ("mat1", "mat2"):
        write_recording(tmp_path, material, 1, rows=60)
    config = MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif")
    samples = load_biotac_channels(tmp_path, ["pac"], ["mat1", "mat2"], duration=0.5)
    levels = input_levels(config, samples)
    cost = classification_cost(config, "loihi2", samples, levels, 0.5)
    assert len(cost.costs) == len(samples) and cost.dynamic_energy > 0
    # the same sample through the single-network path: the chip's realisation in the golden
    # model, costed with one input
    network = config.groups[0].network.build()
    encoder = config.groups[0].make_encoder()
    signals = samples.channel("pac").normalized(levels["pac"], "test")
    train = encoder.encode(signals.signals[:1], signals.fs)[0]
    result = backends.get("golden:profile=loihi2").simulate(network, train, 0.5)
    alone = chips.cost(chips.OnChip(network, "loihi2"), result)
    assert cost.costs[0].energy == alone.energy
    assert cost.input_spikes == pytest.approx(
        np.mean([t.size for t in encoder.encode(signals.signals, signals.fs)])
    )
    assert cost.latency == pytest.approx(0.5 * max(1.0, cost.real_time_factor))


def chips_argv(tmp_path, profiles: str, network: str = LOW) -> tuple[list[str], object]:
    """``spll-hw chips --multichannel`` of the multichannel ``network`` (default: the two-channel
    ``LOW``) on one 60-row recording of each of the 20 materials, 0.5 s each; the arguments and
    the report folder."""
    for material in range(1, 21):
        write_recording(tmp_path, f"mat{material}", 1, rows=60)
    path = tmp_path / "mc.toml"
    path.write_text(network)
    out = tmp_path / "chips"
    argv = ["chips", "--network", str(path), "--data", str(tmp_path), "--recordings", "1",
            "--windows", "0.5", "--profiles", profiles, "--out", str(out)]  # fmt: skip
    return argv, out


def test_chips_command_places_and_costs_a_multichannel_network(tmp_path, capsys):
    argv, out = chips_argv(tmp_path, "loihi2,dynapse2,analog")
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "| loihi2 | yes | 1 | 1 | 0 | 2 |" in text  # one input message per channel spike
    # four circuits fit DYNAP-SE2's budget, but one bias set per core needs 8 cores for them
    assert "| dynapse2 | no | 8 | 2 | 8 |" in text and "needs 8 cores for 8 distinct" in text
    assert "| 0 | ele1 4/4, pdc 4/4 |" in text and "Skipped (no [resources] table): analog" in text
    data = json.loads((out / "results.json").read_text())
    loihi = data["profiles"][0]
    assert loihi["channels_per_core"] == [{"ele1": [4, 4], "pdc": [4, 4]}]
    assert loihi["classification"]["samples"] == 20 and loihi["classification"]["latency_s"] >= 0.5
    assert data["profiles"][1]["resources"]["fits"] is False

    assert main(argv[:3] + ["--network", "x"]) == 2


def test_one_shared_three_offset_network_fits_dynapse2_and_two_circuits_do_not(preset, tmp_path):
    rows = preset.groups[1].network
    shared = replace(rows, layout="grouped:1", f_start=2.0, f_end=45.0, n=3)
    one = preset.with_network(shared)
    assert [g.network for g in one.groups] == [shared, shared]
    assert [(g.channels, g.encoder, g.input_level) for g in one.groups] == [
        (g.channels, g.encoder, g.input_level) for g in preset.groups
    ]
    assert one.groups[1].space is None and one.n_spll == 3 * 23
    place = placement(one, "dynapse2")
    assert place.fit.fits and place.fit.cores == 4 and place.split == 69
    assert place.cores[0] == {c: (3, 0) for c in preset.channels}  # every TDE on one core
    assert all(core == {c: (0, 1) for c in preset.channels} for core in place.cores[1:])
    own = replace(one.groups[0], network=replace(shared, f_start=41.6, f_end=671.0))
    two = replace(one, groups=(own, one.groups[1]))
    assert not placement(two, "dynapse2").fit.fits  # 2 TDE sets + 6 offsets: 8 cores
    path = tmp_path / "shared.toml"
    path.write_text(one.to_toml())
    assert MultichannelConfig.load(path).groups == one.groups
    assert MultichannelConfig.load("biotac-multichannel-dynapse2").groups == one.groups
