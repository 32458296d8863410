"""A multichannel network and its spiking readout as one NIR graph (mappings/nir/multichannel.py,
spll-hw export --multichannel): written and read back to the same networks and readout, and the
read-back graph's golden runs decide as the original; bad input is a clear ValueError."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import multichannel as mc  # noqa: E402
from spll_hw import simulate_batch  # noqa: E402
from spll_hw.cli.main import main  # noqa: E402
from spll_hw.multichannel.chips import whole_network  # noqa: E402
from spll_hw.multichannel.config import MultichannelConfig  # noqa: E402
from spll_hw.multichannel.decisions import engine_decisions  # noqa: E402
from spll_hw.multichannel.readout import START, Readout  # noqa: E402
from spll_hw.multichannel.readout_file import SavedReadout, load_readout, save_readout  # noqa: E402

from .test_multichannel_data import ROW_SPLL  # noqa: E402

SPLL = ROW_SPLL
CONFIG = f"""
[[channel]]
channels = ["a"]
[channel.spll]
{SPLL}
[channel.network]
layout = "time-scaled"
f_start = 5.0
f_end = 40.0
n = 3
[channel.encoder]
name = "lif"

[[channel]]
channels = ["b", "c"]
[channel.spll]
{SPLL}
[channel.network]
layout = "time-scaled"
f_start = 2.0
f_end = 20.0
n = 2
[channel.encoder]
name = "lif"
"""
NAMES = ("slow", "middle", "fast")
DURATION = 1.0


@pytest.fixture(scope="module")
def config() -> MultichannelConfig:
    return MultichannelConfig.from_document(tomllib.loads(CONFIG), Path("test.toml"))


def tde_runs(networks, trains):
    """Every run's TDE spike times in feature order: ``trains[r][c]`` channel c's input."""
    out = []
    for run in trains:
        row = []
        for network, train in zip(networks, run, strict=True):
            (result,) = simulate_batch(network, [train], DURATION, record_spikes=True, threads=1)
            row += result.tde_spikes
        out.append(row)
    return out


@pytest.fixture(scope="module")
def trained(config):
    """A readout trained on golden runs of three classes of input rate, held-out runs' input
    trains and the original networks' TDE spikes of them."""
    rng = np.random.default_rng(7)
    rates = np.repeat([8.0, 15.0, 30.0], 6)  # Hz, one class each
    trains = [
        [np.sort(rng.uniform(0, DURATION, rng.poisson(r * s))) for s in (1.0, 0.7, 1.4)]
        for r in rates
    ]
    networks = [g.network.build() for g in config.groups for _ in g.channels]
    runs = tde_runs(networks, trains)
    counts = np.array([[len(t) for t in run] for run in runs], float)
    labels = np.repeat(np.arange(3), 6)
    train = np.arange(18) % 3 != 0
    readout = Readout.from_ridge(counts[train], labels[train], NAMES)
    held = [t for t, keep in zip(trains, train, strict=True) if not keep]
    held_runs = [r for r, keep in zip(runs, train, strict=True) if not keep]
    saved = SavedReadout(readout, config.channels, np.array([1.5, 2.0, 0.25]))
    return saved, held, held_runs


def test_graph_reads_back_to_the_same_networks_and_readout(config, trained, tmp_path):
    saved, _, _ = trained
    back = mc.read_nir_multichannel(
        mc.write_nir_multichannel(tmp_path / "net.nir", config, saved, 0.4, 0.2)
    )
    network, inputs = whole_network(config)
    assert network.n_spll == 7
    np.testing.assert_array_equal(back.network.matrix(), network.matrix())
    np.testing.assert_array_equal(back.network.scales, network.scales)
    np.testing.assert_array_equal(back.inputs, inputs)
    assert back.config.groups == config.groups
    originals = [g.network.build() for g in config.groups for _ in g.channels]
    for mine, theirs in zip(back.channel_networks(), originals, strict=True):
        np.testing.assert_array_equal(mine.matrix(), theirs.matrix())
    r, b = saved.readout, back.readout.readout
    np.testing.assert_array_equal(b.weights, r.weights)
    np.testing.assert_array_equal(b.bias, r.bias)
    assert (b.class_names, b.bits) == (NAMES, None)
    np.testing.assert_array_equal(back.readout.levels, saved.levels)
    assert (back.threshold, back.not_before) == (0.4, 0.2)


