"""The staged spiking readout (spll_hw/multichannel/readout.py, issue 60): readouts that take
turns over the run, each trained on its own stretch's prefixes; their decisions in the engine
equal the Python reference; per-class weight scales keep integer decisions."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.multichannel import anytime
from spll_hw.multichannel import readout as ro
from spll_hw.multichannel.anytime import fit_staged
from spll_hw.multichannel.decisions import engine_decisions
from spll_hw.multichannel.readout import START, Readout, StagedReadout, decide_staged

NAMES = ("a", "b", "c")
THRESHOLDS = (0.05, 0.2, 0.5, 1.0, 2.0, 5.0, np.inf)


def test_stages_cover_the_run_and_the_last_trains_on_the_whole_run():
    got = ro.stages(4.0)
    assert [start for start, _ in got] == [START, *ro.STAGE_EDGES]
    assert got[0][1] == (0.25, 0.5) and got[1][1] == (0.5, 1.0) and got[-1][1] == (4.0,)
    # edges outside the run are dropped; a short run keeps its end stage
    assert ro.stages(0.8) == ((START, (0.25, 0.5)), (0.5, (0.8,)))
    times, offset = anytime.training("staged", 4.0)
    assert times == (0.25, 0.5, 1.0, 2.0, 3.0, 4.0) and offset == anytime.PREFIX_OFFSET
    with pytest.raises(ValueError, match="staged"):
        anytime.training("bogus", 4.0)


def synthetic_counts(rng, n_per_class=12, d=6, times=(0.25, 0.5, 1.0, 2.0, 3.0, 4.0)):
    # class c: TDE rates with a class-specific pattern; counts grow with time plus noise
    labels = np.repeat(np.arange(3), n_per_class)
    pattern = rng.uniform(5, 50, (3, d))
    rates = pattern[labels] + rng.normal(0, 4, (labels.size, d))
    counts = np.stack([np.round(rates * t + rng.normal(0, 2, rates.shape)) for t in times], 1)
    return np.clip(counts, 0, None), labels, times


def test_fit_staged_trains_each_stage_on_its_own_prefixes():
    rng = np.random.default_rng(1)
    counts, labels, times = synthetic_counts(rng)
    staged = fit_staged(counts, times, labels, NAMES, 4.0, (None, 8), 100.0)
    assert set(staged) == {"float", "8-bit"}
    s = staged["float"]
    assert s.starts == (START, *ro.STAGE_EDGES) and s.weights.shape == (5, 3, 6)
    # the last stage is the ridge of the whole run's rates; the second that of 0.5 and 1 s
    for stage, at in ((-1, [5]), (1, [1, 2])):
        rates, y = anytime.stacked_prefixes(counts[:, at], [times[i] for i in at], labels)
        want = anytime.fit_readouts(rates, y, NAMES, (None,), 100.0)["float"]
        np.testing.assert_array_equal(s.stages[stage].weights, want.weights)
        np.testing.assert_array_equal(s.stages[stage].bias, want.bias)
    assert staged["8-bit"].bits == 8
    with pytest.raises(ValueError, match=r"stage from 1 s trains on counts at \[2.0\] s"):
        fit_staged(counts[:, :3], times[:3], labels, NAMES, 4.0)


def random_staged(rng, d=4, k=3) -> StagedReadout:
    readouts = tuple(
        Readout(rng.normal(0, 0.05, (k, d)), rng.normal(0.5, 0.5, k), NAMES[:k]) for _ in range(3)
    )
    return StagedReadout(readouts, (START, 0.4, 0.7))


def test_staged_decisions_in_the_engine_equal_the_python_reference():
    rng = np.random.default_rng(7)
    duration = 1.0
    for trial in range(15):
        staged = random_staged(rng)
        runs = [
            [np.sort(np.round(rng.uniform(0, duration, rng.integers(5, 60)), 2)) for _ in range(4)]
            for _ in range(6)
        ]
        for not_before in (0.0, START, 0.5):
            got = engine_decisions(staged, runs, duration, THRESHOLDS, not_before)
            for r, run in enumerate(runs):
                want = [decide_staged(staged, run, duration, t, not_before) for t in THRESHOLDS]
                assert [got.at(r, m) for m in range(len(THRESHOLDS))] == want, (trial, r)


def test_a_stage_decides_only_while_it_is_on():
    # stage 0 (on 0.1-0.5 s) would reach 1 at 0.6 s, after it is off: stage 1 (class c) decides
    # at its own crossing; with a lower threshold stage 0 fires at 0.3 s
    stage0 = Readout(np.zeros((3, 1)), np.array([5 / 3, 0.0, 0.0]), NAMES)
    stage1 = Readout(np.zeros((3, 1)), np.array([0.0, 0.0, 1.25]), NAMES)
    staged = StagedReadout((stage0, stage1), (START, 0.5))
    run = [np.array([0.2])]
    late = decide_staged(staged, run, 1.0, 1.0, START)
    assert late.label == 2 and late.fired and late.time == pytest.approx(0.8)
    early = decide_staged(staged, run, 1.0, 0.5, START)
    assert early.label == 0 and early.time == pytest.approx(0.3)
    got = engine_decisions(staged, [run], 1.0, (0.5, 1.0, np.inf), START)
    assert got.at(0, 0) == early and got.at(0, 1) == late
    assert not got.fired[0, 2] and got.labels[0, 2] == 2  # the last stage decides at the end
    with pytest.raises(ValueError, match="must increase"):
        StagedReadout((stage0, stage1), (0.5, 0.5))


def test_per_class_scales_keep_integer_decisions_where_one_scale_does_not():
    # one channel, three classes whose weights differ 200-fold: with one scale per channel,
    # 4-bit steps of class 0's size round classes 1 and 2 to zero and their decisions are lost;
    # with a scale per class and channel every class keeps its resolution
    rng = np.random.default_rng(3)
    d = 8
    weights = rng.normal(0, 1, (3, d)) * np.array([[1.0], [0.005], [0.005]])
    readout = Readout(weights, np.zeros(3), NAMES)
    rates = rng.uniform(0, 100, (400, d))
    want = readout.scores(rates).argmax(1)
    assert np.unique(want).size == 3
    for bits in (8, 6):
        shared = readout.quantized(bits, rates=rates).scores(rates).argmax(1)
        mine = readout.quantized(bits, rates=rates, per_class=True).scores(rates).argmax(1)
        assert np.mean(mine == want) >= 0.97, bits
        assert np.mean(shared == want) < 0.9, bits
    assert np.count_nonzero(readout.quantized(4, rates=rates).weights[1:]) == 0
    assert np.count_nonzero(readout.quantized(4, rates=rates, per_class=True).weights[1:]) > 8


def test_training_loss_is_the_worst_prefix_decided_by_the_stage_on_then():
    rng = np.random.default_rng(4)
    counts, labels, times = synthetic_counts(rng)
    good = fit_staged(counts, times, labels, NAMES, 4.0, (None,), 100.0)["float"]
    assert anytime.training_loss(good, good, counts, times, labels) == (0.0, times[0])
    # break the stage on from 0.5 s to 1 s: of the prefixes only 0.5 s is decided by it
    stages = list(good.stages)
    stages[1] = Readout(np.zeros_like(stages[1].weights), np.zeros(3), NAMES)
    broken = StagedReadout(tuple(stages), good.starts)
    loss, at = anytime.training_loss(broken, good, counts, times, labels)
    right = good.stages[1].scores(counts[:, 1] / 0.5).argmax(axis=1) == labels
    assert at == 0.5 and loss == pytest.approx(100 * (right.mean() - np.mean(labels == 0)))
    assert loss > 30  # a stage of zeros says class a for every run: a third right


def test_a_staged_readout_file_reads_back_to_the_same_stages(tmp_path):
    from spll_hw.multichannel.readout_file import SavedReadout, load_readout, save_readout

    staged = random_staged(np.random.default_rng(2))
    path = save_readout(tmp_path / "s.npz", SavedReadout(staged, ("pac",), np.ones(1)))
    with np.load(path) as data:
        np.testing.assert_array_equal(data["weights"], staged.weights)
        np.testing.assert_array_equal(data["starts"], staged.starts)
        assert data["bias"].shape == (3, 3)
    back = load_readout(path)
    assert isinstance(back.readout, StagedReadout) and back.readout.starts == staged.starts
    for mine, theirs in zip(back.readout.stages, staged.stages, strict=True):
        np.testing.assert_array_equal(mine.weights, theirs.weights)
        np.testing.assert_array_equal(mine.bias, theirs.bias)
    with np.load(path) as data:  # a stage's NaN weight is named with its stage
        arrays = dict(data)
    arrays["weights"][1, 0, 0] = np.nan
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match=r"bad.npz \(stage 2\): weights, bias and levels"):
        load_readout(tmp_path / "bad.npz")
    assert back.training_loss is None
    back.check_loss("float")  # nothing measured, nothing refused


def test_an_integer_readout_keeps_its_training_loss_and_export_refuses_a_large_one(tmp_path):
    from spll_hw.multichannel.readout_file import SavedReadout, load_readout, save_readout

    staged = random_staged(np.random.default_rng(2))
    four = StagedReadout(tuple(r.quantized(4) for r in staged.stages), staged.starts)
    for loss, refused in ((1.5, False), (anytime.READOUT_LOSS_LIMIT, False), (9.4, True)):
        path = save_readout(tmp_path / "r.npz",
                            SavedReadout(four, ("pac",), np.ones(1), (loss, 0.5)))  # fmt: skip
        back = load_readout(path)
        assert back.training_loss == (loss, 0.5) and back.readout.bits == 4
        if not refused:
            back.check_loss("r.npz")
            continue
        with pytest.raises(ValueError, match=r"r.npz: its 4-bit weights decide the training "
                           r"recordings 9.4 points below its float weights \(0.5 s into the "
                           r"run.*the limit is 2 points"):  # fmt: skip
            back.check_loss("r.npz")
    with np.load(path) as data:
        arrays = dict(data)
    arrays["training_loss"] = np.array([np.nan, 1.0])
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match=r"bad.npz: training_loss must be 2 finite numbers"):
        load_readout(tmp_path / "bad.npz")


def test_slide_trains_and_decides_a_staged_readout_on_causal_runs(tmp_path):
    # the path slide --readout --readout-train staged takes: causal counts at every stage's
    # prefix times, a staged readout per width, every held-out run decided at every threshold
    from spll_hw.datasets.biotac_channels import load_biotac_channels
    from spll_hw.multichannel.config import MultichannelConfig
    from spll_hw.multichannel.features import input_levels

    from .test_multichannel_data import write_recording
    from .test_multichannel_network import LOW

    folders = ("mat1", "mat2", "mat20")
    for folder in folders:
        for n in (1, 2, 3):
            write_recording(tmp_path, folder, n, rows=130 + 5 * n)
    (tmp_path / "mc.toml").write_text(LOW)
    config = MultichannelConfig.load(tmp_path / "mc.toml")
    samples = load_biotac_channels(tmp_path, ["ele1", "pdc"], list(folders), duration=1.0)
    held = np.array(["_3_" in str(r) for r in samples.recordings])
    train, test = samples.subset(np.flatnonzero(~held)), samples.subset(np.flatnonzero(held))
    names = list(train.class_names)
    got = anytime.anytime_over_class_sets(
        train, test, config, {"all": names}, 1.0, (None, 8), train_on="staged"
    )
    staged = got.readouts["all"]["float"]
    assert isinstance(staged, StagedReadout) and staged.starts == (START, 0.5)
    times, offset = anytime.training("staged", 1.0)
    levels = input_levels(config, train)
    counts = ro.causal_counts(train, config, levels, times)
    want = fit_staged(counts, times, train.labels, names, 1.0, (None,), None,
                      np.repeat([0, 1], config.groups[0].network.n), offset)  # fmt: skip
    np.testing.assert_array_equal(staged.weights, want["float"].weights)
    assert got.readouts["all"]["8-bit"].bits == 8
    loss, at = got.losses["all"]["8-bit"]  # measured on the training runs, as defined
    assert (
        at in times
        and loss
        == anytime.training_loss(got.readouts["all"]["8-bit"], staged, counts, times, train.labels)[
            0
        ]
    )
    points = got.points["all"]
    assert len(points) == 2 * len(anytime.THRESHOLDS)
    assert all(START <= p.mean_time <= 1.0 for p in points)
