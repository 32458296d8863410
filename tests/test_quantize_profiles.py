"""Chip profiles: bundled TOML files, the generic N-bit profile, and every bad-input path."""

from __future__ import annotations

import dataclasses

import pytest

import quantize
from quantize import (
    AnalogProfile,
    FixedPointProfile,
    ProfileError,
    available_profiles,
    generic_fixed_point,
    load_profile,
    parse_profile,
)

LOIHI = """
[profile]
name = "chip"
kind = "fixed-point"
description = "a test chip"

[fixed_point]
dt = 1e-5
state_bits = 24
decay_bits = 12
refractory_bits = 8
weight_mantissa_bits = 8
weight_exponent_min = 0
weight_exponent_max = 13
trigger_shift_max = 24
current_shift_max = 0
bias_mantissa_bits = 13
bias_exponent_min = 0
bias_exponent_max = 7
threshold_mantissa_bits = 17
threshold_shift = 6
headroom_bits = 6
"""

ANALOG = """
[profile]
name = "mixed"
kind = "analog"
description = "a test analog chip"

[analog]
tau_sigma = 0.1
gain_sigma = 0.05
offset_levels = 16
max_groups = 8
seed = 3
"""


def edit(text: str, key: str, value: str | None) -> str:
    """``text`` with ``key = ...`` replaced by ``key = value`` (or removed when None)."""
    lines = []
    for line in text.splitlines():
        if line.split("=")[0].strip() == key:
            if value is not None:
                lines.append(f"{key} = {value}")
        else:
            lines.append(line)
    return "\n".join(lines) + "\n"


def test_bundled_profiles_load_with_their_documented_formats():
    assert {"analog", "fixed16", "loihi2"} <= set(available_profiles())
    loihi = load_profile("loihi2")
    assert isinstance(loihi, FixedPointProfile) and loihi.kind == "fixed-point"
    assert (loihi.state_bits, loihi.decay_bits, loihi.weight_mantissa_bits) == (24, 12, 8)
    assert (loihi.bias_mantissa_bits, loihi.bias_exponent_max) == (13, 7)
    assert (loihi.threshold_mantissa_bits, loihi.threshold_shift) == (17, 6)
    assert loihi.dt == 1e-5 and loihi.current_shift_max == 0
    # Threshold: the largest power of two below half the state range, held by the 17-bit
    # mantissa shifted by 6; the facilitatory weight is a power of two the weight format holds.
    assert loihi.threshold == 2**22 and (loihi.threshold >> 6) < 2**17
    assert loihi.fac_weight == 2**17 and loihi.state_max == 2**23 - 1
    analog = load_profile("analog")
    assert isinstance(analog, AnalogProfile) and analog.kind == "analog"
    assert analog.offset_levels >= 1 and analog.max_groups >= 1


def test_fixed16_is_the_generic_16_bit_profile():
    bundled = load_profile("fixed16")
    generic = generic_fixed_point(16, bundled.dt)
    same = {f.name for f in dataclasses.fields(FixedPointProfile)} - {"name", "description"}
    assert {k: getattr(bundled, k) for k in same} == {k: getattr(generic, k) for k in same}
    assert generic.threshold == 2**14 and generic.fac_weight == 2**9
    assert generic_fixed_point(32, 1e-6).decay_bits == 30  # capped for 64-bit products