def test_the_graph_states_the_readout_in_standard_nodes(config, trained):
    saved, _, _ = trained
    graph = mc.to_nir_multichannel(config, saved, 0.5)
    assert graph.nodes["input"].input_type["input"].tolist() == [3]
    fanout = graph.nodes["fanout"].weight
    assert fanout.shape == (7, 3) and fanout.sum(axis=0).tolist() == [3, 2, 2]
    affine, decision = graph.nodes["readout"], graph.nodes["decision"]
    assert isinstance(affine, nir.Affine) and isinstance(decision, nir.IF)
    assert affine.weight.shape == (3, 7) and decision.v_threshold.tolist() == [0.5] * 3
    assert ("tde", "readout") in graph.edges and ("decision", "decision_output") in graph.edges
    assert graph.metadata["spll_hw_not_before"] == START
    assert "winner-take-all" in graph.metadata["spll_hw_decision"]


def test_read_back_graph_decides_as_the_original(config, trained, tmp_path):
    saved, held, held_runs = trained
    back = mc.read_nir_multichannel(
        mc.write_nir_multichannel(tmp_path / "net.nir", config, saved, 1.0)
    )
    runs = tde_runs(back.channel_networks(), held)
    for mine, theirs in zip(runs, held_runs, strict=True):
        for a, b in zip(mine, theirs, strict=True):
            np.testing.assert_array_equal(a, b)
    got = back.decisions(runs, DURATION)
    want = engine_decisions(saved.readout, held_runs, DURATION, [1.0], START)
    for field in ("labels", "times", "fired"):
        np.testing.assert_array_equal(getattr(got, field), getattr(want, field))
    # decisions that could differ: every class decided, by a spike and at the end
    assert np.unique(got.labels).size == 3 and got.fired.any() and not got.fired.all()
    assert (got.times[got.fired] >= START).all()


def test_a_network_without_readout_reads_back(config, tmp_path):
    back = mc.read_nir_multichannel(mc.write_nir_multichannel(tmp_path / "n.nir", config))
    assert back.readout is None and "readout" not in mc.to_nir_multichannel(config).nodes
    np.testing.assert_array_equal(back.network.matrix(), whole_network(config)[0].matrix())
    with pytest.raises(ValueError, match="no readout"):
        back.decisions([], DURATION)


def test_without_threshold_the_end_decides_and_a_wrong_file_is_not_kept(config, trained, tmp_path):
    saved, held, held_runs = trained
    back = mc.read_nir_multichannel(mc.write_nir_multichannel(tmp_path / "n.nir", config, saved))
    assert back.threshold == np.inf
    got = back.decisions(held_runs, DURATION)
    assert not got.fired.any() and (got.times == DURATION).all()
    np.testing.assert_array_equal(got.labels[:, 0], np.repeat(np.arange(3), 2))
    # a file that reads back to another network than the one meant is refused
    other = MultichannelConfig.from_document(
        tomllib.loads(CONFIG.replace("f_end = 40.0", "f_end = 41.0")), Path("other.toml")
    )
    with pytest.raises(ValueError, match="n.nir does not read back to the network"):
        mc.check_read_back(tmp_path / "n.nir", other, saved, np.inf)
    with pytest.raises(ValueError, match="does not read back"):
        mc.check_read_back(tmp_path / "n.nir", config, saved, 2.0)


def test_a_readout_of_another_network_is_refused(config, trained):
    saved, _, _ = trained
    r = saved.readout
    fewer = dataclasses.replace(saved, readout=Readout(r.weights[:, :5], r.bias, NAMES))
    with pytest.raises(ValueError, match="takes 5 TDE features, .* has 7 TDEs"):
        mc.to_nir_multichannel(config, fewer, 1.0)
    other = dataclasses.replace(saved, channels=("a", "c", "b"))
    with pytest.raises(ValueError, match="trained on a, c, b"):
        mc.to_nir_multichannel(config, other, 1.0)
    with pytest.raises(ValueError, match="threshold must be > 0"):
        mc.to_nir_multichannel(config, saved, 0.0)


