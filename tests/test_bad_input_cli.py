"""Bad command-line input fails in the parser or at the first read, naming the flag or file and
its range, with exit status 2 (issue: the last bad inputs)."""

from __future__ import annotations

import pytest

from spll_hw.cli.main import main


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["simulate", "--rate", "-5"], "argument --rate/--poisson: must be a finite number > 0"),
        (["simulate", "--rate", "nan"], "must be a finite number > 0, got 'nan'"),
        (["simulate", "--duration", "-1"], "argument --duration: must be a finite number > 0"),
        (["simulate", "--seed", "-1"], "argument --seed: must be an integer >= 0, got '-1'"),
        (["evaluate", "--folds", "0"], "argument --folds: must be an integer > 0"),
        (["compare", "--duration", "inf"], "argument --duration: must be a finite number > 0"),
        (["response", "--f-min", "-3"], "argument --f-min: must be a finite number >= 0"),
    ],
)
def test_numbers_out_of_range_name_the_flag(argv, words, tmp_path, capsys):
    assert main([*argv, "--out", str(tmp_path)]) == 2
    assert words in capsys.readouterr().err


def test_a_value_in_an_unlikely_unit_is_flagged(tmp_path, capsys):
    argv = ["simulate", "--phase-noise", "0.5", "--duration", "0.05", "--out", str(tmp_path)]
    assert main(argv) == 0
    assert "--phase-noise 0.5 is in seconds" in capsys.readouterr().err


def test_unreadable_files_are_named(tmp_path, capsys):
    binary = tmp_path / "net.toml"
    binary.write_bytes(b"\xff\xfe\x00[spll]")
    assert main(["simulate", "--network", str(binary), "--out", str(tmp_path / "a")]) == 2
    assert f"{binary}: not a text file" in capsys.readouterr().err
    scalar = tmp_path / "five.toml"
    scalar.write_text("spll = 5\n")
    assert main(["simulate", "--network", str(scalar), "--out", str(tmp_path / "b")]) == 2
    assert f"{scalar} [spll]: must be a table" in capsys.readouterr().err
    truncated = tmp_path / "spikes.npy"
    truncated.write_bytes(b"\x93NUMPY\x01\x00")
    assert main(["simulate", "--input", str(truncated), "--out", str(tmp_path / "c")]) == 2
    assert f"{truncated}: not a readable .npy array" in capsys.readouterr().err
    profile = tmp_path / "chip.toml"
    profile.write_bytes(b"\xff\xfe")
    argv = ["simulate", "--backend", f"golden:profile={profile}", "--out", str(tmp_path / "d")]
    assert main(argv) == 2
    assert f"{profile}: not a text file" in capsys.readouterr().err


def test_an_empty_profile_says_what_to_give(tmp_path, capsys):
    argv = ["simulate", "--backend", "golden:profile=", "--out", str(tmp_path)]
    assert main(argv) == 2
    assert "profile is empty: give a profile name" in capsys.readouterr().err


def test_a_missing_extra_is_one_line_and_exit_2(monkeypatch, tmp_path, capsys):
    import builtins

    real = builtins.__import__

    def no_nir(name, *args, **kwargs):
        if name == "nir" or name.startswith("nir."):
            raise ModuleNotFoundError("No module named 'nir'")  # as without the [nir] extra
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_nir)
    argv = ["export", "--to", "nir-standard", "--out", str(tmp_path / "x")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "pip install" in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
