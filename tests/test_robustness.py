"""``spll-hw robustness`` and :mod:`spll_hw.harness.robustness`: a tuned figure with the training
recordings, the test recordings and the input scale varied."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.datasets import make_synthetic
from spll_hw.encoders import make_encoder
from spll_hw.harness.robustness import Variation, score_variations, standard_variations
from spll_hw.harness.robustness_report import survives

from .pipeline_data import BIOTAC_DIR, needs_biotac
from .test_recordings import FS, leaky_folder

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def numbered_synthetic(per_class=8):
    """Synthetic textures, 3 classes x ``per_class`` 1-s samples, each its own recording,
    numbered 1..per_class within its class."""
    s = make_synthetic(3, per_class, 1.0, seed=0)
    return replace(s, numbers=np.tile(np.arange(1, per_class + 1), 3))


def small_network(preset="vibtac-time-scaled-lif", n=6):
    return NetworkConfig.preset(preset).with_n(n).build()


def test_standard_variations_vary_training_test_and_scale():
    v = standard_variations(range(1, 41), range(33, 41), [range(1, 25)], [range(25, 33)], [0.9])
    assert [x.label for x in v] == ["baseline: train 1-32", "train 1-24", "test 25-32",
                                    "scale x 0.9"]  # fmt: skip
    assert v[0].train == tuple(range(1, 33)) and v[0].test == tuple(range(33, 41))
    assert v[2].train == tuple(range(1, 25)) + tuple(range(33, 41))
    assert v[3].level_factor == 0.9 and v[3].train == v[0].train
    with pytest.raises(ValueError, match=r"overlap \(3-4\)"):
        Variation("x", (1, 2, 3, 4), (3, 4, 5))
    with pytest.raises(ValueError, match="level factor must be > 0"):
        Variation("x", (1,), (2,), 0.0)


def test_identical_networks_change_nothing_and_the_level_follows_the_factor():
    samples = numbered_synthetic()
    net = small_network()
    variations = standard_variations(range(1, 9), [7, 8], [[1, 2, 3, 4]], [[5, 6]], [0.5, 2.0])
    rows = score_variations(samples, make_encoder("lif"), net, net, variations, input_level=80.0,
                            phase_noise=5e-4, repeats=2)  # fmt: skip
    assert len(rows) == 5
    for r in rows:
        change = r.tuned.change_against(r.reference)
        assert (change.mean, change.low, change.high) == (0.0, 0.0, 0.0)
        assert r.tuned.correct.shape == (2, 3 * len(r.variation.test))
    # the network file's level holds whatever the training recordings are
    assert [r.level for r in rows] == [80.0, 80.0, 80.0, 40.0, 160.0]
    assert not survives(rows)


@pytest.mark.parametrize(("encoder", "reused"), [("pacinian", True), ("lif", False)])
def test_a_scale_whose_spike_trains_are_unchanged_reuses_their_features(encoder, reused):
    samples = numbered_synthetic(per_class=4)
    tuned, reference = small_network(n=4), small_network("vibtac-vary-offset-lif", n=4)
    variations = standard_variations(range(1, 5), [4], [], [], [0.5])
    lines: list[str] = []
    rows = score_variations(samples, make_encoder(encoder), tuned, reference, variations,
                            input_level=80.0, repeats=1, say=lines.append)  # fmt: skip
    assert rows[1].level == 40.0
    assert any("their features reused" in line for line in lines) == reused
    same = [np.array_equal(rows[0].tuned.correct, rows[1].tuned.correct),
            np.array_equal(rows[0].reference.correct, rows[1].reference.correct)]  # fmt: skip
    if reused:  # the Pacinian model scales every sample to 20 um RMS: the level cannot matter
        assert all(same)


def test_without_a_level_the_scale_follows_the_training_samples():
    samples = numbered_synthetic()
    net = small_network()
    variations = standard_variations(range(1, 9), [7, 8], [[1, 2]], [], [])
    rows = score_variations(samples, make_encoder("lif"), net, net, variations, repeats=1)
    for r in rows:
        train = np.isin(samples.numbers, r.variation.train)
        assert r.level == pytest.approx(samples.subset(np.flatnonzero(train)).reference_level())
    assert rows[0].level != rows[1].level


def test_a_better_network_survives_and_a_class_missing_from_a_side_is_named():
    samples = numbered_synthetic(per_class=10)
    good, poor = small_network(n=12), small_network(n=2)
    variations = standard_variations(range(1, 11), [9, 10], [], [[1, 2]], [])
    rows = score_variations(samples, make_encoder("lif"), good, poor, variations, repeats=1)
    assert all(r.tuned.accuracy > r.reference.accuracy for r in rows)
    odd = replace(samples, numbers=np.where(samples.labels == 0, 1, samples.numbers))
    with pytest.raises(ValueError, match=r"train 2-10: class\(es\) \['texture 1"):
        score_variations(odd, make_encoder("lif"), good, poor,
                         [Variation("train 2-10", tuple(range(2, 11)), (1,))])  # fmt: skip


def test_the_command_writes_table_plot_and_json_and_names_bad_flags(tmp_path, capsys):
    root = leaky_folder(tmp_path / "vib", per_class=6, chunks=1)
    net = tmp_path / "small.toml"
    net.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(4).to_toml())
    common = ["robustness", "--dataset", "folder", "--data", str(root), "--fs", str(FS),
              "--network", str(net), "--reference", "vibtac-vary-offset-lif",
              "--repeats", "1", "--quiet", "--jobs", "1"]  # fmt: skip
    out = tmp_path / "robust"
    varied = ["--holdout-recordings", "5-6", "--train-recordings", "1-2", "--test-blocks", "1-2",
              "--level-factors", "0.9", "--out", str(out)]  # fmt: skip
    assert main([*common, *varied]) == 0
    result = json.loads((out / "results.json").read_text())
    labels = [v["label"] for v in result["variations"]]
    assert labels == ["baseline: train 1-4", "train 1-2", "test 1-2", "scale x 0.9"]
    for v in result["variations"]:
        assert v["change"]["low"] <= v["change"]["mean"] <= v["change"]["high"]
        assert v["n_test_samples"] == 4
    summary = (out / "summary.md").read_text()
    assert "| train 1-2 | 1-2 | 5-6 (4 samples) |" in summary
    assert (out / "robustness.png").read_bytes().startswith(PNG_MAGIC)
    capsys.readouterr()
    bad = {
        ("--out", str(out)): "robustness needs --holdout-recordings",
        ("--holdout-recordings", "5-9"): "--holdout-recordings: recording(s) 7-9 are not loaded "
        "(loaded: 1-6)",
        ("--holdout-recordings", "5-6", "--train-recordings", "4-5"): "--train-recordings 4-5 "
        "overlaps --holdout-recordings 5-6",
        ("--holdout-recordings", "5-6", "--level-factors", "0.9,x"): "--level-factors '0.9,x'",
    }
    for extra, message in bad.items():
        assert main([*common, *extra]) == 2
        assert message in capsys.readouterr().err
    assert main(["robustness", "--holdout-recordings", "1", "--quiet"]) == 2
    assert "robustness needs numbered recordings (--dataset biotac or folder)" in (
        capsys.readouterr().err
    )


@needs_biotac
def test_a_tuned_biotac_preset_keeps_its_input_level_in_every_variation(tmp_path):
    out = tmp_path / "bt"
    assert main([
        "robustness", "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "1,2,3",
        "--recordings", "1-6", "--holdout-recordings", "5-6", "--train-recordings", "1-2",
        "--test-blocks", "3-4", "--level-factors", "1.25", "--repeats", "1", "--quiet",
        "--network", "biotac-tuned-vary-offset-lif", "--reference", "biotac-vary-offset-lif",
        "--jobs", "1", "--out", str(out),
    ]) == 0  # fmt: skip
    rows = json.loads((out / "results.json").read_text())["variations"]
    levels = [r["input_level"] for r in rows]
    assert levels[:3] == [pytest.approx(106.96779602011281)] * 3
    assert levels[3] == pytest.approx(1.25 * 106.96779602011281)
    assert [r["test_recordings"] for r in rows] == [[5, 6], [5, 6], [3, 4], [5, 6]]


def test_an_empty_level_factor_list_varies_only_the_recordings():
    from argparse import Namespace

    from spll_hw.cli.jobs.robustness import checked_variations

    args = Namespace(holdout_recordings="7-8", train_recordings=["1-3"], test_blocks=[],
                     level_factors="")  # fmt: skip
    variations = checked_variations(args, list(range(1, 9)))
    assert [v.label for v in variations] == ["baseline: train 1-6", "train 1-3"]
    assert {v.level_factor for v in variations} == {1.0}
    args.level_factors = "1.1,-2"
    with pytest.raises(ValueError, match=r"--level-factors: every factor must be finite and > 0"):
        checked_variations(args, list(range(1, 9)))