def test_an_edited_graph_is_refused(config, trained):
    saved, _, _ = trained
    graph = mc.to_nir_multichannel(config, saved, 1.0)
    graph.nodes["readout"] = nir.Affine(weight=saved.readout.weights[:2], bias=np.zeros(2))
    with pytest.raises(ValueError, match="one row per class"):
        mc.from_nir_multichannel(graph)
    graph = mc.to_nir_multichannel(config, saved, 1.0)
    graph.nodes["fanout"] = nir.Linear(weight=np.ones((7, 3)))
    with pytest.raises(ValueError, match="channel one-hot"):
        mc.from_nir_multichannel(graph)
    graph = mc.to_nir_multichannel(config, saved, 1.0)
    del graph.metadata["spll_hw_levels"]
    with pytest.raises(ValueError, match=r"no metadata \['spll_hw_levels'\]"):
        mc.from_nir_multichannel(graph)
    graph = mc.to_nir_multichannel(config, saved, 1.0)
    graph.metadata["spll_hw_format"] = "other"
    with pytest.raises(ValueError, match="not an spll-hw multichannel NIR graph"):
        mc.from_nir_multichannel(graph)


def test_readout_file_round_trip_and_bad_files(trained, tmp_path):
    saved, _, _ = trained
    quantized = dataclasses.replace(saved, readout=saved.readout.quantized(8))
    back = load_readout(save_readout(tmp_path / "r.npz", quantized))
    np.testing.assert_array_equal(back.readout.weights, quantized.readout.weights)
    np.testing.assert_array_equal(back.readout.bias, quantized.readout.bias)
    assert (back.readout.bits, back.readout.class_names) == (8, NAMES)
    assert back.channels == saved.channels
    np.testing.assert_array_equal(back.levels, saved.levels)
    arrays = dict(class_names=np.array(NAMES), bits=0, channels=np.array(["a"]), levels=[1.0])
    np.savez(tmp_path / "bad.npz", weights=np.ones((3, 7)), bias=np.ones(2), **arrays)
    with pytest.raises(ValueError, match=r"bad.npz: bias has shape \(2,\), expected \(3,\)"):
        load_readout(tmp_path / "bad.npz")
    np.savez(tmp_path / "other.npz", x=np.ones(2))
    with pytest.raises(ValueError, match="other.npz: not a readout file"):
        load_readout(tmp_path / "other.npz")
    with pytest.raises(FileNotFoundError, match="no such readout file"):
        load_readout(tmp_path / "none.npz")


def test_cli_exports_the_network_with_its_readout(config, trained, tmp_path, capsys):
    saved, _, _ = trained
    (tmp_path / "mc.toml").write_text(CONFIG)
    readout = save_readout(tmp_path / "r.npz", saved)
    out = tmp_path / "export"
    argv = ["export", "--to", "nir", "--network", str(tmp_path / "mc.toml"), "--out", str(out)]
    assert main([*argv, "--readout", str(readout), "--threshold", "0.75"]) == 0
    printed = capsys.readouterr().out
    assert "7 sPLLs of 3 channels and a 3-class readout" in printed
    assert f"how each part was checked: {out / 'README.md'}" in printed
    files = ["network.nir", "multichannel.toml", "README.md"]
    assert [line.strip() for line in printed.splitlines()[1:]] == [str(out / f) for f in files]
    back = mc.read_nir_multichannel(out / "network.nir")
    assert back.threshold == 0.75
    np.testing.assert_array_equal(back.readout.readout.weights, saved.readout.weights)
    assert MultichannelConfig.load(out / "multichannel.toml").groups == config.groups
    assert "Winner-take-all" in (out / "README.md").read_text()
    assert main([*argv, "--readout", str(readout)]) != 0
    assert "--readout FILE and --threshold THETA go together" in capsys.readouterr().err
    assert main(["export", "--to", "nir", "--out", str(out), "--readout", str(readout)]) != 0
    assert "--readout and --threshold need a multichannel --network" in capsys.readouterr().err


def test_a_multichannel_export_goes_through_the_registry(tmp_path, capsys):
    """The target's exporter declares its multichannel writer (``nir``'s does); any other
    target is refused before anything is written, naming the targets that can."""
    from spll_hw import exporters

    assert exporters.multichannel_writer("nir") is exporters.get("nir").multichannel
    (tmp_path / "mc.toml").write_text(CONFIG)
    out = tmp_path / "lava"
    argv = ["export", "--to", "lava", "--network", str(tmp_path / "mc.toml")]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--to lava exports one sPLL network; give --to " in err, err
    able = err.split("give --to ")[1].split(" or ")
    assert [t.strip() for t in able] == ["lava-standard", "nir", "nir-standard"], err
    assert not out.exists()
