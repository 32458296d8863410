"""The spiking readout (spll_hw/multichannel/readout.py): the ridge's scores as integrate-and-fire
membranes, exact crossing times, winner-take-all, integer weights."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sklearn.linear_model import RidgeClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from spll_hw.multichannel.anytime import stacked_prefixes, training
from spll_hw.multichannel.readout import Readout, decide

NAMES = ("a", "b", "c")


def spike_trains(rng, d: int, duration: float, rates) -> list[np.ndarray]:
    """Poisson spike times [s] of ``d`` TDEs with the given rates [Hz]."""
    return [np.sort(rng.uniform(0, duration, rng.poisson(r * duration))) for r in rates[:d]]


@pytest.fixture(scope="module")
def trained():
    rng = np.random.default_rng(0)
    centres = rng.uniform(5, 60, size=(3, 6))
    labels = np.repeat(np.arange(3), 20)
    rates = centres[labels] + rng.normal(0, 4, size=(60, 6))
    return rates, labels, centres


def test_a_membrane_at_the_end_of_a_run_is_the_ridge_score_times_the_run(trained):
    rates, labels, centres = trained
    readout = Readout.from_ridge(rates, labels, NAMES, alpha=2.0)
    ridge = make_pipeline(StandardScaler(), RidgeClassifier(alpha=2.0)).fit(rates, labels)
    rng = np.random.default_rng(1)
    for c in range(3):
        spikes = spike_trains(rng, 6, 2.0, centres[c])
        counts = np.array([len(s) for s in spikes], float)
        end = readout.membrane_path(spikes, 2.0).values[-1]
        scores = ridge.decision_function((counts / 2.0)[None, :])[0]
        np.testing.assert_allclose(end, 2.0 * scores, rtol=1e-9, atol=1e-9)
        fixed = decide(readout.membrane_path(spikes, 2.0), np.inf)
        assert not fixed.fired and fixed.time == 2.0
        assert fixed.label == ridge.predict((counts / 2.0)[None, :])[0]


def test_crossing_times_are_exact_on_stretches_and_at_jumps():
    readout = Readout(np.array([[0.0], [0.5], [0.0]]), np.array([2.0, 0.1, -1.0]), NAMES)
    path = readout.membrane_path([np.array([0.3, 0.4])], 1.0)
    # a rises at 2/s and reaches 0.5 at 0.25 s; b jumps from 0.03 to 0.53 at 0.3 s, then
    # from 0.54 to 1.04 at 0.4 s; c falls and never fires
    crossed = path.first_crossings(0.5)
    assert crossed[0] == pytest.approx(0.25, abs=1e-15)
    assert crossed[1] == 0.3 and np.isinf(crossed[2])
    assert decide(path, 0.5).label == 0 and decide(path, 0.5).time == pytest.approx(0.25)
    # at 1.02, b's jump at 0.4 s comes before a's stretch (1.02 at 0.51 s)
    assert (decide(path, 1.02).label, decide(path, 1.02).time) == (1, 0.4)
    # switched on at 0.35 s: a (0.7) and b (0.535) are both above 0.5 by then; the larger decides
    late = decide(path, 0.5, not_before=0.35)
    assert (late.label, late.time, late.fired) == (0, 0.35, True)
    np.testing.assert_allclose(path.at_time(0.35), [0.7, 0.535, -0.35])
    # nobody reaches 10 within the run: the largest membrane at the end decides, unfired
    assert decide(path, 10.0) == decide(path, np.inf) and not decide(path, 10.0).fired


def test_first_crossings_match_a_fine_time_grid(trained):
    rates, labels, centres = trained
    readout = Readout.from_ridge(rates, labels, NAMES)
    rng = np.random.default_rng(2)
    spikes = spike_trains(rng, 6, 1.0, centres[1])
    path = readout.membrane_path(spikes, 1.0)
    grid = np.linspace(0, 1.0, 200_001)
    counts = np.stack([np.searchsorted(s, grid, side="right") for s in spikes], axis=1)
    v = counts @ readout.weights.T + grid[:, None] * readout.bias
    for theta in (0.05, 0.2, 0.5):
        exact = path.first_crossings(theta)
        for j in range(3):
            hit = np.flatnonzero(v[:, j] >= theta)
            if hit.size:
                assert abs(exact[j] - grid[hit[0]]) <= 1.0 / 200_000 + 1e-12
            else:
                assert np.isinf(exact[j]) or exact[j] > grid[-2]


def test_quantized_weights_are_integers_of_a_power_of_two_scale_per_group(trained):
    rates, labels, _ = trained
    readout = Readout.from_ridge(rates, labels, NAMES)
    groups = np.array([0, 0, 0, 1, 1, 1])
    q = readout.quantized(8, groups)
    for g in (0, 1):
        w = readout.weights[:, groups == g]
        step = 2.0 ** np.ceil(np.log2(np.percentile(np.abs(w), 99) / 127))
        units = q.weights[:, groups == g] / step
        np.testing.assert_allclose(units, np.round(units), atol=1e-9)
        assert np.max(np.abs(units)) <= 127 and q.bits == 8
        inside = np.abs(w) <= 127 * step  # the others saturate at +-127 steps
        assert np.max(np.abs(units * step - w)[inside]) <= step / 2 + 1e-12
    # with the training rates, the bias absorbs the rounding's mean effect on their scores
    coarse = readout.quantized(3, groups, rates)
    plain = readout.quantized(3, groups)
    shift = np.abs(np.mean(coarse.scores(rates) - readout.scores(rates), axis=0))
    bias_step = np.percentile(np.abs(coarse.bias), 99) / 3
    assert np.all(shift <= bias_step / 2 + 1e-9)
    assert np.abs(np.mean(plain.scores(rates) - readout.scores(rates), axis=0)).max() > shift.max()


def onset_runs(rng, centres, labels, burst, duration: float = 2.0) -> list[list[np.ndarray]]:
    """Spike times [s] of 6 TDEs per run: a burst of ``burst[i]`` spikes in the first 50 ms,
    the same for every class (an onset transient), then Poisson at the class's rates [Hz]."""
    return [
        [
            np.sort(
                np.r_[rng.uniform(0, 0.05, b), rng.uniform(0, duration, rng.poisson(r * duration))]
            )
            for r, b in zip(centres[c], burst, strict=True)
        ]
        for c in labels
    ]


