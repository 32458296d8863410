"""sPLL-network features (thesis 2.5): the TDE firing rate of each of the network's sPLLs.

Every spike train drives the whole network on a backend (:mod:`spll_hw.backends`: the golden
model by default, or e.g. ``golden-fixed-point:profile=loihi2`` for a chip's own arithmetic);
the feature vector is the ``(N,)`` vector of TDE rates [Hz], or with ``parts`` > 1 the
``(parts · N,)`` rates in each of ``parts`` equal stretches of the run (issue 60: the rates of a
window's quarters decide early windows better than the window's rate;
docs/notes/2026-12-08-window-parts.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from .. import backends
from ..network import Network
from ..result import SimulationResult
from ..simulate import recordable_samples


def spll_features(
    trains: Sequence[np.ndarray],
    duration: float,
    network: Network,
    threads: int | None = None,
    chunk: int | None = None,
    on_chunk: Callable[[int], None] | None = None,
    backend: str | backends.Backend = "golden",
    parts: int = 1,
) -> np.ndarray:
    """TDE rates [Hz] of ``network`` for every spike train, shape ``(n, parts · network.n_spll)``.

    Trains are simulated ``chunk`` at a time (default: the backend's ``batch_size``) on
    ``backend`` (a spec or a configured backend)
    with ``threads`` threads (no backend-side noise: add phase noise to ``trains``
    beforehand); ``on_chunk(k)`` is called after each chunk of ``k`` samples (progress bars).
    With ``parts`` > 1 the columns are :func:`part_rates` (the spikes are recorded, so a chunk
    holds at most the samples whose recording fits in memory).
    """
    if isinstance(parts, bool) or not isinstance(parts, int) or parts < 1:
        raise ValueError(f"parts must be an integer >= 1, got {parts!r}")
    sim = backends.get(backend)
    chunk = chunk or sim.batch_size
    if parts > 1:
        chunk = min(chunk, recordable_samples(network.matrix(), duration))
    out = np.zeros((len(trains), parts * network.n_spll))
    for start in range(0, len(trains), chunk):
        batch = [np.ascontiguousarray(t, dtype=float) for t in trains[start : start + chunk]]
        if parts == 1:
            rates = sim.rates(network, batch, duration, threads=threads)
        else:
            runs = sim.simulate_batch(network, batch, duration, threads=threads,
                                      record_spikes=True)  # fmt: skip
            rates = part_rates(runs, parts)
        out[start : start + len(batch)] = rates
        if on_chunk is not None:
            on_chunk(len(batch))
    return out


def part_rates(runs: Sequence[SimulationResult], parts: int) -> np.ndarray:
    """Every sPLL's TDE rate [Hz] in each of ``parts`` equal stretches ``[k T/parts, (k+1)
    T/parts)`` of runs of length ``T`` with recorded spikes, shape ``(len(runs), parts ·
    n_spll)``, stretch-major (the first stretch's ``n_spll`` rates, then the next); the
    stretches' mean is the run's :attr:`~spll_hw.result.SimulationResult.tde_rates`."""
    duration = runs[0].duration
    edges = np.concatenate([[-np.inf], np.arange(1, parts) * (duration / parts), [np.inf]])
    counts = np.array(
        [[np.diff(np.searchsorted(s, edges)) for s in run.tde_spikes] for run in runs]
    )  # (runs, n_spll, parts)
    return counts.transpose(0, 2, 1).reshape(len(runs), -1) / (duration / parts)
