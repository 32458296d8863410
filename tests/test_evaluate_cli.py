"""``spll-hw evaluate``: end-to-end runs on small data, report folder contents, bad arguments."""

from __future__ import annotations

import json
from dataclasses import fields, replace

import numpy as np
import pytest
from matplotlib.container import ErrorbarContainer

from spll_hw import backends
from spll_hw.cli import inputs
from spll_hw.cli.main import COMMANDS, build_parser, main
from spll_hw.config import NetworkConfig
from spll_hw.datasets import make_synthetic
from spll_hw.encoders import PacinianEncoder, make_encoder
from spll_hw.features import spll_features
from spll_hw.pipeline import PipelineConfig, encode_samples, run_pipeline
from spll_hw.report.plots import plot_accuracies
from spll_hw.stats import Interval

from .figure_checks import capture_figures, legend_over_axes
from .pipeline_data import BIOTAC_DIR, needs_biotac

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run_cli(*argv: str) -> int:
    args = build_parser().parse_args(["evaluate", *argv])
    return args.func(args)


def test_evaluate_is_a_registered_command_and_reports_bad_input(capsys):
    assert "evaluate" in COMMANDS
    assert main(["evaluate", "--features", "mfcc", "--quiet"]) == 2
    assert "spll-hw evaluate: error: unknown feature(s) ['mfcc']" in capsys.readouterr().err


def test_synthetic_run_writes_markdown_json_and_plots(tmp_path, capsys, monkeypatch):
    figures = capture_figures(monkeypatch)
    out = tmp_path / "report"
    code = run_cli(
        "--synthetic-classes", "3", "--synthetic-samples", "10", "--duration", "1",
        "--encoders", "lif,pacinian,peak", "--features", "spectrum,sfft,isi,spll",
        "--network", "biotac-vary-offset-{encoder}", "--jobs", "1", "--quiet", "--out", str(out),
    )  # fmt: skip
    assert code == 0
    assert "report:" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    assert results["dataset"]["n_samples"] == 30 and results["dataset"]["sample_duration_s"] == 1
    rows = {(r["encoder"], r["feature"]): r for r in results["results"]}
    assert len(rows) == 1 + 3 * 3
    for r in rows.values():
        assert 0.0 <= r["accuracy"] <= 1.0 and len(r["fold_accuracies"]) == 5
        assert np.sum(r["confusion"]) == 30
    assert rows[(None, "spectrum")]["accuracy"] > 0.8  # three well-separated textures
    assert set(results["encoders"]) == {"lif", "pacinian", "peak"}
    summary = (out / "summary.md").read_text()
    assert "| feature | (pressure) | lif | pacinian | peak |" in summary
    assert "| spll |" in summary and "peak: `biotac-vary-offset-peak`" in summary
    for name in ["class_spectra", "spike_rasters", "accuracy", "confusion_lif_spll"]:
        assert (out / f"{name}.png").read_bytes()[:8] == PNG_MAGIC
        assert f"({name}.png)" in summary
    # Every accuracy bar carries its 95 % interval; the legend stays off the bars.
    ax = figures["accuracy.png"].axes[0]
    bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    assert len(ax.patches) == len(bars) == len(rows)
    assert legend_over_axes(ax) == 0 and "95 % CI" in ax.get_ylabel()


