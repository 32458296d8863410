"""One vocabulary across the sub-commands, run for real (docs/cli.md, "Vocabulary"): the new
names work, the old spellings still work and say in one line which name replaced them, and a
command that takes one value refuses a list by name.

(``tests/test_cli_arguments.py`` parses every old spelling of every command against its new
name.)"""

from __future__ import annotations

import pytest

from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig


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
