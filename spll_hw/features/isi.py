"""Inter-spike-interval (ISI) histogram features (thesis 2.3).

All intervals between consecutive spikes are counted in 50 bins. Default edges: linear from
``ISI_MIN`` = 1 ms (the encoders' refractory periods: LIF 1 ms, TouchSim 1.2 ms) to ``ISI_MAX`` =
100 ms (an interval longer than that, i.e. a gap below 10 Hz, is rare in encoded trains), so each
bin is ~2 ms wide. ``spacing="geometric"`` spaces the same range logarithmically instead, giving
equal relative resolution to 10-1000 Hz rhythms (more accurate on BioTac, further from the thesis's
figures; docs/pipeline_results.md). Intervals below the first edge are counted in the first bin
and above the last edge in the last bin, so every interval counts.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .spectrum import N_FEATURES

#: Lower edge of the first ISI bin [s].
ISI_MIN = 1e-3
#: Upper edge of the last ISI bin [s].
ISI_MAX = 100e-3
_SPACINGS = ("linear", "geometric")


def isi_edges(
    n_bins: int = N_FEATURES,
    isi_min: float = ISI_MIN,
    isi_max: float = ISI_MAX,
    spacing: str = "linear",
) -> np.ndarray:
    """Bin edges [s], shape ``(n_bins + 1,)``, ``"linear"`` or ``"geometric"`` from min to max."""
    if not 0 < isi_min < isi_max:
        raise ValueError(f"need 0 < isi_min < isi_max, got {isi_min}, {isi_max}")
    if spacing not in _SPACINGS:
        raise ValueError(f"ISI bin spacing must be one of {_SPACINGS}, got {spacing!r}")
    if spacing == "linear":
        return np.linspace(isi_min, isi_max, n_bins + 1)
    return np.geomspace(isi_min, isi_max, n_bins + 1)


def isi_features(trains: Sequence[np.ndarray], edges: np.ndarray | None = None) -> np.ndarray:
    """ISI histogram counts, shape ``(n, len(edges) - 1)`` (module docstring for the bins)."""
    edges = isi_edges() if edges is None else np.asarray(edges, dtype=float)
    n_bins = edges.size - 1
    out = np.zeros((len(trains), n_bins))
    for row, train in enumerate(trains):
        isi = np.diff(np.asarray(train, dtype=float))
        idx = np.clip(np.searchsorted(edges, isi, side="right") - 1, 0, n_bins - 1)
        out[row] = np.bincount(idx, minlength=n_bins)
    return out