def test_evaluate_accuracy_bars_carry_their_clipped_confidence_intervals(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    table = {
        "spectrum": {"(pressure)": Interval(0.9, 0.8, 1.05)},
        "isi": {"lif": Interval(0.5, 0.3, 0.7), "peak": Interval(0.2, -0.1, 0.5)},
    }
    plot_accuracies(table, 1 / 3, tmp_path / "accuracy.png")
    ax = figures["accuracy.png"].axes[0]
    assert legend_over_axes(ax) == 0
    assert "95 % CI" in ax.get_ylabel()
    tops, bottoms = [], []
    for container in ax.containers:
        if isinstance(container, ErrorbarContainer):
            (segments,) = container.lines[2]
            for (_, y0), (_, y1) in segments.get_segments():
                bottoms.append(round(min(y0, y1), 6))
                tops.append(round(max(y0, y1), 6))
    assert sorted(zip(bottoms, tops, strict=True)) == [(0.0, 50.0), (30.0, 70.0), (80.0, 100.0)]


def test_spll_features_on_the_chips_own_arithmetic(tmp_path):
    """--backend golden-fixed-point:profile=loihi2: the features are the fixed-point
    reference's TDE rates (not the golden model's), and the report says which backend ran."""
    out = tmp_path / "report"
    spec = "golden-fixed-point:profile=loihi2"
    code = run_cli(
        "--synthetic-classes", "3", "--synthetic-samples", "4", "--duration", "0.5",
        "--encoders", "lif", "--features", "spll", "--network", "vibtac-vary-offset-lif",
        "--backend", spec, "--folds", "2", "--jobs", "1", "--quiet", "--out", str(out),
    )  # fmt: skip
    assert code == 0
    results = json.loads((out / "results.json").read_text())
    assert results["config"]["backend"] == "golden-fixed-point"  # loihi2 is its default
    # the summary names the chip, its default profile too
    assert (
        "simulated on backend `golden-fixed-point:profile=loihi2`"
        in (out / "summary.md").read_text()
    )
    samples = make_synthetic(3, 4, 0.5, seed=0).normalized()
    settings = PipelineConfig(features=("spll",), network="vibtac-vary-offset-lif", n_splits=2)
    chip = run_pipeline(samples, [make_encoder("lif")], replace(settings, backend=spec))
    golden = run_pipeline(samples, [make_encoder("lif")], settings)
    trains = encode_samples(make_encoder("lif"), samples)
    network = NetworkConfig.preset("vibtac-vary-offset-lif").build()
    expected = backends.get(spec).rates(network, trains, samples.duration)
    np.testing.assert_array_equal(chip.get("lif", "spll").features, expected)
    assert not np.array_equal(expected, golden.get("lif", "spll").features)
    with pytest.raises(ValueError, match="unknown profile 'loihi3'"):
        run_cli("--features", "spll", "--backend", "golden-fixed-point:profile=loihi3")


def test_network_file_with_spread_is_what_the_spll_features_run(tmp_path):
    config = replace(NetworkConfig.preset("biotac-time-scaled-lif").with_n(6), spread=0.5)
    path = tmp_path / "best.toml"
    path.write_text(config.to_toml())
    samples = make_synthetic(2, 5, 0.5, seed=1).normalized()
    settings = PipelineConfig(features=("spll",), network=str(path))
    result = run_pipeline(samples, [make_encoder("lif")], settings).get("lif", "spll")
    trains = encode_samples(make_encoder("lif"), samples)
    expected = spll_features(trains, samples.duration, config.build())
    np.testing.assert_array_equal(result.features, expected)
    assert not np.array_equal(
        expected, spll_features(trains, samples.duration, replace(config, spread=0.0).build())
    )


def test_peak_trains_longer_than_the_sample_are_scored_over_their_whole_length():
    samples = make_synthetic(2, 5, 0.5, seed=1).normalized()
    long = make_encoder("peak", duration=2.0)  # four times the sample
    config = PipelineConfig(features=("spll", "sfft"), network="biotac-vary-offset-peak")
    result = run_pipeline(samples, [long], config)
    trains = encode_samples(long, samples)
    assert max(t.max() for t in trains) > 1.5
    network = NetworkConfig.preset("biotac-vary-offset-peak").build()
    expected = spll_features(trains, 2.0, network)
    np.testing.assert_array_equal(result.get("peak", "spll").features, expected)
    assert not np.array_equal(expected, spll_features(trains, 0.5, network))
    assert result.windows["peak"] == 2.0
    spikes = np.mean([t.size for t in trains])
    assert result.to_dict()["encoders"]["peak"]["mean_rate_hz"] == pytest.approx(spikes / 2.0)
    short = run_pipeline(samples, [make_encoder("peak")], config)
    assert short.windows["peak"] == 0.5


def test_phase_noise_repeats_pool_folds(tmp_path):
    out = tmp_path / "noisy"
    run_cli(
        "--synthetic-classes", "2", "--synthetic-samples", "6", "--duration", "0.5",
        "--encoders", "lif", "--features", "sfft", "--phase-noise", "5e-4", "--repeats", "3",
        "--folds", "3", "--quiet", "--jobs", "1", "--out", str(out),
    )  # fmt: skip
    (result,) = json.loads((out / "results.json").read_text())["results"]
    assert len(result["fold_accuracies"]) == 9 and np.sum(result["confusion"]) == 36


def test_parallel_encoding_equals_serial():
    samples = make_synthetic(n_classes=2, samples_per_class=5, duration=0.5)
    enc = PacinianEncoder(noisy=True, seed=3)
    serial = encode_samples(enc, samples, jobs=1)
    parallel = encode_samples(enc, samples, jobs=2)
    assert len(serial) == len(parallel) == 10
    for a, b in zip(serial, parallel, strict=True):
        np.testing.assert_array_equal(a, b)


def test_pipeline_timings_and_first_repeat_features():
    samples = make_synthetic(n_classes=2, samples_per_class=5, duration=0.5)
    config = PipelineConfig(features=("isi",), n_splits=5)
    result = run_pipeline(samples, [PacinianEncoder(noisy=False)], config)
    r = result.get("pacinian", "isi")
    assert r.features.shape == (10, 50) and r.seconds >= 0
    assert result.encode_seconds["pacinian"] > 0
    with pytest.raises(KeyError):
        result.get("lif", "isi")


@needs_biotac
def test_biotac_subset_run(tmp_path):
    out = tmp_path / "biotac"
    run_cli(
        "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "mat1,metal",
        "--recordings", "1-2", "--encoders", "lif", "--features", "spectrum,sfft",
        "--folds", "2", "--quiet", "--jobs", "1", "--out", str(out),
    )  # fmt: skip
    results = json.loads((out / "results.json").read_text())
    assert results["dataset"]["class_counts"]["carpet net"] == 6
    assert results["dataset"]["unit"].startswith("median RMS of the training samples")
    assert {r["feature"] for r in results["results"]} == {"spectrum", "sfft"}


def test_bad_arguments_raise_clear_errors(tmp_path, monkeypatch):
    monkeypatch.delenv(inputs.BIOTAC_ENV, raising=False)
    with pytest.raises(ValueError, match="needs --data"):
        run_cli("--dataset", "biotac", "--quiet")
    with pytest.raises(ValueError, match="lif has no parameter 'gian'"):
        run_cli("--set", "lif.gian=3", "--quiet")
    with pytest.raises(
        ValueError, match=r"--set 'pacinian.model=x': pacinian.model must be int, got 'x'"
    ):
        run_cli("--set", "pacinian.model=x", "--quiet")
    with pytest.raises(ValueError, match="unknown feature"):
        run_cli("--features", "mfcc", "--quiet")
    with pytest.raises(ValueError, match="unknown sPLL network preset"):
        run_cli("--features", "spll", "--network", "nope", "--quiet")
    with pytest.raises(ValueError, match="bad range"):
        inputs.parse_ranges("5-1")
    assert inputs.parse_ranges("1-3,7") == [1, 2, 3, 7]
    overrides = inputs.encoder_overrides(["pacinian.rms_um=none", "lif.tau=0.003"], ["lif"])
    assert overrides == {"lif": {"tau": 0.003}, "pacinian": {"rms_um": None}}


@pytest.mark.parametrize(
    "name, params",
    [
        ("pacinian", {"model": 2, "rms_um": 39.849559139685034, "noisy": False}),
        ("pacinian", {"rms_um": None}),
        ("peak", {"cutoff": None, "duration": 4.0, "n_peaks": 5}),
        ("lif", {"normalize": "rms", "gain": 1 / 3}),
        ("lif", {}),
    ],
)
def test_settings_flags_rebuild_the_encoder_exactly(name, params):
    from spll_hw.encoders import settings_flags

    encoder = make_encoder(name, **params)
    flags = settings_flags(encoder)
    assert flags.count("--set") == len(params)
    items = flags.removeprefix("--set ").split(" --set ") if flags else []
    assert inputs.encoder_overrides(items, [name]) == {name: params}
    assert make_encoder(name, **inputs.encoder_overrides(items, [name])[name]) == encoder


@pytest.mark.parametrize(
    "name, params",
    [
        ("pacinian", {"model": 2, "rms_um": 39.849559139685034, "noisy": False}),
        ("peak", {"cutoff": None, "duration": 4.0, "n_peaks": 5, "spectrum": "pressure"}),
        ("lif", {"normalize": "rms", "gain": 1 / 3}),
    ],
)
def test_encoder_table_of_a_network_file_rebuilds_the_encoder_exactly(tmp_path, name, params):
    from spll_hw.config import read_encoder_table
    from spll_hw.encoders import settings_table

    encoder = make_encoder(name, **params)
    path = tmp_path / "net.toml"
    config = NetworkConfig.preset("biotac-vary-offset-lif")
    path.write_text(config.to_toml() + settings_table(encoder))
    assert NetworkConfig.from_toml(path) == config  # network commands read past the table
    tuned_on, settings = read_encoder_table(path)
    assert tuned_on == name and make_encoder(name, **settings) == encoder
    # every field is written, so the file keeps its meaning if a default changes
    assert set(settings) == {f.name for f in fields(encoder)}
    assert read_encoder_table("biotac-vary-offset-lif") is None  # presets carry none
    path.write_text(config.to_toml())
    assert read_encoder_table(path) is None


@pytest.mark.parametrize(
    "table, message",
    [
        ('[encoder]\nname = "mfcc"\n', r"net.toml \[encoder\]: name must be one of"),
        ("[encoder]\ntau = 0.002\n", r"name must be one of .*, got None"),
        ('[encoder]\nname = "lif"\ngian = 3.0\n', "lif has no parameter 'gian'"),
        ('[encoder]\nname = "pacinian"\nmodel = "two"\n', "pacinian.model must be int"),
        ('[encoder]\nname = "lif"\ngain = [1, 2]\n', r"gain = \[1, 2\] is not a setting"),
        ("encoder = 3\n", "encoder must be a table"),
    ],
)
def test_bad_encoder_tables_name_the_file_and_entry(tmp_path, table, message):
    from spll_hw.config import read_encoder_table

    path = tmp_path / "net.toml"
    path.write_text(table + NetworkConfig.preset("biotac-vary-offset-lif").to_toml())
    with pytest.raises(ValueError, match=message) as info:
        read_encoder_table(path)
    assert "net.toml" in str(info.value)


def test_evaluate_encodes_with_the_network_files_encoder_and_set_overrides_it(tmp_path, capsys):
    from spll_hw.encoders import settings_table

    config = NetworkConfig.preset("biotac-vary-offset-peak").with_n(4)
    path = tmp_path / "peak.toml"
    path.write_text(config.to_toml() + settings_table(make_encoder("peak", n_peaks=1)))
    common = ["--encoders", "peak", "--network", str(path), "--synthetic-classes", "3"]
    common += ["--synthetic-samples", "5", "--duration", "0.5", "--quiet", "--jobs", "1"]

    def settings(*extra):
        out = tmp_path / "out"
        assert main(["evaluate", *common, *extra, "--out", str(out)]) == 0
        return json.loads((out / "results.json").read_text())["encoders"]["peak"]["params"]

    assert settings("--features", "spll")["n_peaks"] == 1
    assert "encoder settings from" in capsys.readouterr().err
    assert settings("--features", "spll", "--set", "peak.n_peaks=2")["n_peaks"] == 2
    assert settings("--features", "sfft")["n_peaks"] == 3  # no sPLL network: file not used
    lif = tmp_path / "lif.toml"
    lif.write_text(config.to_toml() + settings_table(make_encoder("lif")))
    common[3] = str(lif)
    assert settings("--features", "spll")["n_peaks"] == 3
    assert "tuned on lif spike trains; peak keeps its own" in capsys.readouterr().err


@needs_biotac
def test_held_out_recordings_train_on_the_others_and_test_once(tmp_path, capsys):
    """--test-recordings 4-5: no held-out recording is trained on, the accuracy is the share of
    right test samples, and its interval resamples whole recordings."""
    out = tmp_path / "held"
    common = ["--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "1,2,3",
              "--recordings", "1-5", "--encoders", "lif", "--features", "spectrum,sfft",
              "--quiet", "--jobs", "1"]  # fmt: skip
    assert run_cli(*common, "--holdout-recordings", "4-5", "--out", str(out)) == 0
    results = json.loads((out / "results.json").read_text())
    for r in results["results"]:
        correct = np.array(r["correct"])
        assert correct.shape[0] == 1 and r["accuracy"] == pytest.approx(correct.mean())
        ci = r["accuracy_ci"]
        assert ci["low"] <= r["accuracy"] <= ci["high"]
        assert r["test_recordings"] == 6  # 3 classes x recordings 4 and 5
        assert np.sum(r["confusion"]) == correct.shape[1]
    assert "held-out samples of 6 recordings" in (out / "summary.md").read_text()
    from spll_hw.cli.main import main

    capsys.readouterr()
    assert main(["evaluate", *common, "--holdout-recordings", "30-31", "--out", str(out)]) == 2
    assert "recording(s) 30-31 are not loaded (loaded: 1-5" in capsys.readouterr().err
    # a range partly beyond the loaded recordings is refused, not silently cut
    assert main(["evaluate", *common, "--holdout-recordings", "4-9", "--out", str(out)]) == 2
    assert "recording(s) 6-9 are not loaded" in capsys.readouterr().err
    assert main(["evaluate", "--holdout-recordings", "1-2", "--quiet", "--out", str(out)]) == 2
    assert "needs --dataset biotac or folder" in capsys.readouterr().err


def test_an_interval_past_0_or_100_percent_is_shown_clipped_by_its_ends():
    from spll_hw.report.markdown import percent

    assert percent(0.546, 0.018) == "54.6 ± 1.8 %"
    # 2 folds: t(1 dof) = 12.7 makes the half-width larger than the accuracy itself
    assert percent(0.583, 1.467) == "58.3 % [0.0, 100.0]"
    assert percent(0.95, 0.08) == "95.0 % [87.0, 100.0]"
