"""One vocabulary across the sub-commands, run for real (docs/cli.md, "Vocabulary" and "Exit
status"): the new names work, the old spellings still work and say in one line which name
replaced them, a command that takes one value refuses a list by name, ``fit``'s exit status
says whether the network fits, and a reader that closes the output early gets no traceback.

(``tests/test_cli_arguments.py`` parses every old spelling of every command against its new
name.)"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from spll_hw.cli.main import EXIT_PIPE_CLOSED, main
from spll_hw.config import NetworkConfig

#: DYNAP-SE2 cut to 2 cores: even one group of sPLLs needs 4 (a TDE core and 3 CCO biases).
TWO_CORES = (
    '[profile]\nbase = "dynapse2"\nname = "dynapse2-2cores"\n'
    'description = "DYNAP-SE2 with 2 cores: no grouped layout of an sPLL network fits"\n'
    '[resources]\ncores_per_chip = { value = 2, source = "a test: half the chip" }\n'
    'cores_per_tile = { value = 2, source = "a test: half the chip" }\n'
)


@pytest.fixture
def small_network(tmp_path):
    """A 4-sPLL time-scaled network file (grouped:auto tries every G up to n)."""
    path = tmp_path / "four.toml"
    path.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(4).to_toml())
    return path


def test_old_spellings_run_the_command_and_each_says_its_new_name(small_network, capsys):
    argv = ["fit", "--params", str(small_network), "--layout", "grouped:auto", "--profile",
            "analog"]  # fmt: skip
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert "grouped:auto on analog: grouped:4 is the largest that fits" in captured.out
    assert captured.err.splitlines() == [
        "spll-hw fit: --params is deprecated, use --network",
        "spll-hw fit: --layout is deprecated, use --layouts",
        "spll-hw fit: --profile is deprecated, use --profiles",
    ]


def test_the_new_names_run_the_command_and_say_nothing_else(small_network, tmp_path, capsys):
    assert main(["fit", "--network", str(small_network), "--layouts", "grouped:auto",
                 "--profiles", "analog,loihi2"]) == 0  # fmt: skip
    captured = capsys.readouterr()
    assert "## analog" in captured.out and "## loihi2" in captured.out
    assert "fits on: analog, loihi2" in captured.out
    assert "deprecated" not in captured.err
    out = tmp_path / "sim"
    assert main(["simulate", "--network", str(small_network), "--layouts", "grouped:2",
                 "--rate", "200", "--phase-noise", "0", "--duration", "0.2", "--out",
                 str(out)]) == 0  # fmt: skip
    assert (out / "summary.md").is_file() and "deprecated" not in capsys.readouterr().err
    assert main(["chips", "--profiles", "loihi2", "--windows", "2"]) == 0
    assert "deprecated" not in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["simulate", "--layouts", "grouped:2,grouped:4"], "--layouts"),
        (["export", "--to", "nir", "--profiles", "loihi1,loihi2"], "--profiles"),
        (["report", "--encoders", "lif,peak"], "--encoders"),
    ],
)
def test_a_command_that_takes_one_value_refuses_a_list_by_name(argv, flag, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"argument {flag}" in err and "takes one value in this command, got 2" in err


def test_grouped_auto_with_nothing_that_fits_is_a_no_not_bad_input(small_network, tmp_path,
                                                                   capsys):  # fmt: skip
    profile = tmp_path / "two-cores.toml"
    profile.write_text(TWO_CORES)
    argv = ["fit", "--network", str(small_network), "--layouts", "grouped:auto"]
    assert main([*argv, "--profiles", str(profile)]) == 1  # does not fit
    assert "does not fit: no grouped layout of this network fits" in capsys.readouterr().out
    assert main([*argv, "--profiles", f"{profile},analog"]) == 0  # fits one of them
    assert "fits on: analog" in capsys.readouterr().out
    assert main([*argv, "--profiles", str(tmp_path / "none.toml")]) == 2  # bad input


@pytest.mark.parametrize(
    ("argv", "status"),
    [(["chips"], EXIT_PIPE_CLOSED), (["fit", "--profiles", "loihi2"], EXIT_PIPE_CLOSED),
     (["export", "--help"], 0)],  # argparse drops what it cannot print: --help is done
    ids=["chips", "fit", "export --help"],
)  # fmt: skip
def test_a_reader_that_closes_the_output_early_gets_no_traceback(argv, status):
    """``spll-hw fit ... | head``: 141 (128 + SIGPIPE), nothing on stderr."""
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the command writes a byte
    done = subprocess.run([sys.executable, "-m", "spll_hw.cli.main", *argv], stdout=write,
                          stderr=subprocess.PIPE, text=True, timeout=120)  # fmt: skip
    os.close(write)
    assert done.returncode == status, done.stderr
    assert done.stderr == ""


def test_export_usage_shows_what_it_requires_and_out_has_a_default(
    small_network, tmp_path, monkeypatch, capsys
):
    assert main(["export", "--help"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("usage: spll-hw export (--to TARGET | --check FOLDER [--to TARGET])")
    assert "(default: reports/export)" in " ".join(text.split())
    assert main(["export"]) == 2
    assert "needs --to TARGET (or --check FOLDER" in capsys.readouterr().err
    pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")
    monkeypatch.chdir(tmp_path)
    argv = ["export", "--to", "nir", "--network", str(small_network), "--check-duration", "0.2"]
    assert main(argv) == 0
    assert (tmp_path / "reports" / "export" / "network.nir").is_file()
