"""sPLL-network features (thesis 2.5): the TDE firing rate of each of the network's sPLLs.

Every spike train drives the whole network (golden engine, :func:`spll_hw.simulate_batch`, which
runs samples in parallel); the feature vector is the ``(N,)`` vector of TDE rates [Hz].

:data:`THESIS_NETWORKS` holds the thesis's tuned networks (Tables 6 and 7): base sPLL parameters
and the free-running frequency range / log offset for every dataset × layout × encoder;
:func:`thesis_network` builds one as a :class:`~spll_hw.network.Network`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..network import DEFAULT_N_SPLL, Network
from ..params import SpllParams

_TABLE6_COLUMNS = (
    "tau_cco_syn", "tau_cco", "tau_tde_trg", "tau_tde_fac", "tau_tde",
    "g_cco", "g_tde_trg", "g_tde_fac",
)  # fmt: skip

_INF = math.inf
# "<dataset>-<layout>-<encoder>": Table 6 row (_TABLE6_COLUMNS order), then Table 7's
# f_start [Hz], f_end [Hz] and log offset beta (inf: linear spacing).
_THESIS_TABLES: dict[str, tuple[float, ...]] = {
    "vibtac-time-scaled-lif":
        (1.38e-2, 6.53e-2, 5.70e-4, 1.46e-2, 2.29e-2, 8.92, 0.466, 7.5e3, 48.1, 523.0, 10.0),
    "vibtac-time-scaled-pacinian":
        (3.23e-2, 0.287, 8.61e-4, 1.89e-2, 4.73e-2, 2.61, 2.68, 1.32e3, 68.1, 493.0, 10.0),
    "vibtac-time-scaled-peak":
        (1.41e-2, 0.11, 5.57e-4, 7.19e-4, 2.47e-3, 5.77, 2.6, 4.45e3, 70.5, 329.0, 100.0),
    "biotac-time-scaled-lif":
        (5.39e-2, 6.36e-2, 1.15e-3, 1.99e-2, 2.09e-2, 9.83, 0.348, 3.45e3, 32.2, 692.0, 1.0),
    "biotac-time-scaled-pacinian":
        (0.178, 0.463, 2.36e-3, 7.47e-3, 2.89e-3, 7.28, 0.227, 3.78e4, 44.0, 668.0, 10.0),
    "biotac-time-scaled-peak":
        (5.48e-3, 0.483, 1.48e-2, 3.76e-3, 6.60e-2, 0.108, 0.201, 1.98e3, 85.7, 497.0, 1.0),
    "vibtac-vary-offset-lif":
        (7.50e-3, 0.314, 1.25e-3, 9.59e-3, 4.52e-3, 9.84, 0.271, 6.15e2, 56.2, 668.0, 1.0),
    "vibtac-vary-offset-pacinian":
        (1.37e-2, 0.159, 1.20e-3, 1.06e-2, 5.07e-2, 8.04, 3.57, 1.83e3, 96.2, 486.0, _INF),
    "vibtac-vary-offset-peak":
        (7.69e-3, 6.01e-2, 1.59e-2, 9.41e-4, 9.99e-2, 0.117, 0.568, 1.72e4, 79.3, 685.0, _INF),
    "biotac-vary-offset-lif":
        (4.70e-2, 7.68e-2, 9.66e-4, 1.25e-2, 7.31e-3, 3.96, 2.42, 1.23e3, 61.6, 669.0, 1.0),
    "biotac-vary-offset-pacinian":
        (6.49e-2, 8.10e-2, 6.68e-4, 1.49e-2, 2.37e-3, 6.1, 2.39, 1.43e4, 54.6, 692.0, 10.0),
    "biotac-vary-offset-peak":
        (7.09e-3, 5.63e-2, 1.57e-3, 5.32e-4, 3.63e-2, 0.1, 1.7, 4.3e3, 95.9, 442.0, 10.0),
}  # fmt: skip

#: Preset names ``"<dataset>-<layout>-<encoder>"`` (e.g. ``"biotac-vary-offset-lif"``) →
#: ``(base SpllParams, (f_start, f_end, beta))`` from the thesis's Tables 6 and 7.
THESIS_NETWORKS: dict[str, tuple[SpllParams, tuple[float, float, float]]] = {
    name: (SpllParams(**dict(zip(_TABLE6_COLUMNS, row[:8], strict=True))), tuple(row[8:]))
    for name, row in _THESIS_TABLES.items()
}


def thesis_network(preset: str, n: int = DEFAULT_N_SPLL) -> Network:
    """The thesis's tuned network ``preset`` (a key of :data:`THESIS_NETWORKS`) with ``n`` sPLLs."""
    from ..config import NetworkConfig

    return NetworkConfig.preset(preset).with_n(n).build()


def spll_features(
    trains: Sequence[np.ndarray],
    duration: float,
    network: Network,
    threads: int | None = None,
    chunk: int = 64,
    on_chunk: Callable[[int], None] | None = None,
) -> np.ndarray:
    """TDE rates [Hz] of ``network`` for every spike train, shape ``(n, network.n_spll)``.

    Trains are simulated ``chunk`` at a time by the golden engine with ``threads`` threads (no
    engine-side noise: add phase noise to ``trains`` beforehand); ``on_chunk(k)`` is called after
    each chunk of ``k`` samples (progress bars).
    """
    import spll_hw

    out = np.zeros((len(trains), network.n_spll))
    for start in range(0, len(trains), chunk):
        batch = [np.ascontiguousarray(t, dtype=float) for t in trains[start : start + chunk]]
        results = spll_hw.simulate_batch(network, batch, duration, threads=threads)
        out[start : start + len(batch)] = [r.tde_rates for r in results]
        if on_chunk is not None:
            on_chunk(len(batch))
    return out
