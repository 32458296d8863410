"""The command line never presents bad input as a result: each case found by trying it."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from spll_hw import backends
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.harness.metrics import rate_error
from spll_hw.simulate import poisson_spikes


def test_version_and_python_dash_m():
    done = subprocess.run([sys.executable, "-m", "spll_hw", "--version"], capture_output=True,
                          text=True, timeout=60)  # fmt: skip
    assert done.returncode == 0 and done.stdout.startswith("spll-hw ")


def test_help_lists_presets_backends_and_profiles(capsys):
    assert main(["report", "--help"]) == 0
    # argparse wraps long names at their hyphens: compare without any whitespace.
    text = "".join(capsys.readouterr().out.split())
    for name in ("biotac-vary-offset-lif", "golden-fixed-point", "loihi2", "analog"):
        assert name in text


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ('beta = "x"', "beta must be a number >= 0"),
        ("n = 2.5", "n must be a whole number of sPLLs >= 1, got 2.5"),
        ("f_start = -1.0", "f_start must be a finite number of Hz > 0"),
        ('layout = "grouped:x"', "unknown network layout 'grouped:x'"),
    ],
)
def test_wrong_types_in_a_network_file_name_file_and_key(tmp_path, capsys, line, message):
    key = line.split()[0]
    text = NetworkConfig.preset("vibtac-vary-offset-lif").to_toml()
    kept = [row for row in text.splitlines() if not row.startswith(f"{key} ")]
    path = tmp_path / "net.toml"
    path.write_text("\n".join(kept).replace("[network]", f"[network]\n{line}") + "\n")
    out = tmp_path / "out"
    assert main(["simulate", "--network", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{path} [network]: {message}" in err and "Traceback" not in err
    assert not out.exists()


def test_an_unwritable_out_fails_before_any_work(tmp_path, capsys):
    blocker = tmp_path / "file.txt"
    blocker.write_text("not a folder")
    assert main(["report", "--out", str(blocker / "report")]) == 2
    assert (
        f"--out {blocker / 'report'}: {blocker} is a file, not a folder" in capsys.readouterr().err
    )


def test_a_two_dimensional_spike_file_is_refused_not_flattened(tmp_path, capsys):
    spikes = tmp_path / "spikes.npy"
    np.save(spikes, np.array([[0.1, 0.2], [0.3, 0.4]]))
    assert main(["simulate", "--input", str(spikes), "--out", str(tmp_path / "o")]) == 2
    assert "a (2, 2) array; a spike file holds one train" in capsys.readouterr().err
    np.save(spikes, np.array([[0.1], [0.3]]))  # one column is one train
    assert main(["simulate", "--input", str(spikes), "--out", str(tmp_path / "o")]) == 0


def test_spikes_after_the_duration_are_reported_not_silently_dropped(tmp_path, capsys):
    spikes = tmp_path / "spikes.csv"
    spikes.write_text("0.1\n0.2\n0.9\n1.5\n")
    out = tmp_path / "o"
    args = ["simulate", "--input", str(spikes), "--duration", "0.5", "--out", str(out)]
    assert main(args) == 0
    assert "2 input spike(s) after --duration 0.5 s were not simulated" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    assert results["n_input_spikes"] == 2 and results["inputs_after_end"] == 2
    assert "(2 more after the end, not simulated)" in (out / "summary.md").read_text()


def test_fit_says_what_a_network_needs_and_grouped_auto_takes_the_largest_that_fits(capsys):
    args = ["fit", "--network", "vibtac-vary-offset-lif", "--profiles"]
    assert main([*args, "analog", "--layouts", "time-scaled"]) == 1
    assert "at most 8 are available" in capsys.readouterr().out
    assert main([*args, "analog", "--layouts", "grouped:auto"]) == 0
    assert "grouped:auto on analog: grouped:8 is the largest that fits" in capsys.readouterr().out
    assert main([*args, "loihi2", "--layouts", "vary-offset"]) == 0
    out = capsys.readouterr().out
    assert "**loihi2**: 50 sPLLs" in out
    # the chip's own arithmetic against golden, said where the network is designed
    network = NetworkConfig.preset("vibtac-vary-offset-lif").with_layout("vary-offset").build()
    train = poisson_spikes(float(np.median(network.free_frequencies())), 1.0, seed=0)
    golden = backends.get("golden").simulate(network, train, 1.0)
    chip = backends.get("golden-fixed-point:profile=loihi2").simulate(network, train, 1.0)
    error = rate_error(chip, golden)
    assert "(`golden-fixed-point:profile=loihi2`), on a 1-s Poisson train" in out
    assert f"the TDE rates are {100 * error:.1f} % off golden" in out
    assert main([*args, "dynapse2", "--layouts", "vary-offset"]) == 0
    out = capsys.readouterr().out
    assert "4 core(s) on 1 chip(s)" in out and "integer arithmetic" not in out  # analog chip
    assert main([*args, "dynapse2", "--layouts", "grouped:2"]) == 1
    assert "does not fit: needs 8 cores" in capsys.readouterr().out
    assert main([*args, "loihi3"]) == 2


def test_a_warning_is_one_line_of_the_command_not_python_s_source_line(tmp_path):
    """A network file without [network] is run on stated defaults, and the warning that says so
    reads as the command's own line (issue 62: it came in Python's FILE:LINE: UserWarning
    format with a line of spll-hw's source below)."""
    text = NetworkConfig.preset("vibtac-vary-offset-lif").to_toml()
    kept = [t for t in text.split("\n[") if not t.startswith("network]")]
    path = tmp_path / "nonet.toml"
    path.write_text("\n[".join(kept))
    done = subprocess.run(  # pytest records warnings itself: the CLI as a user runs it
        [sys.executable, "-m", "spll_hw", "fit", "--network", str(path), "--profiles", "loihi2"],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert done.stderr.strip().splitlines() == [
        f"spll-hw fit: warning: {path}: no [network] table, so the defaults are used: 50 "
        "vary-offset sPLLs over 56.2-668 Hz (the VibTac band); add [network] with layout, "
        "f_start, f_end and n to say what you mean"
    ]