def test_profiles_load_from_paths_and_pass_through(tmp_path):
    path = tmp_path / "chip.toml"
    path.write_text(LOIHI)
    chip = load_profile(path)
    assert chip.name == "chip" and load_profile(str(path)) == chip
    assert load_profile(chip) is chip
    assert chip.with_dt(2e-5).dt == 2e-5 and chip.with_dt(2e-5).state_bits == 24
    mixed = parse_profile(ANALOG)
    assert (mixed.tau_sigma, mixed.gain_sigma, mixed.seed) == (0.1, 0.05, 3)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (LOIHI + "\n[extra]\nx = 1\n", "unknown table(s) ['extra']"),
        (LOIHI.replace('name = "chip"', 'name = "chip"\ncolour = "red"'), "colour"),
        (edit(LOIHI, "kind", None), "missing key(s) ['kind']"),
        (edit(LOIHI, "kind", '"quantum"'), "kind = 'quantum'"),
        (edit(LOIHI, "name", '""'), "name must be a non-empty string"),
        (edit(LOIHI, "state_bits", None), "[fixed_point]: missing key(s) ['state_bits']"),
        (LOIHI + "state_bitz = 3\n", "unknown key(s) ['state_bitz']"),
        (LOIHI.split("[fixed_point]")[0], "needs a [fixed_point] table"),
        (LOIHI.replace("[profile]", "[profil]"), "unknown table(s) ['profil']"),
        (LOIHI + "\n[analog]\ntau_sigma = 0.1\n", "cannot have a [analog] table"),
        ("this is = = not toml", "not valid TOML"),
        (edit(LOIHI, "state_bits", "40"), "state_bits = 40 is impossible"),
        (edit(LOIHI, "state_bits", "4"), "state_bits = 4 is impossible"),
        (edit(LOIHI, "state_bits", "24.0"), "state_bits must be an integer"),
        (edit(LOIHI, "state_bits", "true"), "state_bits must be an integer"),
        (edit(LOIHI, "decay_bits", "0"), "decay_bits = 0 is impossible"),
        (edit(LOIHI, "decay_bits", "31"), "decay_bits = 31 is impossible"),
        (edit(LOIHI, "refractory_bits", "0"), "refractory_bits = 0 is impossible"),
        (edit(LOIHI, "weight_mantissa_bits", "1"), "weight_mantissa_bits = 1 is impossible"),
        (edit(LOIHI, "weight_exponent_min", "-2"), "weight_exponent_min = -2 is impossible"),
        (edit(LOIHI, "weight_exponent_max", "25"), "weight_exponent_max = 25 is impossible"),
        (edit(LOIHI, "bias_exponent_min", "9"), "bias_exponent_max = 7 is impossible"),
        (edit(LOIHI, "trigger_shift_max", "63"), "trigger_shift_max = 63 is impossible"),
        (edit(LOIHI, "current_shift_max", "31"), "current_shift_max = 31 is impossible"),
        (edit(LOIHI, "threshold_shift", "23"), "threshold_shift = 23 is impossible"),
        (edit(LOIHI, "threshold_mantissa_bits", "0"), "threshold_mantissa_bits = 0"),
        (edit(LOIHI, "headroom_bits", "22"), "headroom_bits = 22 is impossible"),
        (
            edit(edit(LOIHI, "weight_exponent_min", "18"), "weight_exponent_max", "18"),
            "leaves no facilitatory weight",
        ),  # fmt: skip
        (edit(LOIHI, "dt", "0.0"), "dt = 0.0 must be a finite time step"),
        (edit(LOIHI, "dt", "nan"), "dt = nan"),
        (edit(LOIHI, "dt", '"fast"'), "dt must be a number"),
        (edit(ANALOG, "tau_sigma", "-0.1"), "tau_sigma = -0.1 is impossible"),
        (edit(ANALOG, "gain_sigma", "inf"), "gain_sigma = inf is impossible"),
        (edit(ANALOG, "offset_levels", "0"), "offset_levels = 0 is impossible"),
        (edit(ANALOG, "max_groups", "2.5"), "max_groups must be an integer"),
        (edit(ANALOG, "seed", "-1"), "seed = -1 is impossible"),
        (ANALOG + "dt = 1e-5\n", "unknown key(s) ['dt']"),
    ],
)
def test_bad_profiles_name_the_key(text, message):
    with pytest.raises(ProfileError) as info:
        parse_profile(text, "bad.toml")
    assert message in str(info.value)
    assert str(info.value).startswith("bad.toml")
    assert isinstance(info.value, ValueError)


VARIANT = """
[profile]
base = "loihi2"
name = "loihi2-40us"
description = "loihi2 stepped every 40 us"

[fixed_point]
dt = 4e-5

[energy]
static_power = { value = 0.01, source = "assumed: a test figure" }
"""


