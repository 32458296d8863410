"""Feature extractors: spectrum downsampling, pressure spectrum, sFFT, ISI histogram, sPLL."""

from __future__ import annotations

import numpy as np
import pytest

import spll_hw
from spll_hw import presets
from spll_hw.config import NetworkConfig
from spll_hw.features import (
    isi_edges,
    isi_features,
    pressure_spectrum_features,
    sfft_features,
    spll_features,
)
from spll_hw.features.sfft import binned_trains, spike_spectrum
from spll_hw.features.spectrum import decimation_matrix, downsample_spectrum
from spll_hw.features.spll import part_rates


def test_downsampling_keeps_flat_spectra_flat_and_locates_peaks():
    flat = downsample_spectrum(np.ones((1, 1200)))
    assert flat.shape == (1, 50)
    np.testing.assert_allclose(flat, 1.0, atol=1e-9)  # unit DC gain, mirrored edges
    spectrum = np.zeros(2000)
    spectrum[40 * 17] = 1.0  # a line exactly at feature 17's centre
    features = downsample_spectrum(spectrum)[0]
    assert int(np.argmax(features)) == 17
    assert decimation_matrix(2000).shape == (2000, 50)
    with pytest.raises(ValueError, match="cannot downsample"):
        downsample_spectrum(np.ones(30))


def test_pressure_spectrum_feature_of_a_tone_sits_in_its_12hz_band():
    fs = 2200.0
    t = np.arange(4400) / fs
    x = np.stack([np.sin(2 * np.pi * 300 * t), np.sin(2 * np.pi * 120 * t)])
    features = pressure_spectrum_features(x, fs)
    assert features.shape == (2, 50)
    assert list(np.argmax(features, axis=1)) == [25, 10]  # 300 / 12, 120 / 12


def test_sfft_of_a_periodic_train_peaks_at_its_rate_and_harmonics():
    train = np.arange(1, 400) / 200.0  # 200 Hz for 2 s
    spectrum = spike_spectrum([train], 2.0)[0]
    assert spectrum.shape == (2000,)
    assert spectrum[0] == pytest.approx(399 / 2.0)  # DC = rate
    assert spectrum[400] == pytest.approx(spectrum[0], rel=0.01)  # 200 Hz line
    features = sfft_features([train], 2.0)[0]
    assert features.shape == (50,)
    assert features[10] > 5 * np.median(features) and features[20] > 5 * np.median(features)


def test_binning_keeps_spikes_at_the_window_edges():
    counts = binned_trains([np.array([0.0, 0.99999, 1.0])], 1.0, fs_bin=100.0)[0]
    assert counts.sum() == 3 and counts[0] == 1 and counts[-1] == 2


def test_isi_histogram_counts_every_interval():
    periodic = np.arange(0, 1, 5e-3)  # 5 ms intervals
    edges = isi_edges()
    counts = isi_features([periodic, np.array([0.0, 0.0001, 0.5]), np.array([1.0])])
    assert counts.shape == (3, 50)
    assert counts[0].sum() == periodic.size - 1
    assert counts[0, np.searchsorted(edges, 5e-3, side="right") - 1] == periodic.size - 1
    assert counts[1, 0] == 1 and counts[1, -1] == 1  # below / above the range: end bins
    assert counts[2].sum() == 0


def test_isi_edges_spacing():
    lin, geo = isi_edges(), isi_edges(spacing="geometric")
    assert lin[0] == geo[0] == pytest.approx(1e-3) and lin[-1] == geo[-1] == pytest.approx(0.1)
    np.testing.assert_allclose(np.diff(lin), np.diff(lin)[0])
    np.testing.assert_allclose(geo[1:] / geo[:-1], geo[1] / geo[0])
    with pytest.raises(ValueError, match="spacing"):
        isi_edges(spacing="mel")


def test_tuned_presets_carry_their_encoder_and_provenance():
    from spll_hw.config import read_encoder_table

    tuned = [n for n in presets.names() if "-tuned-" in n]
    assert "biotac-tuned-vary-offset-lif" in tuned
    for name in tuned:
        text = presets.path(name).read_text()
        # Where it was tuned and tested, so its README row can be traced and reproduced.
        assert "tuned on recordings 1-32" in text and "recordings 33-40" in text, name
        encoder, settings = read_encoder_table(name)
        assert encoder == name.rsplit("-", 1)[1] and settings, name
        net = NetworkConfig.preset(name).build()
        assert net.n_spll == 50 and net.layout in name