def counts_at(runs, times) -> np.ndarray:
    """``N_i(t)`` of every run at every time, shape ``(runs, times, TDEs)``."""
    return np.array([[[np.searchsorted(s, t, side="right") for s in run] for t in times]
                     for run in runs])  # fmt: skip


@pytest.fixture(scope="module")
def onsets():
    rng = np.random.default_rng(0)
    centres, burst = rng.uniform(5, 60, size=(3, 6)), rng.integers(0, 30, 6)
    labels = np.repeat(np.arange(3), 20)
    return rng, centres, burst, labels, onset_runs(rng, centres, labels, burst)


def test_a_readout_trained_on_prefixes_decides_early_where_the_end_trained_one_cannot(onsets):
    rng, centres, burst, labels, runs = onsets
    times = (0.25, 0.5, 1.0, 2.0)
    counts = counts_at(runs, times)
    end = Readout.from_ridge(*stacked_prefixes(counts[:, -1:], times[-1:], labels), NAMES)
    prefixes = Readout.from_ridge(*stacked_prefixes(counts, times, labels), NAMES)
    truth = np.repeat(np.arange(3), 50)
    held_out = counts_at(onset_runs(rng, centres, truth, burst), (0.25, 2.0))

    def accuracy(readout, column, t):
        return np.mean(np.argmax(readout.scores(held_out[:, column] / t), axis=1) == truth)

    # the burst is 4 s-worth of rate at 0.25 s against 0.5 at 2 s: the end-trained weights
    # read it as class evidence; trained on prefixes, the weights learn to ignore it
    assert accuracy(end, 0, 0.25) <= 0.7 and accuracy(prefixes, 0, 0.25) >= 0.9
    assert accuracy(end, 1, 2.0) >= 0.95 and accuracy(prefixes, 1, 2.0) >= 0.95


def test_a_prefix_trained_readout_still_folds_exactly(onsets):
    _, _, _, labels, runs = onsets
    times = (0.25, 0.5, 1.0, 2.0)
    rates, stacked = stacked_prefixes(counts_at(runs, times), times, labels)
    assert rates.shape == (60 * 4, 6) and np.array_equal(stacked[:4], [0, 0, 0, 0])
    np.testing.assert_allclose(rates[1], counts_at(runs[:1], [0.5])[0, 0] / 0.5)
    readout = Readout.from_ridge(rates, stacked, NAMES, alpha=2.0, offset=1.0)
    ridge = make_pipeline(StandardScaler(), RidgeClassifier(alpha=2.0)).fit(rates, stacked)
    for run in runs[::17]:
        path = readout.membrane_path(run, 2.0)
        for t in (0.13, 0.25, 0.7, 1.9):  # trained or not, a prefix's membrane is t x its score
            x = counts_at([run], [t])[0, 0] / t
            score = ridge.decision_function(x[None])[0] + 1.0  # plus the offset
            np.testing.assert_allclose(path.at_time(t), t * score, rtol=1e-9, atol=1e-9)


