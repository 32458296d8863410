"""Spiking FFT (sFFT) features (thesis 2.3): the spectrum of a binned spike train as a 50-vector.

Spikes are counted in bins of ``1 / fs_bin`` seconds over ``[0, duration)`` (a spike at exactly
``duration`` goes into the last bin), the ``|FFT|`` of that count signal divided by ``duration``
(so bin 0 is the firing rate [Hz]) is kept below ``f_max`` Hz and downsampled to 50 values with
:func:`~spll_hw.features.spectrum.downsample_spectrum`. For 2-s samples: 2000 bins of 0.5 Hz up to
1 kHz → 50 features of 20 Hz (thesis 3.2).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .spectrum import N_FEATURES, downsample_spectrum

#: Rate of the binned spike signal [Hz], well above the highest spike rates (~1 kHz).
SFFT_FS = 10_000.0
#: Highest frequency [Hz] kept before downsampling.
SFFT_F_MAX = 1000.0


def binned_trains(
    trains: Sequence[np.ndarray], duration: float, fs_bin: float = SFFT_FS
) -> np.ndarray:
    """Spike counts per bin, shape ``(n, round(duration * fs_bin))``."""
    n_bins = int(round(duration * fs_bin))
    out = np.zeros((len(trains), n_bins))
    for row, train in enumerate(trains):
        idx = np.clip((np.asarray(train) * fs_bin).astype(np.int64), 0, n_bins - 1)
        out[row] = np.bincount(idx, minlength=n_bins)
    return out


def spike_spectrum(
    trains: Sequence[np.ndarray],
    duration: float,
    fs_bin: float = SFFT_FS,
    f_max: float = SFFT_F_MAX,
) -> np.ndarray:
    """``|FFT| / duration`` of the binned trains below ``f_max`` Hz, ``(n, f_max * duration)``."""
    if not f_max <= fs_bin / 2:
        raise ValueError(f"f_max {f_max} Hz must not exceed half the bin rate {fs_bin} Hz")
    counts = binned_trains(trains, duration, fs_bin)
    n_keep = int(np.ceil(f_max * counts.shape[1] / fs_bin))
    return np.abs(np.fft.rfft(counts, axis=-1)[:, :n_keep]) / duration


def sfft_features(
    trains: Sequence[np.ndarray],
    duration: float,
    fs_bin: float = SFFT_FS,
    f_max: float = SFFT_F_MAX,
    n_out: int = N_FEATURES,
) -> np.ndarray:
    """sFFT feature vectors, shape ``(n, n_out)`` (module docstring)."""
    return downsample_spectrum(spike_spectrum(trains, duration, fs_bin, f_max), n_out)