def test_thesis_network_presets():
    assert len([n for n in presets.names() if "-tuned-" not in n]) == 12
    config = NetworkConfig.preset("biotac-vary-offset-lif")
    net = config.build()
    assert net.n_spll == 50 and net.layout == "vary-offset"
    np.testing.assert_allclose(net.free_frequencies()[[0, -1]], [61.6, 669.0], rtol=1e-9)
    assert config.spll.g_tde_fac == 1.23e3 and config.spll.tau_cco_syn == 4.70e-2
    assert config.beta == 1.0
    scaled = NetworkConfig.preset("vibtac-time-scaled-lif").with_n(5).build()
    assert scaled.layout == "time-scaled"
    np.testing.assert_allclose(scaled.free_frequencies()[[0, -1]], [48.1, 523.0], rtol=1e-6)
    with pytest.raises(ValueError, match="unknown sPLL network preset"):
        NetworkConfig.preset("biotac-vary-offset-cochlea")


def test_spll_features_are_the_engine_tde_rates_in_chunks():
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_n(6).build()
    trains = [np.arange(1, 200) / f for f in (100.0, 250.0, 450.0)]
    trains = [t[t < 1.0] for t in trains]
    rates = spll_features(trains, 1.0, net, threads=1, chunk=2)
    assert rates.shape == (3, 6) and np.all(rates >= 0) and rates.sum() > 0
    direct = spll_hw.simulate_batch(net, trains, 1.0, threads=1)
    np.testing.assert_array_equal(rates, [r.tde_rates for r in direct])
    # different input frequencies give different feature vectors
    assert not np.array_equal(rates[0], rates[2])


def test_part_rates_count_every_tde_spike_in_its_own_stretch():
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_n(5).build()
    rng = np.random.default_rng(3)
    # a train that changes rate halfway: the halves' rates must differ where the window's cannot
    trains = [np.sort(np.concatenate([rng.uniform(0, 0.5, 40), rng.uniform(0.5, 1.0, 220)]))
              for _ in range(3)]  # fmt: skip
    runs = spll_hw.simulate_batch(net, trains, 1.0, threads=1, record_spikes=True)
    for parts in (1, 2, 3, 4):
        rates = part_rates(runs, parts)
        assert rates.shape == (3, parts * 5)
        for i, run in enumerate(runs):
            for k in range(parts):  # an independent count, stretch by stretch: [a, b)
                a, b = k / parts, (k + 1) / parts if k < parts - 1 else np.inf
                want = [np.sum((s >= a) & (s < b)) * parts for s in run.tde_spikes]
                np.testing.assert_array_equal(rates[i, 5 * k : 5 * (k + 1)], want)
        # the stretches' mean is the run's rate
        np.testing.assert_allclose(rates.reshape(3, parts, 5).mean(axis=1),
                                   [r.tde_rates for r in runs])  # fmt: skip
    halves = part_rates(runs, 2).reshape(3, 2, 5)
    assert np.any(halves[:, 0] != halves[:, 1])


def test_spll_features_in_parts_are_the_part_rates_whatever_the_chunk():
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_n(4).build()
    trains = [np.arange(1, 400) / f for f in (150.0, 300.0)]
    trains = [t[t < 1.0] for t in trains]
    runs = spll_hw.simulate_batch(net, trains, 1.0, threads=1, record_spikes=True)
    for chunk in (1, 2):
        quarters = spll_features(trains, 1.0, net, threads=1, chunk=chunk, parts=4)
        np.testing.assert_array_equal(quarters, part_rates(runs, 4))
    whole = spll_features(trains, 1.0, net, threads=1)
    np.testing.assert_allclose(quarters.reshape(2, 4, 4).mean(axis=1), whole)
    for bad in (0, 1.5, True):
        with pytest.raises(ValueError, match="parts must be an integer >= 1"):
            spll_features(trains, 1.0, net, parts=bad)