def test_training_plans_and_bad_prefixes_are_refused():
    assert training("end", 4.0) == ((4.0,), 0.0)
    assert training("prefixes", 1.5) == ((0.25, 0.5, 1.0, 1.5), 1.0)
    with pytest.raises(ValueError, match="'prefixes' or 'end'"):
        training("start", 4.0)
    with pytest.raises(ValueError, match=r"shape \(runs 3, times 2, TDEs\)"):
        stacked_prefixes(np.zeros((3, 1, 6)), (0.5, 1.0), np.arange(3))


def test_bad_readout_input_is_refused(trained):
    rates, labels, _ = trained
    readout = Readout.from_ridge(rates, labels, NAMES)
    with pytest.raises(ValueError, match="bits must be in 2..32"):
        readout.quantized(1)
    with pytest.raises(ValueError, match="one id per TDE"):
        readout.quantized(8, np.zeros(5))
    with pytest.raises(ValueError, match=">= 3 classes"):
        Readout.from_ridge(rates[:40], labels[:40], NAMES[:2])
    with pytest.raises(ValueError, match="threshold must be > 0"):
        decide(readout.membrane_path([np.zeros(0)] * 6, 1.0), 0.0)
    with pytest.raises(ValueError, match="5 TDE spike trains, the readout takes 6"):
        readout.membrane_path([np.zeros(0)] * 5, 1.0)


def test_readout_spikes_are_causal_and_need_a_causal_encoder(tmp_path):
    from spll_hw.datasets.biotac_channels import load_biotac_channels
    from spll_hw.multichannel.config import MultichannelConfig
    from spll_hw.multichannel.features import input_levels
    from spll_hw.multichannel.readout import causal_counts, tde_spikes

    from .test_multichannel_data import write_recording
    from .test_multichannel_network import LOW

    for folder in ("mat1", "mat2"):
        for n in (1, 2):
            write_recording(tmp_path, folder, n, rows=150)
    (tmp_path / "mc.toml").write_text(LOW)
    config = MultichannelConfig.load(tmp_path / "mc.toml")
    samples = load_biotac_channels(tmp_path, ["ele1", "pdc"], ["mat1", "mat2"], duration=1.0)
    levels = input_levels(config, samples)
    whole = tde_spikes(samples, config, levels)
    # the training counts of the same causal runs: at the end without their spike times, at
    # earlier times from spike times dropped chunk by chunk
    counts = np.array([[len(t) for t in run] for run in whole])
    np.testing.assert_array_equal(causal_counts(samples, config, levels, [1.0])[:, 0], counts)
    times = [0.3, 0.55, 1.0]
    prefixes = np.array([[[np.sum(t <= c) for t in run] for c in times] for run in whole])
    assert 0 < prefixes[:, 0].sum() < prefixes[:, 1].sum() < prefixes[:, 2].sum()
    np.testing.assert_array_equal(causal_counts(samples, config, levels, times), prefixes)
    with pytest.raises(ValueError, match=r"prefix times must lie in \(0, 1\] s"):
        causal_counts(samples, config, levels, [0.5, 1.5])
    # the same samples with everything after 0.5 s changed: no spike before 0.5 s moves
    later = {name: s.signals.copy() for name, s in samples.channels.items()}
    for x in later.values():
        x[:, 50:] = x[:, 50:] * 3.0 + 7.0
    changed = type(samples)(
        {n: dataclasses.replace(s, signals=later[n]) for n, s in samples.channels.items()}
    )
    cut = tde_spikes(changed, config, levels)
    assert sum(len(t) for run in whole for t in run) > 0
    for a, b in zip(whole, cut, strict=True):
        for x, y in zip(a, b, strict=True):
            np.testing.assert_array_equal(x[x < 0.5], y[y < 0.5])
    single = MultichannelConfig.single("pac", "biotac-tuned-vary-offset-peak")
    with pytest.raises(ValueError, match="needs a causal encoder"):
        tde_spikes(samples, single, {"pac": 1.0})


def test_causal_centering_subtracts_the_mean_so_far():
    from spll_hw.multichannel.readout import causal_centered

    x = np.random.default_rng(3).normal(size=(2, 50)) + 5.0
    y = causal_centered(x)
    for i in (0, 1, 17, 49):
        np.testing.assert_allclose(y[:, i], x[:, i] - x[:, : i + 1].mean(axis=1))
    changed = x.copy()
    changed[:, 30:] += 100.0
    np.testing.assert_array_equal(causal_centered(changed)[:, :30], y[:, :30])
