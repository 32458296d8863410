"""Every channel's features at every window, in one pool of worker processes.

A decision at ``T`` seconds sees only the first ``T`` s of each recording
(:mod:`.timecourse`), so every window is encoded and simulated on its own. One *unit* is a
channel, its group's network and encoder, its input level and a window; each unit's samples are
cut into a few chunks and every chunk is one task, which encodes and simulates it
(:func:`.features.channel_features` on those samples, one engine thread). All tasks of the run go
to one pool of ``jobs`` processes, longest windows first, so the cores stay busy across channels
and windows and only the rates [Hz] come back (never the spike trains).

Why windows are not prefixes of one run: the LIF encoder removes each window's own mean
(:meth:`spll_hw.encoders.lif.LIFEncoder.current`), so the first ``T`` s of the 4-s spike train
are not the spike train of the first ``T`` s, and the sPLLs see different inputs from the start.
Counting rates on prefixes of the 4-s simulation would change the results; it is not done.

A sample's features do not depend on which other samples share its task (the encoder works row by
row, the engine sample by sample), so the result is the same for every ``jobs`` and chunk size.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np
from tqdm.auto import tqdm

from ..datasets.multichannel import MultiChannelSet
from .config import ChannelGroup
from .features import channel_features

#: A unit's key in the results: ``(window [s], channel, group.key, input level)``.
Key = tuple[float, str, str, float]

#: The samples every worker reads (set once per worker process by :func:`_start_worker`).
_SAMPLES: MultiChannelSet | None = None


def _start_worker(samples: MultiChannelSet) -> None:
    global _SAMPLES
    _SAMPLES = samples


def _task(
    samples: MultiChannelSet | None,
    window: float,
    channel: str,
    group: ChannelGroup,
    level: float,
    rows: np.ndarray,
    backend: str,
    parts: int = 1,
) -> np.ndarray:
    """Features ``(rows.size, parts * group.network.n)`` of the samples ``rows`` of
    ``channel``, first ``window`` s (``samples`` ``None``: the worker's own copy), on the
    group's own backend where it has one, else on ``backend``."""
    part = (_SAMPLES if samples is None else samples).select([channel]).subset(rows).first(window)
    return channel_features(part, channel, group, level, group.backend or backend, jobs=1,
                            parts=parts)  # fmt: skip


def features_over_windows(
    samples: MultiChannelSet,
    units: Sequence[tuple[str, ChannelGroup, float]],
    windows: Sequence[float],
    backend: str = "golden",
    jobs: int = 1,
    progress: bool = False,
    chunk: int | None = None,
    parts: int = 1,
) -> dict[Key, np.ndarray]:
    """Features of every ``(channel, group, level)`` of ``units`` at every window (module
    docstring).

    Args:
        samples: every channel ``units`` names, at least ``max(windows)`` long.
        units: channel, the group whose network and encoder it gets, its input level [the
            channel's raw unit] (:func:`.features.input_levels`).
        windows: decision times [s]; each unit runs on the first ``window`` s of every sample.
        backend: simulator spec (:mod:`spll_hw.backends`) of every group without its own
            (:attr:`.config.ChannelGroup.backend`).
        jobs: worker processes (1: everything in this process).
        progress: a progress bar over samples × units.
        chunk: samples per task (default: a unit in ``2 * jobs`` tasks, or in one task when
            ``jobs`` is 1; the encoder's time steps cost about the same for 50 samples as for
            800, so few large tasks encode fastest, while two per process keep them busy).
        parts: the TDE rates in each of this many equal stretches of the window
            (:func:`spll_hw.features.spll.part_rates`; 1: over the whole window).

    Returns:
        ``(window, channel, group.key, level)`` → TDE rates [Hz], shape
        ``(len(samples), parts * group.network.n)``.
    """
    n = len(samples)
    chunk = chunk or (n if jobs == 1 else -(-n // (2 * jobs)))
    if chunk < 1:
        raise ValueError(f"chunk must be >= 1 sample, got {chunk}")
    for w in windows:  # a bad window fails here, not in a worker
        samples.subset([0]).first(w)
    blocks = [np.arange(a, min(a + chunk, n)) for a in range(0, n, chunk)]
    tasks = [
        ((w, channel, group.key, level), (w, channel, group, level, rows, backend, parts))
        for w in sorted(set(windows), reverse=True)  # the longest first: the pool ends level
        for channel, group, level in units
        for rows in blocks
    ]
    out = {key: np.zeros((n, parts * args[2].network.n)) for key, args in tasks}
    bar = tqdm(total=len(tasks) and n * len(out), desc="encoding + sPLLs", unit="sample",
               disable=not progress)  # fmt: skip
    with bar:
        if jobs == 1:
            for key, args in tasks:
                out[key][args[4]] = _task(samples, *args)
                bar.update(args[4].size)
            return out
        with ProcessPoolExecutor(jobs, initializer=_start_worker, initargs=(samples,)) as pool:
            futures = {pool.submit(_task, None, *args): (key, args[4]) for key, args in tasks}
            for future in as_completed(futures):
                key, rows = futures[future]
                out[key][rows] = future.result()
                bar.update(rows.size)
    return out
