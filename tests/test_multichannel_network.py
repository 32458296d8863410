"""Multichannel networks: the [[channel]] file format, per-channel features, accuracy against
time into the slide, and ``spll-hw slide``."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.container import ErrorbarContainer

from mappings.nir.multichannel import read_nir_multichannel
from spll_hw.classify import HoldoutResult
from spll_hw.cli.main import COMMANDS, main
from spll_hw.config import read_network_file
from spll_hw.datasets.biotac_channels import CHANNELS, load_biotac_channels
from spll_hw.datasets.recordings import split_recordings
from spll_hw.multichannel import presets
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import FeatureCache, channel_features, input_levels
from spll_hw.multichannel.readout_file import load_readout
from spll_hw.multichannel.report import (
    PUBLISHED,
    PUBLISHED_CLASSES,
    change_table,
    markdown_table,
    plot_over_time,
)
from spll_hw.multichannel.timecourse import CV_ALPHAS, Point, accuracy_over_time, cv_alpha
from spll_hw.multichannel.windows import features_over_windows
from spll_hw.pipeline import PipelineConfig, run_pipeline

from .figure_checks import capture_figures, clipped_texts, labelled_ticks
from .pipeline_data import BIOTAC_DIR, needs_biotac
from .test_multichannel_data import ROW_TABLE, write_recording

LOW = '\n[[channel]]\nchannels = ["ele1", "pdc"]' + ROW_TABLE


@pytest.fixture
def fake_root(tmp_path):
    for folder in ("mat1", "mat2", "mat20"):
        for n in (1, 2, 3, 4):
            write_recording(tmp_path, folder, n, rows=120 + 7 * n)
    return tmp_path


def test_preset_is_pac_through_the_tuned_network_and_every_row_channel_through_its_own():
    assert "biotac-multichannel-lif" in presets.names()
    config = MultichannelConfig.load("biotac-multichannel-lif")
    assert config.channels == CHANNELS
    pac, low = config.groups
    tuned = read_network_file("biotac-tuned-time-scaled-lif")
    assert (pac.network, pac.encoder, pac.input_level) == (
        tuned.config,
        tuned.encoder,
        tuned.input_level,
    )
    assert low.network.f_end < 50 and low.encoder[0] == "lif" and low.input_level is None
    assert config.n_spll == 50 + 22 * low.network.n


def test_file_with_a_named_network_and_an_inline_one(tmp_path):
    (tmp_path / "net.toml").write_text("[spll]\n" + LOW.split("[channel.spll]")[1].split("[")[0])
    path = tmp_path / "mc.toml"
    path.write_text('[[channel]]\nchannels = ["pac"]\nnetwork = "net.toml"\n'
                    '[channel.encoder]\nname = "lif"\ngain = 4000.0\n' + LOW)  # fmt: skip
    config = MultichannelConfig.load(path)
    assert config.channels == ("pac", "ele1", "pdc") and config.n_spll == 50 + 2 * 4
    assert config.groups[0].encoder == ("lif", {"gain": 4000.0})
    assert config.groups[0].source == "net.toml" and config.groups[1].source == "inline"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"no \[\[channel\]\] table"),
        ('[[channel]]\nchannels = []\nnetwork = "biotac-vary-offset-lif"\n', "non-empty list"),
        ('[[channel]]\nchannels = ["pac"]\nnetwork = "biotac-vary-offset-lif"\n',
         r"\[\[channel\]\] 1: no encoder"),
        ('[[channel]]\nchannels = ["pac"]\nnetworks = "x"\n', r"unknown key\(s\) \['networks'\]"),
        ('[[channel]]\nchannels = ["pac"]\n', "no network"),
        ('[[channel]]\nchannels = ["pac"]\nnetwork = "missing.toml"\n', "missing.toml"),
        (LOW + LOW, "channel 'ele1' is in \\[\\[channel\\]\\] tables 1 and 2"),
        (LOW.replace("n = 4", "n = 0"), r"\[\[channel\]\] 1 \[network\]: n must be"),
        (LOW.replace('name = "lif"', 'name = "cochlea"'), r"\[\[channel\]\] 1 \[encoder\]"),
        ("title = 1\n" + LOW, r"unknown key\(s\) or table\(s\) \['title'\]"),
    ],
)  # fmt: skip
def test_bad_files_name_the_file_and_table(tmp_path, text, message):
    path = tmp_path / "mc.toml"
    path.write_text(text)
    with pytest.raises((ValueError, FileNotFoundError), match=message):
        MultichannelConfig.load(path)


def test_only_keeps_some_channels_of_a_network():
    config = MultichannelConfig.load("biotac-multichannel-lif")
    electrodes = config.only([f"ele{i}" for i in range(1, 20)])
    assert len(electrodes.groups) == 1 and electrodes.n_spll == 19 * 16
    assert config.only(["tdc", "pac"]).channels == ("pac", "tdc")
    with pytest.raises(ValueError, match=r"has no channel\(s\) \['ele20'\]"):
        config.only(["ele20"])


def test_unknown_channel_is_named_with_the_file(tmp_path):
    path = tmp_path / "mc.toml"
    path.write_text(LOW.replace('"pdc"', '"ele20"'))
    with pytest.raises(ValueError, match=r"mc\.toml: unknown channel\(s\) \['ele20'\]"):
        MultichannelConfig.load(path).check_channels(CHANNELS)


def test_single_channel_features_are_the_single_channel_pipelines(fake_root):
    samples = load_biotac_channels(fake_root, ["pac"], ["mat1", "mat2"], duration=1.0)
    config = MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif")
    group = config.groups[0]
    levels = input_levels(config, samples)
    mine = channel_features(samples, "pac", group, levels["pac"])
    pipeline = run_pipeline(
        samples.channel("pac"), [group.make_encoder()],
        PipelineConfig(features=("spll",), network="biotac-tuned-time-scaled-lif", n_splits=2),
        input_level=group.input_level,
    )  # fmt: skip
    np.testing.assert_array_equal(mine, pipeline.get("lif", "spll").features)


def test_feature_cache_runs_a_shared_channel_once(fake_root, tmp_path):
    path = tmp_path / "mc.toml"
    path.write_text(LOW)
    config = MultichannelConfig.load(path)
    samples = load_biotac_channels(fake_root, ["ele1", "pdc"], ["mat1", "mat2"], duration=1.0)
    levels = input_levels(config, samples)
    calls = []

    def compute(channel, group, level):
        calls.append(channel)
        return channel_features(samples, channel, group, level)

    cache = FeatureCache(compute)
    x = cache.features(config, levels)
    assert x.shape == (len(samples), 8) and np.all(x >= 0)
    np.testing.assert_array_equal(cache.features(config, levels), x)
    assert calls == ["ele1", "pdc"]


def test_accuracy_over_time_scores_every_network_class_set_and_window(
    fake_root, tmp_path, monkeypatch
):
    path = tmp_path / "mc.toml"
    path.write_text(LOW)
    loaded = load_biotac_channels(fake_root, ["pac", "ele1", "pdc"], ["mat1", "mat2", "mat20"],
                                  duration=1.0).openings()  # fmt: skip
    train, test = split_recordings(loaded, [4], "--test-recordings 4")
    single = MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif")
    networks = {"low": MultichannelConfig.load(path), "pac": single}
    names = train.class_names
    points = accuracy_over_time(train, test, networks, {"3": names, "2": names[:2]}, [0.5, 1.0])
    assert len(points) == 2 * 2 * 2
    for p in points:
        assert p.result.correct.shape == (1, 3 if p.classes == "3" else 2)
        assert p.to_dict()["test_recordings"] == p.result.correct.shape[1]
    table = markdown_table(points)
    assert "| low | 3 |" in table and "| 0.5 s | 1 s |" in table
    assert "published SNN" in table  # their 1 s point
    change = change_table(points, "low", "pac")
    assert change.startswith("| classes | 0.5 s | 1 s |") and "| 2 |" in change
    assert change_table(points, "low", "absent") == ""
    with pytest.raises(ValueError, match="not loaded"):
        accuracy_over_time(train, test, networks, {"x": ["felt"]}, [0.5])
    # The picture draws the 95 % interval it claims: bars and a band for every network.
    figures = capture_figures(monkeypatch)
    plot_over_time(points, tmp_path / "accuracy_over_time.png")
    fig = figures["accuracy_over_time.png"]
    for ax in fig.axes:
        mine = [p for p in points if p.classes == ax.get_title().split(" classes")[0]]
        assert_intervals_drawn(ax, mine, bands=True)
    assert clipped_texts(fig) == []


def test_cv_alpha_penalises_noisy_features_and_not_clean_ones():
    rng = np.random.default_rng(0)
    # 10 weak features among 150 of noise, 200 recordings: a strong penalty wins
    y = np.arange(200) % 2
    noisy = np.concatenate([y[:, None] * 0.8 + rng.normal(size=(200, 10)),
                            rng.normal(size=(200, 150))], axis=1)  # fmt: skip
    assert cv_alpha(noisy, y, np.arange(200)) == 1000.0
    # the class in a small difference of two large, correlated features: a weak one wins
    y = np.arange(300) % 3
    z = 10 * rng.normal(size=300)
    clean = np.stack([z + 0.5 * y + 0.1 * rng.normal(size=300), z], axis=1)
    assert cv_alpha(clean, y, np.arange(300)) <= 1.0
    with pytest.raises(ValueError, match="at least 2 training recordings"):
        cv_alpha(clean, y, y)  # one recording per class


def test_accuracy_over_time_chooses_alpha_per_window_on_the_training_recordings(fake_root):
    path_network = MultichannelConfig.load(presets.path("biotac-multichannel-lif")).only(
        ["ele1", "pdc"]
    )
    loaded = load_biotac_channels(fake_root, ["ele1", "pdc"], ["mat1", "mat2", "mat20"],
                                  duration=1.0).openings()  # fmt: skip
    train, test = split_recordings(loaded, [4], "--test-recordings 4")
    names = train.class_names
    args = (train, test, {"low": path_network}, {"3": names}, [0.5, 1.0])
    points = accuracy_over_time(*args, alpha="cv")
    fixed = accuracy_over_time(*args, alpha=1.0)
    assert [p.window for p in points] == [0.5, 1.0]
    for p, q in zip(points, fixed, strict=True):
        assert p.alpha in CV_ALPHAS and p.to_dict()["alpha"] == p.alpha and q.alpha == 1.0
        # the chosen alpha is the one cross-validation on the training rows picks
        x = FeatureCache(
            lambda c, g, level, w=p.window: channel_features(train.first(w), c, g, level)
        ).features(path_network, input_levels(path_network, train))
        assert p.alpha == cv_alpha(x, train.labels, train.recordings)
    with pytest.raises(ValueError, match="ridge alpha"):
        accuracy_over_time(*args, alpha="best")


def assert_intervals_drawn(ax, points, bands: bool):
    """Every network of ``points`` (one class set) has error bars from each window's 95 % CI
    low to high and, with ``bands``, a shaded band as wide; a legend entry that claims an
    interval (``CI``) has one drawn, and every other says it has none."""
    bars = {c.get_label(): c for c in ax.containers if isinstance(c, ErrorbarContainer)}
    fills = [c for c in ax.collections if isinstance(c, PolyCollection)]
    for network in dict.fromkeys(p.network for p in points):
        mine = sorted((p for p in points if p.network == network), key=lambda p: p.window)
        label = next((name for name in bars if name.startswith(network)), None)
        assert label is not None, f"no error bars drawn for {network}"
        assert "95 % CI" in label and bars[label].has_yerr
        segments = bars[label].lines[2][0].get_segments()
        assert len(segments) == len(mine)
        for segment, p in zip(segments, mine, strict=True):
            ci = p.result.accuracy_ci()
            assert segment[:, 0] == pytest.approx([p.window] * 2)
            assert sorted(segment[:, 1]) == pytest.approx([100 * ci.low, 100 * ci.high])
        if bands:
            lows = [100 * p.result.accuracy_ci().low for p in mine]
            highs = [100 * p.result.accuracy_ci().high for p in mine]
            assert any(
                f.get_paths()[0].vertices[:, 1].min() == pytest.approx(min(lows))
                and f.get_paths()[0].vertices[:, 1].max() == pytest.approx(max(highs))
                for f in fills
            ), network
    assert len(fills) == (len(bars) if bands else 0)
    for line in ax.get_legend().get_texts():
        text = line.get_text()
        assert text in bars or "CI" not in text or "no CI" in text, text


def _held_out(network, classes, window, right):
    """A held-out result of 20 classes, one sample per recording, ``right`` of them right."""
    labels = np.arange(20)
    predicted = np.where(labels < right, labels, (labels + 1) % 20)
    names = [f"m{k}" for k in range(20)]
    result = HoldoutResult.of_predictions(predicted, labels, np.arange(20), names)
    return Point(network, classes, window, result)


def test_accuracy_over_time_with_one_window_still_draws_its_intervals_not_the_published_ones(
    tmp_path, monkeypatch
):
    # One window (`spll-hw slide --windows 0.5`): a band of one point has no width, so the
    # intervals used to vanish while the axis label still claimed them.
    figures = capture_figures(monkeypatch)
    points = [_held_out("multichannel", PUBLISHED_CLASSES, 0.5, 14),
              _held_out("single-channel (pac)", PUBLISHED_CLASSES, 0.5, 9)]  # fmt: skip
    plot_over_time(points, tmp_path / "accuracy_over_time.png")
    fig = figures["accuracy_over_time.png"]
    (ax,) = fig.axes
    assert_intervals_drawn(ax, points, bands=False)
    published = [t.get_text() for t in ax.get_legend().get_texts() if "published" in t.get_text()]
    assert published == [f"published {name} (no CI)" for name in PUBLISHED]
    # The published curves' windows are read off labelled ticks too.
    assert labelled_ticks(ax.xaxis) == ["0.5", "1", "4"]
    assert clipped_texts(fig) == []  # the note under one narrow panel is broken, not clipped


def test_slide_is_a_command_and_refuses_bad_input(capsys, tmp_path):
    assert "slide" in COMMANDS
    data = ["--data", str(tmp_path), "--quiet", "--out", str(tmp_path / "o")]
    assert main(["slide", *data, "--windows", "0.5,x"]) == 2
    assert "--windows: 'x' is not a number" in capsys.readouterr().err
    assert main(["slide", *data, "--windows", "0.255"]) == 2
    assert "multiple of 10 ms" in capsys.readouterr().err
    assert main(["slide", *data, "--train-recordings", "1-4", "--holdout-recordings", "4-5"]) == 2
    assert "recording(s) 4 are also training recordings" in capsys.readouterr().err
    assert main(["slide", *data, "--network", "biotac-multichannel-cochlea"]) == 2
    assert "unknown multichannel network preset" in capsys.readouterr().err
    assert main(["slide", *data, "--channels", "pac,ele20"]) == 2
    assert "--channels pac,ele20: " in capsys.readouterr().err
    assert main(["slide", *data, "--readout", "--readout-bits", "8,1"]) == 2
    assert "--readout-bits: '1' is not an integer width in 2..32" in capsys.readouterr().err
    assert main(["slide", *data, "--window-parts", "0"]) == 2
    assert "--window-parts: 0 is not a number of parts in 1..16" in capsys.readouterr().err


def slide_on_biotac(out, windows: str, *args: str) -> int:
    """``spll-hw slide`` trained on the real recordings 1-2 and scored on 3 after ``windows``
    (its ``--windows``), quietly on one job, with ``args``, writing the report to ``out``."""
    return main(["slide", "--data", str(BIOTAC_DIR), "--train-recordings", "1-2",
                 "--holdout-recordings", "3", "--windows", windows, "--jobs", "1", "--quiet",
                 *args, "--out", str(out)])  # fmt: skip


@needs_biotac
def test_slide_on_a_few_real_recordings_writes_the_report(tmp_path, capsys):
    out = tmp_path / "slide"
    code = slide_on_biotac(out, "0.5", "--readout", "--readout-bits", "6")
    assert code == 0 and "report:" in capsys.readouterr().out
    results = json.loads((out / "results.json").read_text())
    assert {(p["network"], p["classes"]) for p in results["points"]} == {
        ("multichannel", "thesis 11"), ("multichannel", "all 20"),
        ("single-channel (pac)", "thesis 11"), ("single-channel (pac)", "all 20"),
    }  # fmt: skip
    assert results["n_test"] == 20 and results["networks"]["multichannel"]["n_spll"] > 50
    assert (out / "accuracy_over_time.png").read_bytes()[:4] == b"\x89PNG"
    summary = (out / "summary.md").read_text()
    assert "Taunyazov" in summary and "Multichannel minus single-channel" in summary
    readout = results["readout"]
    assert set(readout) == {"thesis 11", "all 20"} and "Spiking readout, all 20" in summary
    assert results["readout_train"] == "prefixes" and "rates over the first 0.25, 0.5 s" in summary
    assert {p["readout"] for p in readout["all 20"]} == {"float", "6-bit"}
    for p in readout["all 20"]:  # decisions after the 0.1-s baseline, within the window
        assert 0.1 <= p["mean_time_s"] <= 0.5 and 0 <= p["fired"] <= 1
    assert (out / "readout.png").read_bytes()[:4] == b"\x89PNG"
    # the trained readouts are saved, and export with the network they were trained on
    pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")
    assert sorted(p.name for p in (out / "readouts").iterdir()) == [
        "all20-6-bit.npz", "all20-float.npz", "thesis11-6-bit.npz", "thesis11-float.npz",
    ]  # fmt: skip
    saved = load_readout(out / "readouts" / "all20-6-bit.npz")
    assert saved.readout.bits == 6 and len(saved.readout.class_names) == 20
    loss, at = saved.training_loss  # against float on the training runs, in the summary too
    assert 0.25 <= at <= 0.5 and f"all 20, 6-bit weights: {-loss:+.1f} points" in summary
    assert load_readout(out / "readouts" / "all20-float.npz").training_loss is None
    assert saved.readout.weights.shape[1] == results["networks"]["multichannel"]["n_spll"]
    assert main(["export", "--to", "nir", "--network", "biotac-multichannel-lif",
                 "--readout", str(out / "readouts" / "all20-6-bit.npz"), "--threshold", "1",
                 "--out", str(tmp_path / "nir")]) == 0  # fmt: skip
    back = read_nir_multichannel(tmp_path / "nir" / "network.nir").readout
    np.testing.assert_array_equal(back.readout.weights, saved.readout.weights)
    np.testing.assert_array_equal(back.levels, saved.levels)


@needs_biotac
def test_slide_alpha_cv_reports_the_alpha_each_window_chose(tmp_path, capsys):
    out = tmp_path / "slide"
    code = slide_on_biotac(out, "0.5,1", "--channels", "ele1,pdc", "--single", "none", "--alpha-cv")
    assert code == 0
    points = json.loads((out / "results.json").read_text())["points"]
    assert len(points) == 2 * 2 and all(p["alpha"] in CV_ALPHAS for p in points)
    assert "penalty alpha chosen per window and class set by CV" in (out / "summary.md").read_text()
    code = slide_on_biotac(out, "0.5", "--channels", "ele1,pdc", "--single", "none",
                           "--window-parts", "2")  # fmt: skip
    assert code == 0
    results = json.loads((out / "results.json").read_text())
    assert {p["alpha"] for p in results["points"]} == {1.0} and results["window_parts"] == 2
    summary = (out / "summary.md").read_text()
    assert "ridge on every TDE's rate in each of the window's 2 equal parts" in summary


def test_one_pool_gives_every_window_the_features_of_its_own_run(fake_root, tmp_path):
    path = tmp_path / "mc.toml"
    path.write_text(LOW)
    networks = [MultichannelConfig.load(path),
                MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif")]  # fmt: skip
    samples = load_biotac_channels(fake_root, ["pac", "ele1", "pdc"], ["mat1", "mat2"],
                                   duration=1.0)  # fmt: skip
    units = [(c, g, input_levels(config, samples)[c])
             for config in networks for g in config.groups for c in g.channels]  # fmt: skip
    windows = [0.25, 1.0]
    rates = features_over_windows(samples, units, windows, jobs=2, chunk=3)
    assert len(rates) == len(units) * len(windows)
    for w in windows:
        for channel, group, level in units:
            alone = channel_features(samples.first(w), channel, group, level)
            np.testing.assert_array_equal(rates[w, channel, group.key, level], alone)
    short, long = (rates[w, "pac", units[-1][1].key, units[-1][2]] for w in windows)
    assert short.shape == long.shape == (len(samples), 50) and not np.array_equal(short, long)
    with pytest.raises(ValueError, match="not within the 1 s samples"):
        features_over_windows(samples, units, [2.0])
    halves = features_over_windows(samples, units[-1:], windows, jobs=2, chunk=3, parts=2)
    for w in windows:  # the halves' rates of each window's own run, and their mean its rate
        channel, group, level = units[-1]
        got = halves[w, channel, group.key, level]
        np.testing.assert_array_equal(
            got, channel_features(samples.first(w), channel, group, level, parts=2)
        )
        assert got.shape == (len(samples), 100)
        np.testing.assert_allclose(got.reshape(-1, 2, 50).mean(axis=1),
                                   rates[w, channel, group.key, level])  # fmt: skip


def test_a_window_is_not_a_prefix_of_the_longest_one(fake_root):
    # The LIF encoder removes each window's own mean, so the first 0.25 s of the 1-s spike
    # train differ from the spike train of the first 0.25 s: rates cannot be counted on
    # prefixes of one run without changing the results (spll_hw/multichannel/windows.py).
    samples = load_biotac_channels(fake_root, ["pac"], ["mat1"], duration=1.0).channel("pac")
    encoder = MultichannelConfig.single("pac", "biotac-tuned-time-scaled-lif").groups[0]
    encoder = encoder.make_encoder()
    signals = samples.normalized(samples.reference_level(), "test").signals
    short = encoder.encode(signals[:, :550], samples.fs)
    long = encoder.encode(signals, samples.fs)
    prefixes = [t[t < 0.25] for t in long]
    pairs = zip(short, prefixes, strict=True)
    assert any(a.size != b.size or not np.array_equal(a, b) for a, b in pairs)
