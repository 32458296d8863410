"""Synthetic sliding-texture vibrations: an embedded dataset that needs no download.

A texture with spatial period ``lambda`` slid over at speed ``u`` vibrates at ``f0 = u / lambda``
and its harmonics; irregular textures give wide peaks, rough ones a strong broadband floor. Each
class draws (from ``seed``):

- a fundamental ``f0``, log-uniform over 60-420 Hz (so some classes lie close together),
- a harmonic decay ``rho`` in [0.2, 0.8] (harmonic ``k`` has amplitude ``rho**(k-1)``, k = 1..4),
- a peak width ``w`` in [4, 16] Hz,
- a broadband floor: level ``b`` in [0.05, 0.4] relative to the fundamental, first-order
  low-pass shape with corner ``fc`` in [100, 600] Hz,
- a second, inharmonic resonance of the finger and texture (a bending mode) at ``r · f0`` with
  ``r`` in [1.3, 2.7], relative amplitude in [0.2, 0.8] and its own width in [8, 30] Hz.

Each sample then varies within its class: sliding speed (all peak frequencies scaled by
``exp(N(0, 0.08))``), a speed drift within the sample (the speed changes linearly by
``N(0, 0.06)`` of itself from start to end, so every peak glides), overall amplitude
(``exp(N(0, 0.3))``) and random phases. The signal is ``irfft(E(f) * z(f))`` with ``E`` the
class envelope at the sample's mean speed and ``z`` complex white Gaussian noise, so peaks are
narrowband noise rather than pure tones, then time-warped by the drift; it is scaled to an RMS
of 100 (ADC-count-like units) times the amplitude factor. Everything is deterministic per
``seed``; 8 classes x 350 samples take about two seconds. Samples last
:data:`SYNTHETIC_DURATION` (1 s) by default, half the BioTac chunks: long enough for the drift
and every peak, and it halves the default report's simulation time.
"""

from __future__ import annotations

import numpy as np

from .samples import SampleSet

#: Default sample length [s] of the synthetic dataset (the demo's).
SYNTHETIC_DURATION = 1.0

_N_HARMONICS = 4
#: Within-class spread of the sliding speed (log-normal sd): shifts every peak of a sample.
_SPEED_SD = 0.08
#: Spread (sd) of the relative speed change from a sample's start to its end.
_DRIFT_SD = 0.06


def make_synthetic(
    n_classes: int = 8,
    samples_per_class: int = 350,
    duration: float = SYNTHETIC_DURATION,
    fs: float = 2200.0,
    seed: int = 0,
) -> SampleSet:
    """Generate the synthetic texture dataset (module docstring), ``n_classes * samples_per_class``
    samples of ``duration`` seconds at ``fs`` Hz."""
    if n_classes < 2:
        raise ValueError(f"synthetic dataset needs >= 2 classes, got {n_classes}")
    if samples_per_class < 1:
        raise ValueError(f"samples per class must be >= 1, got {samples_per_class}")
    if not fs >= 1000:
        raise ValueError(
            f"fs must be >= 1000 Hz so the textures' peaks fit below Nyquist, got {fs}"
        )
    length = int(round(duration * fs))
    if length < 16:
        raise ValueError(f"duration {duration} s is too short at {fs} Hz")
    rng = np.random.default_rng(seed)
    f0 = np.sort(np.exp(rng.uniform(np.log(60.0), np.log(420.0), n_classes)))
    rho = rng.uniform(0.2, 0.8, n_classes)
    width = rng.uniform(4.0, 16.0, n_classes)
    floor = rng.uniform(0.05, 0.4, n_classes)
    corner = rng.uniform(100.0, 600.0, n_classes)
    mode_ratio = rng.uniform(1.3, 2.7, n_classes)
    mode_height = rng.uniform(0.2, 0.8, n_classes)
    mode_width = rng.uniform(8.0, 30.0, n_classes)

    labels = np.repeat(np.arange(n_classes), samples_per_class)
    n = labels.size
    speed = np.exp(rng.normal(0.0, _SPEED_SD, n))
    drift = rng.normal(0.0, _DRIFT_SD, n)
    amplitude = np.exp(rng.normal(0.0, 0.3, n))
    freqs = np.fft.rfftfreq(length, 1.0 / fs)  # (F,)

    harmonic = np.arange(1, _N_HARMONICS + 1)  # (H,)
    lines = np.concatenate([harmonic[None, :] * np.ones((n_classes, 1)), mode_ratio[:, None]], 1)
    centres = (f0[labels] * speed)[:, None] * lines[labels]  # (n, H + 1) peak frequencies [Hz]
    heights = np.concatenate(
        [rho[:, None] ** (harmonic[None, :] - 1), mode_height[:, None]], axis=1
    )[labels]  # (n, H + 1)
    widths = np.concatenate(
        [np.repeat(width[:, None], _N_HARMONICS, axis=1), mode_width[:, None]], axis=1
    )[labels]  # (n, H + 1) [Hz]
    bumps = np.exp(-0.5 * ((freqs[None, None, :] - centres[:, :, None]) / widths[:, :, None]) ** 2)
    envelope = np.einsum("nh,nhf->nf", heights, bumps)
    envelope += floor[labels][:, None] / np.sqrt(
        1.0 + (freqs[None, :] / corner[labels][:, None]) ** 2
    )
    envelope[:, 0] = 0.0
    noise = rng.standard_normal((n, freqs.size)) + 1j * rng.standard_normal((n, freqs.size))
    signals = _drifted(np.fft.irfft(envelope * noise, n=length, axis=-1), drift)
    signals *= (100.0 * amplitude / np.sqrt(np.mean(signals**2, axis=-1)))[:, None]

    names = tuple(f"texture {c + 1} ({f0[c]:.0f} Hz)" for c in range(n_classes))
    sources = tuple(
        f"synthetic(seed={seed}) class {lab + 1} sample {i % samples_per_class + 1}"
        for i, lab in enumerate(labels)
    )
    return SampleSet(signals, fs, labels, names, sources, name="synthetic")


def _drifted(signals: np.ndarray, drift: np.ndarray) -> np.ndarray:
    """Time-warp every row of ``signals`` ``(n, L)`` so its speed changes linearly by
    ``drift[i]`` (relative) from start to end at an unchanged mean: the read rate is
    ``1 + d (k / L - 1/2)``, so sample ``k`` of the output reads the input at its integral
    ``k (1 + d (k / (2 L) - 1/2))``, linearly interpolated."""
    length = signals.shape[1]
    k = np.arange(length, dtype=float)
    out = np.empty_like(signals)
    for i, d in enumerate(drift):
        source = np.clip(k * (1.0 + d * (k / (2 * length) - 0.5)), 0.0, length - 1.0)
        out[i] = np.interp(source, k, signals[i])
    return out
