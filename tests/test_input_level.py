"""The input level a network's encoder was tuned at travels with the network file: the same
network sees the same amplitudes whichever recordings a run trains on (issue: the Pacinian
preset's figure, scale as part of the network)."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import presets
from spll_hw.config import read_network_file
from spll_hw.datasets import make_synthetic
from spll_hw.encoders import make_encoder, settings_table
from spll_hw.pipeline import PipelineConfig, run_pipeline

from .pipeline_data import BIOTAC_DIR, needs_biotac

TUNED = [name for name in presets.names() if name.startswith("biotac-tuned-")]


def _file(tmp_path, level) -> str:
    path = tmp_path / "net.toml"
    text = read_network_file("vibtac-vary-offset-lif").config.to_toml()
    path.write_text(text + "\n" + settings_table(make_encoder("lif"), level))
    return str(path)


def test_every_tuned_preset_carries_the_level_it_was_tuned_at():
    assert len(TUNED) == 5
    for name in TUNED:
        network = read_network_file(name)
        # the median sample RMS of the 440-sample study on recordings 1-32 (docs/tuning.md)
        assert network.input_level == pytest.approx(106.9678, rel=1e-5), name


def test_the_level_round_trips_through_the_encoder_table(tmp_path):
    network = read_network_file(_file(tmp_path, 123.5))
    assert network.input_level == 123.5 and network.encoder[0] == "lif"
    assert "input_level" not in network.encoder[1]  # not an encoder setting


@pytest.mark.parametrize("bad", ["-1", "0", "nan", '"loud"'])
def test_a_bad_level_names_the_file_and_the_key(tmp_path, bad):
    path = tmp_path / "net.toml"
    _file(tmp_path, 1.0)
    path.write_text(path.read_text().replace("input_level = 1.0", f"input_level = {bad}"))
    with pytest.raises(ValueError, match=r"net\.toml \[encoder\]: input_level must be a finite"):
        read_network_file(path)


def _encoder_inputs(samples, test, level):
    config = PipelineConfig(features=("spectrum",), n_splits=2, progress=False)
    result = run_pipeline(samples, [make_encoder("lif")], config, test, input_level=level)
    return result


def test_the_encoder_sees_the_same_signals_whichever_samples_it_trains_on():
    everything = make_synthetic(3, 12, 0.5, seed=4)
    test = everything.subset(np.arange(0, len(everything), 4))
    rest = np.setdiff1d(np.arange(len(everything)), np.arange(0, len(everything), 4))
    few, many = everything.subset(rest[::3]), everything.subset(rest)  # every class in both
    assert few.reference_level() != many.reference_level()  # the trap: a level per training set
    a, b = _encoder_inputs(few, test, 2.5), _encoder_inputs(many, test, 2.5)
    np.testing.assert_array_equal(a.test.signals, b.test.signals)
    np.testing.assert_array_equal(a.test.signals, test.signals / 2.5)
    assert a.input_level == b.input_level == 2.5
    assert "input_level" in a.test.unit
    # without a level each run divides by its own training samples' median RMS
    c, d = _encoder_inputs(few, test, None), _encoder_inputs(many, test, None)
    assert not np.array_equal(c.test.signals, d.test.signals)
    assert c.input_level == pytest.approx(few.reference_level())


@needs_biotac
def test_evaluate_on_a_tuned_preset_divides_by_its_level(tmp_path):
    import json

    from spll_hw.cli.main import main

    out = tmp_path / "eval"
    code = main(["evaluate", "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes",
                 "mat3,mat5,mat7", "--recordings", "1-6", "--encoders", "lif", "--features", "spll",
                 "--network", "biotac-tuned-vary-offset-lif", "--folds", "2", "--quiet",
                 "--out", str(out)])  # fmt: skip
    assert code == 0
    results = json.loads((out / "results.json").read_text())
    assert results["input_level"] == pytest.approx(106.96779602011281)
    assert results["dataset"]["unit"].startswith("the network file's input_level (106.968")
