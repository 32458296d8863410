"""A multichannel network exported for clocked consumers (spll-hw export --network MULTICHANNEL
--to nir-standard|lava-standard; mappings/nir/multichannel_standard.py,
spll_hw/exporters/multichannel.py): each channel group a checked export of its own, checked on
its channels' encoded BioTac signals, the readout as standard nodes at the groups' common step,
and decisions.json reproduced from the folder's own files."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import multichannel_standard as mcs  # noqa: E402
from mappings.nir.executor import NODE_TYPES, neuron_nodes  # noqa: E402
from mappings.nir.files import read_graph  # noqa: E402
from spll_hw.cli.main import main  # noqa: E402
from spll_hw.exporters.checked_folder import ExportOptions  # noqa: E402
from spll_hw.exporters.multichannel import CHECK_RECORDINGS  # noqa: E402
from spll_hw.multichannel.config import MultichannelConfig  # noqa: E402
from spll_hw.multichannel.readout import START, Readout, StagedReadout  # noqa: E402
from spll_hw.multichannel.readout_file import SavedReadout, save_readout  # noqa: E402

from .pipeline_data import BIOTAC_DIR, needs_biotac  # noqa: E402
from .test_multichannel_data import ROW_SPLL  # noqa: E402


def _table(channels: str, f_start: float, f_end: float, n: int) -> str:
    """A ``[[channel]]`` table: ``n`` time-scaled sPLLs of :data:`ROW_SPLL` over
    ``f_start``-``f_end`` Hz through a slow LIF encoder, for ``channels`` (a TOML list)."""
    network = f'layout = "time-scaled"\nf_start = {f_start}\nf_end = {f_end}\nn = {n}'
    encoder = 'name = "lif"\ntau = 0.05\nt_ref = 0.01\ngain = 1000.0'
    return (f"\n[[channel]]\nchannels = {channels}\n[channel.spll]\n{ROW_SPLL}"
            f"[channel.network]\n{network}\n[channel.encoder]\n{encoder}\n")  # fmt: skip


CONFIG = _table('["ele1"]', 2.0, 45.0, 3) + _table('["ele2", "tdc"]', 4.0, 30.0, 2)
#: Length [s] of the decisions check's runs here (the export's default is 4 s).
DURATION = 1.0
CLASSES = tuple(m for m, _ in CHECK_RECORDINGS)


def small_config() -> MultichannelConfig:
    """:data:`CONFIG` (``.ci/small_multichannel.py`` exports it in CI's consumer venv)."""
    return MultichannelConfig.from_document(tomllib.loads(CONFIG), Path("small.toml"))


@pytest.fixture(scope="module")
def config() -> MultichannelConfig:
    return small_config()


def readout(config, rng, stages: int = 1) -> SavedReadout:
    """A readout of random weights that decides within the run: every TDE's ~10-40 spikes a
    second move the membranes by a few thresholds."""
    k, d = len(CLASSES), config.n_spll
    made = [Readout(rng.normal(0, 0.02, (k, d)), rng.normal(0, 0.2, k), CLASSES)
            for _ in range(stages)]  # fmt: skip
    staged = made[0] if stages == 1 else StagedReadout(tuple(made), (START, 0.5)[:stages])
    return SavedReadout(staged, config.channels, np.array([30.0, 30.0, 30.0]))


def test_export_refuses_an_integer_readout_that_lost_on_its_training_runs(config, tmp_path, capsys):
    (tmp_path / "small.toml").write_text(CONFIG)
    made = readout(config, np.random.default_rng(0))
    four = SavedReadout(made.readout.quantized(4), made.channels, made.levels, (9.4, 0.5))
    path = save_readout(tmp_path / "r.npz", four)
    argv = ["export", "--network", str(tmp_path / "small.toml"), "--readout", str(path),
            "--threshold", "0.2", "--to", "nir"]  # fmt: skip
    assert main([*argv, "--out", str(tmp_path / "refused")]) == 2
    err = capsys.readouterr().err
    assert f"--readout {path}: its 4-bit weights decide the training recordings 9.4" in err
    assert not (tmp_path / "refused").exists()
    assert main([*argv, "--allow-error", "--out", str(tmp_path / "allowed")]) == 0
    assert (tmp_path / "allowed" / "network.nir").is_file()


def test_the_readout_runs_at_the_groups_common_step():
    assert mcs.readout_step([1e-4, 5e-5]) == pytest.approx(1e-4)
    assert mcs.readout_step([2e-5, 5e-5, 1e-4]) == pytest.approx(1e-4)
    assert mcs.readout_step([1e-5]) == pytest.approx(1e-5)
    with pytest.raises(ValueError, match="no common multiple up to 0.001 s"):
        mcs.readout_step([3.3e-5, 1.7e-4])


@needs_biotac
@pytest.mark.parametrize("stages", [1, pytest.param(2, marks=pytest.mark.slow)])
def test_groups_are_checked_on_their_channels_and_the_decisions_reproduce(config, tmp_path, stages):
    saved = readout(config, np.random.default_rng(stages), stages)
    out = tmp_path / "export"
    files = mcs.export_multichannel_standard(
        config, out, saved, 0.2, data=BIOTAC_DIR, options=ExportOptions(check_duration=0.5),
        duration=DURATION,
    )  # fmt: skip
    assert all(f.is_file() for f in files) and len(set(files)) == len(files)
    manifest = json.loads((out / "multichannel.json").read_text())
    groups = manifest["groups"]
    assert [g["folder"] for g in groups] == ["channels/1-ele1", "channels/2-ele2-tdc"]
    assert [g["channels"] for g in groups] == [["ele1"], ["ele2", "tdc"]]
    for g in groups:  # every channel of a group is checked on its own encoded recordings
        check = json.loads((out / g["folder"] / "check.json").read_text())
        encoded = [x["label"] for x in check["inputs"] if x["kind"] == "encoded-recording"]
        for channel in g["channels"]:
            assert sum(f" {channel}, lif encoder" in label for label in encoded) == 4, encoded
        assert g["dt"] == json.loads((out / g["folder"] / "standard.json").read_text())["dt"]
    dt = manifest["readout"]["dt"]
    assert dt == pytest.approx(mcs.readout_step([g["dt"] for g in groups]))
    graph = read_graph(out / "readout" / "network.nir")
    assert {type(node).__name__ for node in graph.nodes.values()} <= set(NODE_TYPES)
    assert graph.nodes["a_input"].input_type["input"].tolist() == [config.n_spll]

    made = json.loads((out / "decisions.json").read_text())
    readme = (out / "README.md").read_text()
    for d in made["decisions"]:  # the README's table of the check's decisions
        assert f"| {d['recording']} | {d['class']} | {d['exported']['class']} at " in readme
    assert [d["recording"].split()[0] for d in made["decisions"]] == [
        f"raw_data/{m}/{m}_{n}_bio.csv" for m, n in CHECK_RECORDINGS
    ]
    with np.load(out / "check_inputs.npz") as data:  # the folder's own files reproduce them
        trains = {c: [data[f"r{r}/{c}"] for r in range(4)] for c in config.channels}
        assert float(data["duration"]) == DURATION
    again, tde = mcs.executor_decisions(out, config, manifest, trains, 4, DURATION)
    for want, (label, step, fired) in zip(made["decisions"], again, strict=True):
        mine = want["exported"]
        assert (mine["label"], mine["step"], mine["fired"]) == (label, step, fired)
        assert mine["time_s"] == pytest.approx(step * dt)
        assert 0 <= want["golden"]["label"] < len(CLASSES)
    back, theta = mcs.folder_readout(out)  # what a benchmark decides held-out runs by
    assert theta == 0.2 and np.array_equal(back.levels, saved.levels)
    np.testing.assert_array_equal(back.readout.weights, saved.readout.weights)
    assert tde.shape == (round(DURATION / dt), 4, config.n_spll)
    assert tde.sum() > 100  # the TDEs fire on every channel's signal
    fired = [d["exported"]["fired"] for d in made["decisions"]]
    assert any(fired), made  # the threshold is reached within the run
    # the graph's decisions are golden's where its TDE counts are near golden's
    same = sum(d["exported"]["label"] == d["golden"]["label"] for d in made["decisions"])
    assert same >= 3, made["decisions"]
    _the_cost_is_of_every_part_and_decision(out, groups, made, readme)


def _the_cost_is_of_every_part_and_decision(out, groups, made, readme):
    cost = json.loads((out / "cost.json").read_text())
    parts = cost["parts"]
    assert [p["part"] for p in parts] == [g["folder"] for g in groups] + ["readout"]
    assert [p["copies"] for p in parts] == [len(g["channels"]) for g in groups] + [1]
    assert cost["cores"] == sum(p["cores_each"] * p["copies"] for p in parts) >= len(parts)
    sizes = json.loads((out / groups[0]["folder"] / "cost.json").read_text())
    assert parts[0]["neurons"] == sizes["neurons"]  # the group's graph, as its own folder costs it
    readout = read_graph(out / "readout" / "network.nir")
    assert parts[-1]["neurons"] == sum(
        readout.nodes[n].v_threshold.size for n in neuron_nodes(readout)
    )
    power = 0.0
    for p in parts:
        low, high = p["dynamic_w"]["range"]
        assert 0 < low <= p["dynamic_w"]["value"] <= high
        power += p["dynamic_w"]["value"]
    assert cost["dynamic_w"]["value"] == pytest.approx(power)
    for d, c in zip(made["decisions"], cost["decisions"], strict=True):
        assert c["recording"] == d["recording"] and c["fired"] == d["exported"]["fired"]
        assert c["time_s"] == pytest.approx(d["exported"]["time_s"] if c["fired"] else DURATION)
        for key in ("value", "range"):
            assert np.allclose(
                c["per_decision"][key], np.multiply(c["dynamic_w"][key], c["time_s"])
            )
    assert cost["per_decision"]["value"] == pytest.approx(
        np.mean([c["per_decision"]["value"] for c in cost["decisions"]])
    )
    assert "## What it costs on a chip" in readme and f"**{cost['cores']} cores**" in readme


@needs_biotac
def test_cli_exports_through_the_registry_and_lava_standard_refuses_a_readout(
    config, tmp_path, capsys
):
    (tmp_path / "small.toml").write_text(CONFIG)
    path = save_readout(tmp_path / "r.npz", readout(config, np.random.default_rng(0)))
    out = tmp_path / "lava"
    argv = ["export", "--network", str(tmp_path / "small.toml"), "--readout", str(path),
            "--threshold", "0.2", "--out", str(out)]  # fmt: skip
    assert main([*argv, "--to", "lava-standard"]) == 2
    assert "drop --readout and --threshold (--to nir-standard writes" in capsys.readouterr().err
    assert not out.exists()
    out = tmp_path / "nir"
    argv[-1] = str(out)
    assert main([*argv, "--to", "nir-standard", "--check-duration", "0.5"]) == 0
    printed = capsys.readouterr().out
    assert "7 sPLLs of 3 channels and a 4-class readout exported to nir-standard" in printed
    readme = (out / "README.md").read_text()
    assert "| `channels/2-ele2-tdc` | ele2, tdc | 2 |" in readme
    assert "Checked on the reference trains only" in readme  # no --data: no decisions check
    assert not (out / "decisions.json").exists()
    assert (out / "readout" / "decide.py").is_file() and (out / "readout" / "readout.npz").is_file()


def test_lava_standard_exports_the_groups_or_refuses_one_by_name(config, tmp_path, capsys):
    """Group 1 passes on a clock per sPLL; Loihi's 12-bit decays cannot hold group 2's slow
    time constants at any step of the ladder: the export is refused naming the group, and
    nothing is written (group 1's folder neither)."""
    (tmp_path / "small.toml").write_text(CONFIG)
    out = tmp_path / "lava"
    argv = ["export", "--network", str(tmp_path / "small.toml"), "--to", "lava-standard",
            "--out", str(out), "--check-duration", "0.5"]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "a clock per sPLL (R = 4), 32 band-quantile gate levels: TDE-rate error" in err
    assert "channel group 2 (ele2, tdc): lava-standard: no time step" in err, err
    assert not out.exists()
