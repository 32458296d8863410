"""Frequency-peak oscillator: an idealised encoder that keeps only the strongest spectral peaks.

Thesis 2.2: the pressure signal is low-pass filtered (zero-phase Butterworth, ``order``, cutoff
``cutoff`` Hz), its FFT magnitude is taken, and the ``n_peaks`` highest local maxima at least
``min_spacing`` Hz apart (and at or above ``f_min``) are kept. By default (``spectrum=
"derivative"``) the magnitude is that of the pressure's time derivative (times ``2 pi f``). The
thesis does not say so, but on BioTac only that spectrum reproduces what it reports for this
encoder: Table 1's sFFT and ISI accuracies, Figure 5 (metal spiking far slower than towel and
styrofoam) and Table 7's tuned peak networks (86-497 Hz, which a study re-finds);
``spectrum="pressure"``, the literal reading, puts all three peaks on the spectrum's
low-frequency skirt (docs/pipeline_results.md). Each peak frequency ``f`` drives an
oscillator started at ``t = 0`` that fires at ``k / f`` (k = 1, 2, ...); the trains are merged.
The encoder is deterministic (phase noise, if wanted, is added downstream by the pipeline).
Because the output is stationary it can be made any ``duration`` long (default: the sample's).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import signal

#: Spectra the peaks can be picked from (see :func:`spectral_peaks`).
SPECTRA = ("pressure", "derivative")


def spectral_peaks(
    signals: np.ndarray,
    fs: float,
    n_peaks: int = 3,
    min_spacing: float = 16.0,
    f_min: float = 0.0,
    cutoff: float | None = 550.0,
    order: int = 4,
    spectrum: str = "derivative",
) -> np.ndarray:
    """Frequencies [Hz] of the ``n_peaks`` largest FFT-magnitude peaks of each row.

    Args:
        signals: pressure samples, shape ``(n, L)``, sampled at ``fs`` [Hz].
        min_spacing: minimum distance between kept peaks [Hz].
        f_min: peaks below this frequency [Hz] are ignored.
        cutoff: low-pass cutoff [Hz] applied first (``None`` or >= fs/2: no filter).
        spectrum: ``"pressure"`` (the signal's own spectrum) or ``"derivative"`` (its time
            derivative's: the magnitude weighted by ``2 pi f``).

    Returns:
        Shape ``(n, n_peaks)``, each row sorted by decreasing peak height; ``nan`` where a
        signal has fewer peaks (e.g. a constant signal has none).
    """
    if spectrum not in SPECTRA:
        raise ValueError(f"spectrum must be one of {SPECTRA}, got {spectrum!r}")
    x = np.atleast_2d(np.asarray(signals, dtype=float))
    x = x - x.mean(axis=-1, keepdims=True)
    if cutoff is not None and cutoff < fs / 2:
        sos = signal.butter(order, cutoff, fs=fs, output="sos")
        x = signal.sosfiltfilt(sos, x, axis=-1)
    magnitude = np.abs(np.fft.rfft(x, axis=-1))
    freqs = np.fft.rfftfreq(x.shape[-1], 1.0 / fs)
    if spectrum == "derivative":
        magnitude *= 2.0 * np.pi * freqs
    distance = max(1, int(np.ceil(min_spacing / freqs[1])))
    valid = freqs >= f_min
    out = np.full((len(x), n_peaks), np.nan)
    for row, mag in enumerate(magnitude):
        peaks, _ = signal.find_peaks(np.where(valid, mag, 0.0), distance=distance)
        peaks = peaks[mag[peaks] > 0]
        best = peaks[np.argsort(mag[peaks])[::-1][:n_peaks]]
        out[row, : best.size] = freqs[best]
    return out


def periodic_trains(frequencies: np.ndarray, duration: float) -> np.ndarray:
    """Merged periodic spike trains: times ``k / frequencies[i]``, k >= 1, in ``(0, duration)``.

    ``nan`` frequencies are skipped. Returns one sorted array of spike times [s].
    """
    trains = [
        np.arange(1, np.ceil(duration * f)) / f for f in frequencies if np.isfinite(f) and f > 0
    ]
    return np.sort(np.concatenate(trains)) if trains else np.zeros(0)


@dataclass(frozen=True)
class PeakOscillatorEncoder:
    """Pressure → spikes at the ``n_peaks`` strongest spectral peaks (module docstring).

    ``duration`` [s] of the produced trains defaults to the sample duration.
    """

    n_peaks: int = 3
    min_spacing: float = 16.0
    f_min: float = 0.0
    cutoff: float | None = 550.0
    duration: float | None = None
    spectrum: str = "derivative"

    name = "peak"

    def __post_init__(self) -> None:
        if self.n_peaks < 1:
            raise ValueError(f"n_peaks must be >= 1, got {self.n_peaks}")
        if not self.min_spacing > 0:
            raise ValueError(f"min_spacing must be > 0 Hz, got {self.min_spacing!r}")
        if self.cutoff is not None and not self.cutoff > 0:
            raise ValueError(f"cutoff must be > 0 Hz or None, got {self.cutoff!r}")
        if self.duration is not None and not self.duration > 0:
            raise ValueError(f"duration must be > 0 s or None, got {self.duration!r}")
        if self.spectrum not in SPECTRA:
            raise ValueError(f"spectrum must be one of {SPECTRA}, got {self.spectrum!r}")

    def encode(
        self, signals: np.ndarray, fs: float, ids: Sequence[int] | None = None
    ) -> list[np.ndarray]:
        """Spike times [s] for each row of ``signals`` ``(n, L)`` sampled at ``fs`` [Hz].

        ``ids`` is accepted for interface symmetry and unused: this encoder is deterministic.
        """
        del ids
        x = np.atleast_2d(signals)
        duration = x.shape[-1] / fs if self.duration is None else self.duration
        peaks = spectral_peaks(
            x,
            fs,
            self.n_peaks,
            self.min_spacing,
            self.f_min,
            self.cutoff,
            spectrum=self.spectrum,
        )
        return [periodic_trains(freqs, duration) for freqs in peaks]
