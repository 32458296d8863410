"""The declared tolerance of a fixed-point profile from a TOML file (issue 62): the default
limit of ``spll-hw export --to lava``'s check was looked up by the profile's name, so any
profile file (a copy of loihi2 included) got the worst measured, 58.5 % at 10 µs. Now a profile
has its own ``tolerance`` key's, else that of the measured bundled profile whose integer formats
it has, else the worst with a sentence that says so; the verdict names the rule that applied."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

import quantize
from mappings.fixed_point.backend import ARITHMETIC_ERROR_10US, declared_tolerance, rate_tolerance
from spll_hw import backends
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

LOIHI2 = rate_tolerance(ARITHMETIC_ERROR_10US["loihi2"], 1e-5)  # 16.5 % at 10 µs
WORST = rate_tolerance(ARITHMETIC_ERROR_10US["fixed16"], 1e-5)  # 58.5 % at 10 µs
DOCUMENTED_VARIANT = Path(__file__).resolve().parents[1] / "docs" / "profiles" / "loihi2-80us.toml"


def _variant(path: Path, *keys: str) -> Path:
    """A variant of loihi2 named by the file's stem, with ``keys`` (TOML lines) in its
    ``[fixed_point]`` table."""
    path.write_text(f'[profile]\nbase = "loihi2"\nname = "{path.stem}"\ndescription = "a test '
                    'chip"\n\n[fixed_point]\n' + "\n".join(keys) + "\n")  # fmt: skip
    return path


def _copy_of_loihi2(tmp_path: Path) -> Path:
    """loihi2 written whole under another name (what a user's chip file of the same formats is)."""
    path = tmp_path / "mychip.toml"
    loihi2 = quantize.load_profile("loihi2")
    path.write_text(quantize.profile_toml(dataclasses.replace(loihi2, name="mychip")))
    return path


def test_a_copy_of_a_bundled_profile_gets_its_measured_tolerance(tmp_path):
    assert LOIHI2 == pytest.approx(0.165) and WORST == pytest.approx(0.585)
    assert declared_tolerance(quantize.load_profile("loihi2")) == (LOIHI2, "")
    tolerance, why = declared_tolerance(quantize.load_profile(_copy_of_loihi2(tmp_path)))
    assert tolerance == LOIHI2
    assert why == ("profile mychip has the integer formats of bundled loihi2, so loihi2's "
                   "measured arithmetic at dt = 1e-05 s")  # fmt: skip
    at_80us = rate_tolerance(ARITHMETIC_ERROR_10US["loihi2"], 8e-5)  # 15.2 %, not the worst 24.0 %
    assert declared_tolerance(quantize.load_profile("loihi2@80us")) == (at_80us, "")
    assert declared_tolerance(quantize.load_profile(DOCUMENTED_VARIANT))[0] == at_80us
    fixed16 = rate_tolerance(ARITHMETIC_ERROR_10US["fixed16"], 1e-4)  # at its own 100 µs
    assert declared_tolerance(quantize.load_profile("fixed16")) == (fixed16, "")


def test_other_formats_get_the_worst_unless_the_profile_declares_its_own(tmp_path):
    other = quantize.load_profile(_variant(tmp_path / "other.toml", "current_shift_max = 4"))
    tolerance, why = declared_tolerance(other)
    assert tolerance == WORST
    assert "profile other has the integer formats of no measured bundled profile" in why
    assert "declare tolerance in its [fixed_point] table, or give --max-error" in why
    own = quantize.load_profile(
        _variant(tmp_path / "own.toml", "current_shift_max = 4", "tolerance = 0.2")
    )
    assert declared_tolerance(own) == (0.2, "profile own's own [fixed_point] tolerance = 0.2")
    assert declared_tolerance(own.with_dt(5e-5))[0] == 0.2  # at every step
    assert quantize.load_profile(tmp_path / "own.toml").tolerance == 0.2
    whole = tmp_path / "whole.toml"  # an export folder's profile.toml keeps the key
    whole.write_text(quantize.profile_toml(own))
    assert "tolerance = 0.2" in whole.read_text() and quantize.load_profile(whole) == own
    spec = f"golden-fixed-point:profile={tmp_path / 'own.toml'}"
    assert backends.get(spec).capabilities.rate_tolerance == 0.2


@pytest.mark.parametrize("value", ["1.5", "0", "-0.1", "nan", "inf", '"0.1"', "true"])
def test_a_bad_tolerance_is_refused_naming_file_and_key(tmp_path, value):
    path = _variant(tmp_path / "bad.toml", f"tolerance = {value}")
    with pytest.raises(quantize.ProfileError) as info:
        quantize.load_profile(path)
    message = str(info.value)
    assert message.startswith(f"{path}: profile 'bad' [fixed_point]: tolerance"), message


def test_export_to_lava_states_which_limit_applied_and_why(tmp_path, capsys):
    network = tmp_path / "two.toml"
    network.write_text(NetworkConfig.preset("vibtac-vary-offset-lif").with_n(2).to_toml())
    argv = ["export", "--to", "lava", "--network", str(network), "--profiles"]
    copy = tmp_path / "copy"
    assert main([*argv, str(_copy_of_loihi2(tmp_path)), "--out", str(copy)]) == 0
    out = capsys.readouterr().out
    assert ("limit 16.5 % (`golden-fixed-point:profile=mychip:dt=1e-05`'s declared tolerance: "
            "profile mychip has the integer formats of bundled loihi2") in out  # fmt: skip
    record = json.loads((copy / "check.json").read_text())
    assert record["tolerance"] == record["max_error"] == pytest.approx(LOIHI2)
    assert record["tolerance_basis"].startswith("profile mychip has the integer formats")

    own = _variant(tmp_path / "own.toml", "tolerance = 0.5")
    folder = tmp_path / "own"
    assert main([*argv, str(own), "--out", str(folder)]) == 0
    said = "limit 50.0 % (`golden-fixed-point:profile=own:dt=1e-05`'s declared tolerance: "
    said += "profile own's own [fixed_point] tolerance = 0.5)"
    assert said in capsys.readouterr().out
    assert main(["export", "--check", str(folder)]) == 0  # the folder's profile.toml keeps it
    assert said in capsys.readouterr().out

    bad = _variant(tmp_path / "bad.toml", "tolerance = 1.5")
    assert main([*argv, str(bad), "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert (
        f"{bad}: profile 'bad' [fixed_point]: tolerance = 1.5 must be a fraction in (0, 1]" in err
    )
    assert not (tmp_path / "bad").exists()
