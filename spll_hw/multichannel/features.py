"""Features of a multichannel network: every channel encoded and run through its own copy of
its group's sPLL network; the TDE rates [Hz] of every channel, concatenated in channel order.

Each channel is scaled as the single-channel pipeline scales its one channel
(:func:`spll_hw.pipeline.run_pipeline`): divided by its group's ``input_level`` or, without one,
by the median RMS of that channel's training samples (:func:`input_levels`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..datasets.multichannel import MultiChannelSet
from ..encoders import train_duration
from ..features.spll import spll_features
from ..pipeline import encode_samples
from .config import ChannelGroup, MultichannelConfig


def input_levels(config: MultichannelConfig, train: MultiChannelSet) -> dict[str, float]:
    """What every channel of ``config`` is divided by before encoding [its raw unit]: its
    group's ``input_level``, else the median RMS of ``train``'s samples of that channel."""
    return {
        channel: group.input_level or train.channel(channel).reference_level()
        for group in config.groups
        for channel in group.channels
    }


def channel_features(
    samples: MultiChannelSet,
    channel: str,
    group: ChannelGroup,
    level: float,
    backend: str = "golden",
    jobs: int = 1,
    progress: bool = False,
    parts: int = 1,
) -> np.ndarray:
    """TDE rates [Hz] of ``group``'s network driven by ``channel``'s samples divided by
    ``level`` and encoded by ``group``'s encoder, shape ``(n, parts * group.network.n)``
    (``parts`` > 1: the rates in each of that many equal stretches of the samples,
    :func:`spll_hw.features.spll.part_rates`)."""
    trains, window = channel_trains(samples, channel, group, level, jobs, progress)
    network = group.network.build()
    return spll_features(trains, window, network, threads=jobs, backend=backend, parts=parts)


def channel_trains(
    samples: MultiChannelSet,
    channel: str,
    group: ChannelGroup,
    level: float,
    jobs: int = 1,
    progress: bool = False,
) -> tuple[list[np.ndarray], float]:
    """The spike times [s] of ``channel``'s samples divided by ``level`` and encoded by
    ``group``'s encoder (one array per sample), and their length [s]."""
    signals = samples.channel(channel).normalized(level, "the channel's input level")
    encoder = group.make_encoder()
    trains = encode_samples(encoder, signals, jobs, progress)
    return trains, train_duration(encoder, signals.duration)


class FeatureCache:
    """Channel features computed once per channel, network, encoder and level, so networks that
    share a channel's setup (a multichannel network and the single-channel pipeline on ``pac``)
    share its simulation. ``compute(channel, group, level)`` is :func:`channel_features` on
    the samples the cache was made for."""

    def __init__(self, compute: Callable[[str, ChannelGroup, float], np.ndarray]) -> None:
        self._compute = compute
        self._done: dict[tuple[str, str, float], np.ndarray] = {}

    def features(self, config: MultichannelConfig, levels: dict[str, float]) -> np.ndarray:
        """Every channel's features of ``config``, concatenated in channel order, shape ``(n,
        config.n_spll)`` (times the parts per window where ``compute`` splits windows)."""
        parts = []
        for group in config.groups:
            for channel in group.channels:
                key = (channel, group.key, levels[channel])
                if key not in self._done:
                    self._done[key] = self._compute(channel, group, levels[channel])
                parts.append(self._done[key])
        return np.concatenate(parts, axis=1)
