"""Feature extractors: pressure samples or spike trains → fixed-length vectors (thesis 2.3, 2.5).

- ``spectrum``: |FFT| of the pressure signal up to 600 Hz, downsampled to 50 (no encoder).
- ``sfft``: |FFT| of the binned spike train up to 1 kHz, downsampled to 50.
- ``isi``: histogram of inter-spike intervals, 50 bins.
- ``spll``: TDE rates of a 50-sPLL network (on a backend, the golden model by default).
"""

from .isi import isi_edges, isi_features
from .sfft import sfft_features
from .spectrum import N_FEATURES, downsample_spectrum, pressure_spectrum_features
from .spll import spll_features

#: Feature names, in report order. ``spectrum`` uses the pressure signal, the others spike trains.
FEATURES = ("spectrum", "sfft", "isi", "spll")
#: Features computed from spike trains (one result per encoder).
SPIKE_FEATURES = ("sfft", "isi", "spll")

__all__ = [
    "FEATURES",
    "N_FEATURES",
    "SPIKE_FEATURES",
    "downsample_spectrum",
    "isi_edges",
    "isi_features",
    "pressure_spectrum_features",
    "sfft_features",
    "spll_features",
]
