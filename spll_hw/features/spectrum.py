"""Spectrum of the pressure signal as a 50-vector, and the shared spectrum downsampling (2.3).

Downsampling a spectrum of ``N`` values to ``n_out``: with ``q = N // n_out`` (values beyond
``q * n_out`` are dropped), the spectrum is smoothed by a linear-phase FIR low-pass (Hamming
window, ``8 q + 1`` taps, cutoff at the new Nyquist ``1/q``; edges mirrored) and every ``q``-th
value is kept, starting with the first. Feature ``k`` thus summarises the band around
``k * q`` bins. The operation is linear, so it is applied as one ``(N', n_out)`` matrix product.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal

#: Feature-vector length used throughout the thesis.
N_FEATURES = 50
#: Highest frequency [Hz] of the pressure spectrum (thesis 3.1: ~1200 values of 0.5 Hz).
PRESSURE_F_MAX = 600.0


@lru_cache(maxsize=16)
def decimation_matrix(n: int, n_out: int = N_FEATURES) -> np.ndarray:
    """Matrix ``M`` of shape ``(q * n_out, n_out)`` such that ``spectrum[:q*n_out] @ M`` is the
    FIR-smoothed, decimated spectrum (module docstring). Read-only, cached."""
    q = n // n_out
    if q < 1:
        raise ValueError(f"cannot downsample {n} spectrum values to {n_out} features")
    m = q * n_out
    taps = signal.firwin(8 * q + 1, 1.0 / q, window="hamming") if q > 1 else np.ones(1)
    half = taps.size // 2
    eye = np.pad(np.eye(m), ((0, 0), (half, half)), mode="reflect")
    smoothed = signal.fftconvolve(eye, taps[None, :], mode="valid", axes=1)  # (m, m)
    matrix = np.ascontiguousarray(smoothed[:, ::q])
    matrix.setflags(write=False)
    return matrix


def downsample_spectrum(spectra: np.ndarray, n_out: int = N_FEATURES) -> np.ndarray:
    """Downsample spectra of shape ``(n, N)`` (or ``(N,)``) to ``(n, n_out)``."""
    s = np.atleast_2d(np.asarray(spectra, dtype=float))
    matrix = decimation_matrix(s.shape[-1], n_out)
    return s[:, : matrix.shape[0]] @ matrix


def magnitude_spectrum(signals: np.ndarray, fs: float, f_max: float) -> np.ndarray:
    """``|FFT|`` of mean-free ``signals`` ``(n, L)`` divided by ``L``, bins below ``f_max`` [Hz].

    Returns shape ``(n, ceil(f_max * L / fs))`` with bin ``k`` at ``k * fs / L`` Hz.
    """
    x = np.atleast_2d(np.asarray(signals, dtype=float))
    x = x - x.mean(axis=-1, keepdims=True)
    n_keep = int(np.ceil(f_max * x.shape[-1] / fs))
    if n_keep > x.shape[-1] // 2 + 1:
        raise ValueError(f"f_max {f_max} Hz is above the Nyquist frequency {fs / 2} Hz")
    return np.abs(np.fft.rfft(x, axis=-1)[:, :n_keep]) / x.shape[-1]


def pressure_spectrum_features(
    signals: np.ndarray, fs: float, f_max: float = PRESSURE_F_MAX, n_out: int = N_FEATURES
) -> np.ndarray:
    """Dataset-spectrum features (thesis 3.1): ``|FFT|`` up to ``f_max`` Hz downsampled to 50.

    For 2-s samples at 2.2 kHz: 1200 bins of 0.5 Hz → 50 features of 12 Hz. Shape ``(n, n_out)``.
    """
    return downsample_spectrum(magnitude_spectrum(signals, fs, f_max), n_out)
