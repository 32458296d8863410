"""The spiking readout on a chip: its cores beside the network's, its synapses, the messages
every TDE spike sends it, and its share of a classification, against counts made directly."""

from __future__ import annotations

import json

import numpy as np
import pytest

from quantize import load_profile
from quantize.readout import readout_cost, readout_fit
from quantize.resources import resource_report
from spll_hw import chips
from spll_hw.cli.main import main
from spll_hw.model.grid import n_steps
from spll_hw.multichannel.chips import classification_cost, readout_placement, whole_network
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.result import SimulationResult

from .test_chip_resources import vary_offset, write
from .test_multichannel_chips import PLACED, chips_argv, multi_input_chip
from .test_multichannel_data import write_recording
from .test_multichannel_network import LOW


def route(a: int, b: int, columns: int) -> set:
    """X-then-Y router edges between cores ``a`` and ``b`` of a one-core-per-tile mesh."""
    (x0, y0), (x1, y1) = (a % columns, a // columns), (b % columns, b // columns)
    edges = {((x, y0), (x + 1, y0)) for x in range(min(x0, x1), max(x0, x1))}
    return edges | {((x1, y), (x1, y + 1)) for y in range(min(y0, y1), max(y0, y1))}


def walk(rep, fit, tde, multicast: bool) -> dict:
    """Every TDE spike, one by one, to every readout core: messages, hops, deliveries."""
    out = {"messages": 0, "hops": 0, "deliveries": 0}
    for i in range(rep.n_spll):
        src = int(rep.tde_core[i])
        paths = [route(src, c, 2) for c in fit.cores]
        tree = set().union(*paths) - route(src, int(rep.cco_core[i]), 2)
        for _ in range(int(tde[i])):
            out["messages"] += 0 if multicast else len(fit.cores)
            out["hops"] += len(tree) if multicast else sum(map(len, paths))
            out["deliveries"] += sum(fit.neurons)
    return out


@pytest.mark.parametrize(("multicast", "classes"), [("false", 5), ("true", 5), ("false", 1)])
def test_readout_messages_and_deliveries_equal_a_walk_over_every_tde_spike(
    tmp_path, multicast, classes
):
    # 3 neurons per core: a readout of 5 takes two cores of its own after the network's
    path = multi_input_chip(tmp_path, 3, multicast)
    net = vary_offset(3)
    rep = resource_report(net, path)
    fit = readout_fit(rep, path, classes)
    assert fit.fits and fit.cores[0] == rep.n_cores and sum(fit.neurons) == classes
    assert fit.neurons == ((3, 2) if classes == 5 else (1,))
    assert fit.synapses == classes * 3 and fit.synapse_bits == classes * 3 * 8
    tde = np.array([7, 0, 12])
    cost = readout_cost(fit, rep, path, tde, 0.2, 0.2)
    expect = walk(rep, fit, tde, multicast == "true")
    c = cost.counts
    assert (c.messages, c.hops, c.deliveries) == (
        expect["messages"], expect["hops"], expect["deliveries"])  # fmt: skip
    assert c.hops > 0 and c.spikes == 1
    dt = load_profile(path).dt
    assert c.steps == n_steps(0.2, dt) and c.neuron_updates == classes * c.steps
    # energy: the counts times the profile's figures (multi_input_chip's [energy] table)
    figures = {"deliveries": 2e-12, "messages": 5e-12, "hops": 7e-12, "neuron updates": 1e-12,
               "spikes": 3e-12}  # fmt: skip
    for name, per in figures.items():
        count = getattr(c, name.replace(" ", "_"))
        assert cost.energy[name] == pytest.approx(per * count)
    assert cost.energy["chip hops"] is None and cost.energy["cores"] is None
    assert cost.energy["static"] == 0.0  # the readout stays on the network's chip
    assert cost.dynamic_energy == pytest.approx(sum(figures[n] * getattr(c, n.replace(" ", "_"))
                                                    for n in figures))  # fmt: skip


def test_a_readout_past_the_chips_cores_or_synapses_is_refused_with_the_reason(tmp_path):
    path = multi_input_chip(tmp_path, 3)  # 8 cores of 3 neurons; the network takes 2
    rep = resource_report(vary_offset(3), path)
    fit = readout_fit(rep, path, 19)  # 7 more cores: 9 > 8
    assert not fit.fits and "the profile allows 8" in fit.problems[0]
    text = open(path).read()
    few = write(
        tmp_path,
        text.replace("[timing]", 'synapses_per_core = { value = 2, source = "t" }\n\n[timing]'),
        "few.toml",
    )
    fit = readout_fit(resource_report(vary_offset(1), few), few, 2)
    assert fit.fits and fit.neurons == (2,)  # one TDE: two synapses on a core
    fit = readout_fit(resource_report(vary_offset(3), few), few, 2)
    assert not fit.fits and fit.cores == ()
    assert "needs 3 synapses (one per TDE), the profile allows 2 (synapses_per_core)" in (
        fit.problems[-1])  # fmt: skip
    with pytest.raises(ValueError, match="no readout placement"):
        readout_cost(fit, rep, few, np.zeros(3), 0.1, None)
    with pytest.raises(ValueError, match=">= 1 class"):
        readout_fit(rep, path, 0)


@pytest.fixture(scope="module")
def preset():
    return MultichannelConfig.load("biotac-multichannel-lif")


@pytest.mark.parametrize("name", PLACED)
def test_the_presets_readout_sits_on_a_core_of_its_own_on_every_placing_chip(preset, name):
    fit = readout_placement(preset, name, 20)
    network, inputs = whole_network(preset)
    rep = chips.resources(chips.OnChip(network, name, inputs=inputs))
    assert fit.fits and fit.cores == 1 and fit.data["cores"] == [rep.cores]
    assert fit.data["synapses"] == 20 * 402
    multicast = load_profile(name).chip.resources.value("multicast", False)
    assert fit.data["messages_per_tde_spike"] == (0 if multicast else 1)
    # its cost on a sample is the TDE counts times what one spike adds
    rng = np.random.default_rng(0)
    tde = rng.integers(0, 50, 402)
    result = SimulationResult(tde, tde, 0.1, info={"n_input_spikes": np.full(23, 30)})
    cost = chips.readout_cost(chips.OnChip(network, name, inputs=inputs), 20, result)
    detail = cost.detail
    assert detail.counts.deliveries == 20 * tde.sum()
    assert detail.counts.messages == (0 if multicast else tde.sum())
    assert detail.counts.hops == tde @ fit.detail.hops
    assert cost.dynamic_energy == pytest.approx(detail.dynamic_energy)
    # spinnaker charges its cores by time, not by event: its readout costs a core's power
    assert cost.total_energy > 0 and (cost.dynamic_energy > 0) == (name != "spinnaker")
    assert (
        cost.time_on_chip
        == chips.cost(chips.OnChip(network, name, inputs=inputs), result).time_on_chip
    )


def test_dynapse2_refuses_the_readout_naming_the_synapses_per_neuron(preset):
    fit = readout_placement(preset, "dynapse2", 20)
    assert not fit.fits and fit.cores == 0
    assert "needs 402 synapses (one per TDE), the profile allows 64 (synapses_per_neuron)" in (
        fit.problems[-1])  # fmt: skip


def test_classification_cost_adds_the_readout_apart_from_the_network(tmp_path):
    for material in ("mat1", "mat2", "mat3"):
        write_recording(tmp_path, material, 1, rows=60)
    path = tmp_path / "mc.toml"
    path.write_text(LOW)
    config = MultichannelConfig.load(path)
    from spll_hw.datasets.biotac_channels import load_biotac_channels
    from spll_hw.multichannel.features import input_levels

    samples = load_biotac_channels(tmp_path, config.channels, ["mat1", "mat2", "mat3"],
                                   duration=0.5)  # fmt: skip
    levels = input_levels(config, samples)
    without = classification_cost(config, "loihi2", samples, levels, 0.5)
    cost = classification_cost(config, "loihi2", samples, levels, 0.5, classes=3)
    assert without.readout == () and without.readout_energy is None
    assert [c.energy for c in cost.costs] == [c.energy for c in without.costs]
    assert len(cost.readout) == len(samples) and cost.readout_energy > 0
    # the readout's updates: 3 neurons every 10 us step of the window
    assert all(c.detail.counts.neuron_updates == 3 * 50_000 for c in cost.readout)


def test_chips_command_reports_the_readout_beside_the_network(tmp_path, capsys):
    argv, out = chips_argv(tmp_path, "loihi2,dynapse2")
    assert main(argv + ["--readout-classes", "3"]) == 0
    text = capsys.readouterr().out
    assert "## The spiking readout beside it" in text
    assert "| loihi2 | yes | 1 | 24 (0.024 kB) | 1 |" in text  # 3 x 8 TDEs, 8-bit weights
    data = json.loads((out / "results.json").read_text())
    loihi = data["profiles"][0]
    assert data["readout_classes"] == 3 and loihi["readout"]["cores"] == [1]
    assert loihi["readout"]["classification"]["dynamic_energy_j"] > 0
    assert main(argv + ["--readout-classes", "0"]) == 0
    assert "spiking readout" not in capsys.readouterr().out
    assert main(argv + ["--readout-classes", "-1"]) == 2
