"""Encoders: TouchSim PC reference spikes, exact LIF timing, spectral peaks."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.encoders import (
    LIFEncoder,
    PacinianEncoder,
    PeakOscillatorEncoder,
    make_encoder,
)
from spll_hw.encoders.lif import lif_spike_times
from spll_hw.encoders.pacinian import (
    PC_FS,
    PC_PARAMETERS,
    central_velocity,
    pc_spike_times,
    post_spike_basis,
)
from spll_hw.encoders.peak_oscillator import periodic_trains, spectral_peaks

from .pipeline_data import TOUCHSIM_REF, needs_touchsim_ref
from .test_datasets import write_biotac

# ---------------------------------------------------------------------------------- Pacinian


def _matched_fraction(spikes: np.ndarray, reference: np.ndarray, tol: float) -> float:
    """Fraction of reference spikes with one of ``spikes`` within ``tol`` seconds."""
    if reference.size == 0:
        return 1.0 if spikes.size == 0 else 0.0
    if spikes.size == 0:
        return 0.0
    j = np.searchsorted(spikes, reference)
    before = spikes[np.clip(j - 1, 0, spikes.size - 1)]
    after = spikes[np.clip(j, 0, spikes.size - 1)]
    nearest = np.minimum(np.abs(before - reference), np.abs(after - reference))
    return float(np.mean(nearest <= tol + 1e-12))


@needs_touchsim_ref
def test_pacinian_reproduces_touchsim_reference_spikes():
    ref = np.load(TOUCHSIM_REF / "pc_vectors.npz")
    names = sorted(k.removeprefix("input__") for k in ref.files if k.startswith("input__"))
    assert len(names) >= 20
    by_length: dict[int, list[str]] = {}
    for name in names:
        by_length.setdefault(ref[f"input__{name}"].size, []).append(name)
    checked = 0
    for model in range(len(PC_PARAMETERS)):
        np.testing.assert_array_equal(ref[f"params_pc{model}"][:12], PC_PARAMETERS[model][:12])
        for group in by_length.values():
            x = np.stack([ref[f"input__{n}"] for n in group])
            for name, spikes in zip(group, pc_spike_times(x, PC_PARAMETERS[model]), strict=True):
                expected = ref[f"spikes_pc{model}__{name}"]
                where = f"model {model}, input {name}"
                assert abs(spikes.size - expected.size) <= 0.02 * expected.size, where
                assert _matched_fraction(spikes, expected, 0.4e-3) >= 0.95, where
                checked += 1
    assert checked == 4 * len(names)


def test_post_spike_basis_is_two_raised_cosines():
    basis = post_spike_basis()
    assert basis.shape == (2, 190)
    assert basis[0, 0] == pytest.approx(1.0) and np.all(basis[0, 17:] == 0)
    assert int(np.argmax(basis[1])) == 40 and np.all(basis[1, :6] == 0)
    assert np.all(np.diff(basis[0, :18]) <= 0) and basis[1, -1] < 1e-4
    # in log time the bumps are 2/3 of their centre distance wide: they cross at n = 10
    crossing = np.argmin(np.abs(basis[0, :40] - basis[1, :40]))
    assert crossing == 10
    assert basis[0, 10] == pytest.approx((1 + np.cos(3 * np.pi / 4)) / 2)


def test_central_velocity_copies_ends():
    x = np.array([0.0, 1.0, 4.0, 9.0, 16.0])
    v = central_velocity(x, fs=2.0)
    np.testing.assert_allclose(v, [4.0, 4.0, 8.0, 12.0, 12.0])


def test_pacinian_noise_is_seeded_per_sample_not_per_batch():
    rng = np.random.default_rng(1)
    signals = rng.standard_normal((3, 2200))
    enc = PacinianEncoder(noisy=True, seed=7, rms_um=1.0)  # near threshold: noise matters
    batch = enc.encode(signals, 2200.0, ids=[10, 11, 12])
    alone = enc.encode(signals[1:2], 2200.0, ids=[11])
    np.testing.assert_array_equal(batch[1], alone[0])
    quiet = PacinianEncoder(noisy=False, rms_um=1.0).encode(signals, 2200.0)
    assert any(not np.array_equal(a, b) for a, b in zip(batch, quiet, strict=True))


def test_pacinian_noise_of_a_recording_window_is_the_same_in_every_set(tmp_path):
    from spll_hw.datasets import load_biotac
    from spll_hw.datasets.samples import sample_id
    from spll_hw.pipeline import encode_samples

    for root, recordings in ((tmp_path / "few", [2]), (tmp_path / "many", [1, 2, 3, 4])):
        for folder in ("mat1", "mat2"):
            for n in recordings:
                write_biotac(root, folder, n=n, rows=420)  # two 2-s windows per recording
    window = "raw_data/mat2/mat2_2_bio.csv [2-4 s]"
    enc = PacinianEncoder(seed=3, rms_um=0.2)  # near threshold: the noise decides spikes

    def spikes_of_window(samples, jobs=1):
        return encode_samples(enc, samples, jobs)[samples.sources.index(window)]

    few = load_biotac(tmp_path / "few", classes="mat2")  # the window and one other
    alone = few.subset([few.sources.index(window)])
    many = load_biotac(tmp_path / "many", classes="mat1,mat2")  # 16 windows, another folder
    got = spikes_of_window(alone)
    assert got.size > 0 and len(few) == 2 and len(many) == 16
    for samples, jobs in ((few, 1), (many, 1), (many, 2), (many.subset(range(15, 0, -1)), 1)):
        np.testing.assert_array_equal(spikes_of_window(samples, jobs), got)
    assert sample_id(window) == 0xA9EC1A6BE13B528A  # the same in every run and process
    other_seed = encode_samples(PacinianEncoder(seed=4, rms_um=0.2), alone)[0]
    positional = enc.encode(alone.signals, alone.fs, ids=[0])[0]  # what index seeding drew
    assert not np.array_equal(other_seed, got) and not np.array_equal(positional, got)


def test_pacinian_rms_scaling_makes_amplitude_irrelevant_and_gain_mode_keeps_it():
    t = np.arange(4400) / 2200.0
    x = np.sin(2 * np.pi * 150 * t)[None, :]
    rms = PacinianEncoder(noisy=False)
    np.testing.assert_array_equal(rms.encode(x, 2200.0)[0], rms.encode(50 * x, 2200.0)[0])
    gain = PacinianEncoder(noisy=False, rms_um=None, gain_mm=1e-3)
    assert gain.encode(0.1 * x, 2200.0)[0].size < gain.encode(50 * x, 2200.0)[0].size


def test_pacinian_spikes_lie_in_sample_and_phase_lock_to_vibration():
    t = np.arange(int(PC_FS)) / PC_FS
    x = 0.02 * np.sin(2 * np.pi * 200 * t)  # 20 um at 200 Hz, 1 s
    spikes = pc_spike_times(x, PC_PARAMETERS[0])[0]
    assert 0 < spikes[0] and spikes[-1] <= 1.0
    assert 150 <= spikes.size <= 250  # one spike per cycle, entrained


def test_pacinian_rejects_bad_parameters():
    with pytest.raises(ValueError, match="PC model"):
        PacinianEncoder(model=4)
    with pytest.raises(ValueError, match="rms_um"):
        PacinianEncoder(rms_um=0.0)


# ---------------------------------------------------------------------------------- LIF


def test_lif_constant_current_fires_at_the_analytic_rate():
    tau, t_ref, current = 5e-3, 1e-3, 500.0  # I * tau = 2.5
    period = t_ref + tau * np.log(current * tau / (current * tau - 1.0))
    spikes = lif_spike_times(np.full((1, 2200), current), 2200.0, tau, t_ref)[0]
    first = tau * np.log(current * tau / (current * tau - 1.0))
    assert spikes[0] == pytest.approx(first, rel=1e-12)
    np.testing.assert_allclose(np.diff(spikes), period, rtol=1e-9)
    assert spikes.size == int((1.0 - first) / period) + 1


def test_lif_several_spikes_per_sample_interval_when_refractory_is_short():
    tau, t_ref, current = 10e-3, 0.1e-3, 5000.0
    period = t_ref + tau * np.log(current * tau / (current * tau - 1.0))
    spikes = lif_spike_times(np.full((1, 100), current), 100.0, tau, t_ref)[0]  # 10 ms steps
    assert period < 0.5e-3 and spikes.size > 1000
    np.testing.assert_allclose(np.diff(spikes), period, rtol=1e-9)


def test_lif_subthreshold_and_negative_currents_are_silent():
    currents = np.array([np.full(500, 99.0), np.full(500, -300.0)])  # tau * I < 1, < 0
    assert all(s.size == 0 for s in lif_spike_times(currents, 1000.0, 10e-3, 1e-3))


def test_lif_batch_equals_single_rows():
    rng = np.random.default_rng(3)
    signals = rng.standard_normal((4, 2200))
    enc = LIFEncoder()
    batch = enc.encode(signals, 2200.0)
    for row, spikes in enumerate(batch):
        np.testing.assert_array_equal(spikes, enc.encode(signals[row : row + 1], 2200.0)[0])
    assert all(np.all(np.diff(s) >= enc.t_ref - 1e-12) for s in batch)


def test_lif_rms_normalisation_removes_amplitude():
    rng = np.random.default_rng(4)
    x = rng.standard_normal((1, 2200))
    enc = LIFEncoder(normalize="rms", gain=800.0)
    np.testing.assert_allclose(enc.encode(x, 2200.0)[0], enc.encode(30 * x, 2200.0)[0])
    with pytest.raises(ValueError, match="normalize"):
        LIFEncoder(normalize="max")


# ---------------------------------------------------------------------------------- peaks


def _tones(freqs, amps, fs=2200.0, duration=2.0):
    t = np.arange(int(fs * duration)) / fs
    return sum(a * np.sin(2 * np.pi * f * t) for f, a in zip(freqs, amps, strict=True))[None, :]


def test_spectral_peaks_finds_the_three_strongest_in_order():
    x = _tones([90.0, 230.0, 410.0, 500.0], [1.0, 3.0, 2.0, 0.3])
    peaks = spectral_peaks(x, 2200.0, spectrum="pressure")[0]
    np.testing.assert_allclose(peaks, [230.0, 410.0, 90.0], atol=0.5)


def test_spectral_peaks_keeps_min_spacing():
    x = _tones([200.0, 210.0, 400.0, 600.0], [3.0, 2.5, 1.0, 0.8])
    peaks = spectral_peaks(x, 2200.0, cutoff=None, spectrum="pressure")[0]
    assert 210.0 not in peaks and np.min(np.diff(np.sort(peaks))) >= 16.0
    np.testing.assert_allclose(peaks, [200.0, 400.0, 600.0], atol=0.5)


def test_derivative_spectrum_is_the_default_and_ranks_by_amplitude_times_frequency():
    # pressure amplitudes 1.0, 0.3, 0.25 at 30, 300, 150 Hz; times f: 30, 90, 37.5
    x = _tones([30.0, 300.0, 150.0], [1.0, 0.3, 0.25])
    pressure = spectral_peaks(x, 2200.0, spectrum="pressure")[0]
    np.testing.assert_allclose(pressure, [30.0, 300.0, 150.0], atol=0.5)
    np.testing.assert_allclose(spectral_peaks(x, 2200.0)[0], [300.0, 150.0, 30.0], atol=0.5)
    spikes = make_encoder("peak", n_peaks=1).encode(x, 2200.0)[0]
    np.testing.assert_allclose(spikes, np.arange(1, 600) / 300.0, atol=1e-12)
    slow = make_encoder("peak", n_peaks=1, spectrum="pressure").encode(x, 2200.0)[0]
    np.testing.assert_allclose(slow, np.arange(1, 60) / 30.0, atol=1e-12)
    with pytest.raises(ValueError, match="spectrum must be one of"):
        PeakOscillatorEncoder(spectrum="velocity")


def test_peak_oscillator_emits_periodic_trains_of_any_duration():
    x = _tones([100.0, 250.0, 400.0], [3.0, 2.0, 1.0])
    spikes = PeakOscillatorEncoder(duration=5.0).encode(x, 2200.0)[0]
    assert spikes[-1] < 5.0
    assert spikes.size == pytest.approx(5.0 * (100 + 250 + 400), abs=3)
    np.testing.assert_allclose(periodic_trains(np.array([50.0]), 0.1), np.arange(1, 5) / 50.0)
    assert PeakOscillatorEncoder().encode(np.zeros((1, 4400)), 2200.0)[0].size == 0


def test_make_encoder_names_and_errors():
    assert make_encoder("lif", tau=3e-3).tau == 3e-3
    with pytest.raises(ValueError, match="unknown encoder"):
        make_encoder("cochlea")
    with pytest.raises(ValueError, match="bad parameters"):
        make_encoder("peak", n_peak=3)
