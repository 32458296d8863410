"""Separate clocks for a multichannel network's channel groups: which steps a group can run at,
the backend each group runs on, and what a classification on several clocks costs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from spll_hw import backends
from spll_hw.cli.main import main
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.model.grid import n_steps
from spll_hw.multichannel.chips import ClockedCost, classification_cost, clocks
from spll_hw.multichannel.clocks import (
    clocked_backend,
    clocked_profile,
    group_label,
    parse_group_steps,
    with_group_backends,
)
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels

from .pipeline_data import needs_biotac
from .test_multichannel_chips import chips_argv
from .test_multichannel_data import write_recording
from .test_multichannel_network import LOW, slide_on_biotac

#: pac through the tuned network (Loihi 2 writes it at 40-80 us only) beside two slow row
#: channels (320 us-1.28 ms only).
TWO_SPEEDS = '[[channel]]\nchannels = ["pac"]\nnetwork = "biotac-tuned-time-scaled-lif"\n' + LOW
FAST, SLOW = 80e-6, 640e-6


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "two.toml"
    path.write_text(TWO_SPEEDS)
    return MultichannelConfig.load(path)


def test_group_steps_name_a_group_by_any_of_its_channels(config):
    assert parse_group_steps("pac=80us, pdc=0.64ms", config) == {0: FAST, 1: pytest.approx(SLOW)}
    assert parse_group_steps(None, config) == {} == parse_group_steps(" ", config)
    assert group_label(config.groups[0]) == "pac"
    assert group_label(config.groups[1]) == "ele1…pdc (2 channels)"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("pac", "write CHANNEL=STEP"),
        ("pac=", "write CHANNEL=STEP"),
        ("ele7=1ms", "has no channel 'ele7'"),
        ("ele1=1ms,pdc=2ms", "'ele1' and 'pdc' are in one"),
        ("pac=fast", "entry 'pac=fast': time step 'fast'"),
    ],
)
def test_bad_group_steps_are_named(config, text, message):
    with pytest.raises(ValueError, match=message):
        parse_group_steps(text, config)


def test_a_step_the_chip_cannot_write_a_group_at_is_refused_with_the_steps_that_can(config):
    assert clocked_profile("loihi2", config.groups[0], FAST) == "loihi2@80us"
    with pytest.raises(ValueError, match=r"pac: loihi2@160us cannot write.*Steps that can: 40us"):
        clocked_profile("loihi2", config.groups[0], 160e-6)
    # the slow rows' CCO time constants round to no decay at pac's step
    with pytest.raises(ValueError, match=r"rounds to no decay.*Steps that can: 320us, 640us"):
        clocked_profile("loihi2", config.groups[1], FAST)
    with pytest.raises(ValueError, match="'analog' profile, which has no clock"):
        clocked_profile("analog", config.groups[1], SLOW)


def test_each_group_runs_on_the_chip_at_its_own_step(config):
    chip = "golden-fixed-point:profile=loihi2"
    both = with_group_backends(config, chip, {0: FAST, 1: SLOW})
    specs = [g.backend for g in both.groups]
    assert [backends.get(s).options["profile"] for s in specs] == ["loihi2@80us", "loihi2@640us"]
    assert clocked_backend(chip, config.groups[0], FAST) == specs[0]
    one = with_group_backends(config, chip, {1: SLOW})  # pac keeps the chip's own step
    assert one.groups[0].backend == backends.get(chip).spec
    # the simulator is part of what makes a group's features: no two runs share a cache entry
    golden = with_group_backends(config, "golden", {})
    assert len({g.key for g in (*both.groups, *golden.groups)}) == 4
    assert [g.network for g in both.groups] == [g.network for g in config.groups]
    with pytest.raises(ValueError, match="needs a backend that runs a chip profile"):
        with_group_backends(config, "golden", {0: FAST})


def test_a_classification_on_two_clocks_costs_what_each_clock_costs(config, tmp_path):
    for material in ("mat1", "mat2"):
        write_recording(tmp_path, material, 1, rows=60)
    samples = load_biotac_channels(tmp_path, config.channels, ["mat1", "mat2"], duration=0.5)
    levels = input_levels(config, samples)
    parts = clocks(config, "loihi2", {0: FAST, 1: SLOW})
    assert [(c.label, c.profile, c.config.channels) for c in parts] == [
        ("pac", "loihi2@80us", ("pac",)),
        ("ele1…pdc (2 channels)", "loihi2@640us", ("ele1", "pdc")),
    ]
    costs = [classification_cost(c.config, c.profile, samples, levels, 0.5) for c in parts]
    total = ClockedCost(tuple(costs))
    assert total.dynamic_energy == pytest.approx(sum(c.dynamic_energy for c in costs))
    assert total.static_energy == pytest.approx(sum(c.static_energy for c in costs))
    span = total.dynamic_range
    assert span.low < total.dynamic_energy < span.high
    assert span.low == pytest.approx(sum(c.dynamic_range.low for c in costs))
    # each clock pays its own steps: one per step of its own, on its own chip
    for cost, dt, compartments in zip(costs, (FAST, SLOW), (2 * 50, 2 * 2 * 4), strict=True):
        assert cost.figure_counts["step"] == n_steps(0.5, dt)
        assert cost.figure_counts["neuron_update"] == compartments * n_steps(0.5, dt)
    # pac alone at 80 us costs what the single-clock path costs for pac at 80 us
    pac = config.only(["pac"])
    alone = classification_cost(pac, "loihi2@80us", samples, levels, 0.5)
    assert costs[0].dynamic_energy == pytest.approx(alone.dynamic_energy)
    assert total.latency == max(c.latency for c in costs)
    # at half the rows' step their updates and steps are paid twice as often
    rows = classification_cost(parts[1].config, "loihi2@320us", samples, levels, 0.5)
    for key in ("neuron_update", "step"):
        assert costs[1].figure_counts[key] * 2 == rows.figure_counts[key]


def test_chips_command_costs_each_clock_and_their_sum(tmp_path, capsys):
    argv, out = chips_argv(tmp_path, "loihi2,dynapse2", TWO_SPEEDS)
    argv += ["--group-steps", "pac=80us,pdc=640us"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "| loihi2@80us: pac | yes |" in text
    assert "| loihi2@640us: ele1…pdc (2 channels) | yes |" in text
    # pac: 4 cores, the rows: 1; over loihi2's placement ranges 2 to 5.
    assert "| **loihi2, 2 clocks** | yes | 5 [2, 5] | 2 |" in text
    assert "| dynapse2 | no |" in text  # an analog chip has no clock to split
    data = json.loads((out / "results.json").read_text())
    loihi = data["profiles"][0]
    parts = [c["classification"]["dynamic_energy_j"] for c in loihi["clocks"]]
    assert loihi["classification"]["dynamic_energy_j"] == pytest.approx(sum(parts))
    low, high = loihi["classification"]["dynamic_range_j"]
    assert low < sum(parts) < high
    assert main([*argv[:-1], "pac=160us"]) == 2
    assert "Steps that can: 40us, 80us" in capsys.readouterr().err


@needs_biotac
def test_slide_on_separate_clocks_reports_its_change_against_golden(tmp_path, capsys):
    out = tmp_path / "slide"
    backend = "golden-fixed-point:profile=loihi2"
    code = slide_on_biotac(out, "0.5", "--single", "none", "--backend", backend,
                           "--group-steps", "pac=80us,ele1=640us")  # fmt: skip
    assert code == 0
    assert "on its backend minus the same network on the golden model" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    assert {p["network"] for p in results["points"]} == {"multichannel", "multichannel (golden)"}
    ran = results["networks"]["multichannel"]["backends"]
    assert ran == {
        "pac": "golden-fixed-point:profile=loihi2@80us",
        "ele1…tdc (22 channels)": "golden-fixed-point:profile=loihi2@640us",
    }
    assert set(results["networks"]["multichannel (golden)"]["backends"].values()) == {"golden"}
    summary = (out / "summary.md").read_text()
    assert "pac on `golden-fixed-point:profile=loihi2@80us`" in summary
    accuracy = {(p["network"], p["classes"]): p["accuracy"] for p in results["points"]}
    assert all(0 <= a <= 1 for a in accuracy.values())
    assert np.isfinite(list(accuracy.values())).all()


def test_a_window_past_an_hour_or_a_folder_as_network_is_refused_by_name(tmp_path, capsys):
    write_recording(tmp_path, "mat1", 1, rows=60)
    base = ["chips", "--network", "biotac-multichannel-lif", "--data", str(tmp_path),
            "--profiles", "loihi2", "--out", str(tmp_path / "o")]  # fmt: skip
    assert main([*base, "--windows", "1e308"]) == 2
    assert "--windows must lie in (0, 3600] s" in capsys.readouterr().err
    folder = tmp_path / "exported"
    folder.mkdir()
    (folder / "mc.toml").write_text(TWO_SPEEDS)
    assert main(["chips", "--network", str(folder), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "is a folder, not a multichannel network" in err and "mc.toml" in err
