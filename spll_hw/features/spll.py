"""sPLL-network features (thesis 2.5): the TDE firing rate of each of the network's sPLLs.

Every spike train drives the whole network on a backend (:mod:`spll_hw.backends`: the golden
model by default, or e.g. ``golden-fixed-point:profile=loihi2`` for a chip's own arithmetic);
the feature vector is the ``(N,)`` vector of TDE rates [Hz].
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from .. import backends
from ..network import Network


def spll_features(
    trains: Sequence[np.ndarray],
    duration: float,
    network: Network,
    threads: int | None = None,
    chunk: int | None = None,
    on_chunk: Callable[[int], None] | None = None,
    backend: str | backends.Backend = "golden",
) -> np.ndarray:
    """TDE rates [Hz] of ``network`` for every spike train, shape ``(n, network.n_spll)``.

    Trains are simulated ``chunk`` at a time (default: the backend's ``batch_size``) on
    ``backend`` (a spec or a configured backend)
    with ``threads`` threads (no backend-side noise: add phase noise to ``trains``
    beforehand); ``on_chunk(k)`` is called after each chunk of ``k`` samples (progress bars).
    """
    sim = backends.get(backend)
    chunk = chunk or sim.batch_size
    out = np.zeros((len(trains), network.n_spll))
    for start in range(0, len(trains), chunk):
        batch = [np.ascontiguousarray(t, dtype=float) for t in trains[start : start + chunk]]
        out[start : start + len(batch)] = sim.rates(network, batch, duration, threads=threads)
        if on_chunk is not None:
            on_chunk(len(batch))
    return out
