"""``spll-hw simulate`` / ``response`` and the network TOML format."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from spll_hw import simulate
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig


def test_config_round_trip_and_layouts(tmp_path):
    config = NetworkConfig.preset("biotac-time-scaled-pacinian")
    assert config.layout == "time-scaled" and config.beta == 10.0
    path = tmp_path / "net.toml"
    path.write_text(config.to_toml())
    again = NetworkConfig.from_toml(path)
    assert again == config
    np.testing.assert_array_equal(again.build().matrix(), config.build().matrix())
    linear = NetworkConfig.preset("vibtac-vary-offset-pacinian")
    path.write_text(linear.to_toml())
    assert "beta = inf" in path.read_text() and math.isinf(NetworkConfig.from_toml(path).beta)
    grouped = config.with_layout("grouped:4").build()
    assert grouped.layout == "grouped" and len(set(grouped.groups)) == 4
    diverse = replace(config, spread=0.25, spread_seed=4)
    path.write_text(diverse.to_toml())
    assert "spread = 0.25\nspread_seed = 4" in path.read_text()
    assert NetworkConfig.from_toml(path) == diverse
    np.testing.assert_array_equal(
        diverse.build().matrix(), config.build().with_spread(0.25, seed=4).matrix()
    )


@pytest.mark.parametrize(
    "text,message",
    [
        ("[spll]\ntau_cco = 1.0\n", "missing sPLL parameter"),
        ("[network]\nn = 5\n", r"no \[spll\] table"),
        ("[extra]\n", "unknown table"),
        ("x = = 1", "not valid TOML"),
    ],
)
def test_config_errors_name_the_file(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=message) as info:
        NetworkConfig.from_toml(path)
    assert "bad.toml" in str(info.value)


def test_config_rejects_unknown_network_keys_and_layouts(tmp_path):
    base = NetworkConfig.preset("vibtac-vary-offset-lif")
    path = tmp_path / "net.toml"
    path.write_text(base.to_toml() + "f_stop = 3\n")
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['f_stop'\]"):
        NetworkConfig.from_toml(path)
    path.write_text(base.to_toml().replace('"vary-offset"', '"grouped:0"'))
    with pytest.raises(ValueError, match="unknown network layout"):
        NetworkConfig.from_toml(path)
    with pytest.raises(ValueError, match="unknown sPLL network preset"):
        NetworkConfig.load("no-such-preset")
    for old, new, message in (
        ("spread = 0.0", "spread = -0.5", "spread must be"),
        ("spread_seed = 0", "spread_seed = 1.5", "spread_seed must be"),
    ):
        path.write_text(base.to_toml().replace(old, new))
        with pytest.raises(ValueError, match=message) as info:
            NetworkConfig.from_toml(path)
        assert "net.toml [network]" in str(info.value)


def test_simulate_command_writes_report_matching_the_api(tmp_path, capsys):
    spikes = np.sort(np.random.default_rng(1).uniform(0, 0.5, 150))
    np.save(tmp_path / "in.npy", spikes)
    out = tmp_path / "report"
    code = main(["simulate", "--input", str(tmp_path / "in.npy"), "--duration", "0.5",
                 "--out", str(out), "--layouts", "grouped:2"])  # fmt: skip
    assert code == 0
    for name in ("summary.md", "results.json", "rates.png", "activity.png", "params.toml"):
        assert (out / name).stat().st_size > 0
    results = json.loads((out / "results.json").read_text())
    config = NetworkConfig.from_toml(out / "params.toml")
    assert config.layout == "grouped:2"
    expected = simulate(config.build(), spikes, 0.5)
    np.testing.assert_allclose(results["tde_rate_hz"], expected.tde_rates)
    # every spike time in the binary file the JSON names, none in the JSON itself
    assert results["spikes_file"] == "spikes.npz" and "tde_spikes_s" not in results
    with np.load(out / results["spikes_file"]) as stored:
        for kind in ("tde", "cco"):
            times, offsets = stored[f"{kind}_times"], stored[f"{kind}_offsets"]
            trains = getattr(expected, f"{kind}_spikes")
            assert offsets.shape == (len(trains) + 1,) and offsets[-1] == times.size
            for i, train in enumerate(trains):
                np.testing.assert_array_equal(times[offsets[i] : offsets[i + 1]], train)
    assert not list(tmp_path.glob(".report.tmp-*"))  # the staging folder is gone
    # the terminal gets a table, one row per sPLL, not a numpy array
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"{len(trains)} sPLLs on `golden`, 150 input spikes in 0.5 s")
    first = lines[2].split()
    assert first[0] == "0" and float(first[2]) == pytest.approx(expected.tde_rates[0], abs=0.05)
    assert len([x for x in lines if x.startswith("  ")]) == len(trains) + 1
    assert results["against_golden"] is None  # golden ran: nothing to compare with


def test_simulate_on_a_chip_says_how_far_it_is_from_golden(tmp_path, capsys):
    spikes = np.sort(np.random.default_rng(2).uniform(0, 0.5, 150))
    np.save(tmp_path / "in.npy", spikes)
    out = tmp_path / "chip"
    args = ["simulate", "--input", str(tmp_path / "in.npy"), "--duration", "0.5",
            "--backend", "golden-fixed-point:profile=loihi2", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    results = json.loads((out / "results.json").read_text())
    network = NetworkConfig.from_toml(out / "params.toml").build()
    golden = simulate(network, spikes, 0.5)
    mine = np.asarray(results["tde_rate_hz"])
    expected = np.abs(mine - golden.tde_rates).sum() / golden.tde_rates.sum()
    assert results["against_golden"]["tde_rate_error"] == pytest.approx(expected)
    line = f"TDE-rate error {100 * expected:.1f} %"
    assert line in capsys.readouterr().out and line in (out / "summary.md").read_text()


def test_response_command(tmp_path):
    code = main(["response", "--points", "30", "--f-max", "80", "--duration", "1",
                 "--out", str(tmp_path)])  # fmt: skip
    assert code == 0
    table = np.loadtxt(tmp_path / "response.csv", delimiter=",", skiprows=1)
    assert table.shape == (30, 2) and table[:, 1].max() > 0
    assert (tmp_path / "response.png").stat().st_size > 0


def test_cli_errors_are_messages_not_tracebacks(tmp_path, capsys):
    bad = tmp_path / "in.txt"
    bad.write_text("0.1\nnan\n")
    assert main(["simulate", "--input", str(bad), "--out", str(tmp_path)]) == 2
    assert "not a finite time" in capsys.readouterr().err
    assert main(["simulate", "--network", str(tmp_path / "none.toml")]) == 2
    assert "no such parameter file" in capsys.readouterr().err
    assert main(["simulate", "--help"]) == 0