def test_a_variant_profile_is_its_base_with_the_keys_it_changes(tmp_path):
    base = load_profile("loihi2")
    path = tmp_path / "variant.toml"
    path.write_text(VARIANT)
    variant = load_profile(path)
    assert variant.name == "loihi2-40us" and variant.description.endswith("every 40 us")
    # every format is loihi2's but the time step
    same = {f.name for f in dataclasses.fields(base)} - {"name", "description", "dt", "chip"}
    assert all(getattr(variant, k) == getattr(base, k) for k in same)
    assert variant.dt == 4e-5 and base.dt == 1e-5
    # chip tables are inherited figure by figure; the variant replaces one
    assert variant.chip.resources == base.chip.resources
    assert variant.chip.energy.value("static_power") == 0.01
    assert variant.chip.energy.figure("neuron_update") == base.chip.energy.figure("neuron_update")
    # a chain: a variant of the variant, named by a path relative to its own file
    (tmp_path / "chain.toml").write_text(
        '[profile]\nbase = "variant.toml"\nname = "c"\ndescription = "c"\n'
        "[fixed_point]\ndecay_bits = 16\n"
    )
    chain = load_profile(tmp_path / "chain.toml")
    assert (chain.dt, chain.decay_bits, chain.state_bits) == (4e-5, 16, 24)


@pytest.mark.parametrize("source", [*quantize.available_profiles(), "loihi2@80us", "variant"])
def test_a_profile_written_whole_reads_back_equal(source, tmp_path):
    """:func:`quantize.profile_toml` (an export folder's ``profile.toml``, issue 62): every
    key and chip figure, a variant's base merged in, non-ASCII sources escaped."""
    if source == "variant":
        (tmp_path / "variant.toml").write_text(VARIANT)
        source = tmp_path / "variant.toml"
    profile = load_profile(source)
    text = quantize.profile_toml(profile, "written by a test\nfor µs")
    assert text.isascii() and "\nbase =" not in text
    path = tmp_path / "whole.toml"
    path.write_text(text)
    assert load_profile(path) == profile


def test_the_documented_80us_loihi2_is_loihi2_at_80us():
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "docs" / "profiles" / "loihi2-80us.toml"
    variant, base = load_profile(path), load_profile("loihi2")
    assert variant == dataclasses.replace(
        base.with_dt(8e-5), name="loihi2-80us", description=variant.description
    )


@pytest.mark.parametrize(
    ("header", "message"),
    [
        ('base = "loihi9"\nname = "v"\ndescription = "v"', "base = 'loihi9' is neither"),
        ('base = "gone.toml"\nname = "v"\ndescription = "v"', "no such file"),
        ('base = "self.toml"\nname = "v"\ndescription = "v"', "form a cycle"),
        ('base = "loihi2"\nname = "v"', "needs its own description"),
        ('base = "loihi2"\nkind = "analog"\nname = "v"\ndescription = "v"', "keeps its base"),
        ('base = 3\nname = "v"\ndescription = "v"', "base must be a profile name"),
    ],
)
def test_bad_variants_name_the_base(tmp_path, header, message):
    path = tmp_path / "self.toml"
    path.write_text(f"[profile]\n{header}\n")
    with pytest.raises(ProfileError, match="self.toml") as info:
        load_profile(path)
    assert message in str(info.value)


def test_bad_sources_and_generic_widths(tmp_path):
    with pytest.raises(ProfileError, match="unknown profile 'loihi3'.*loihi2"):
        load_profile("loihi3")
    with pytest.raises(FileNotFoundError, match="no such profile file"):
        load_profile(tmp_path / "missing.toml")
    with pytest.raises(ProfileError, match="bits = 7 is impossible"):
        generic_fixed_point(7, 1e-5)
    with pytest.raises(ProfileError, match="dt = -1"):
        generic_fixed_point(16, -1.0)
    with pytest.raises(ProfileError, match="state_bits = 33"):
        dataclasses.replace(load_profile("loihi2"), state_bits=33)


def test_quantize_accepts_profile_names_paths_and_objects(tmp_path, base_params):
    path = tmp_path / "chip.toml"
    path.write_text(LOIHI)
    one = base_params.with_free_frequency(100.0)
    from_path = quantize.quantize(one, path)
    assert from_path.profile.name == "chip" and from_path.n_spll == 1
    by_name = quantize.quantize(one, "loihi2")
    by_object = quantize.quantize(one, load_profile("loihi2"))
    assert (by_name.network.matrix() == by_object.network.matrix()).all()
    assert by_name.report.of("free_frequency")[0].requested == pytest.approx(100.0)
