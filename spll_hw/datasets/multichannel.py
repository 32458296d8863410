"""Samples of several channels of one sensor: one :class:`SampleSet` per channel, each at its
own sampling rate, all cut from the same recordings at the same times (same labels, sources,
sample length).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from .samples import SampleSet

_SPAN = re.compile(r" \[([-+0-9.e]+)-[-+0-9.e]+ s\]$")


@dataclass(frozen=True)
class MultiChannelSet:
    """Labelled samples of several channels (module docstring).

    Attributes:
        channels: channel name → its samples, in channel order; every set has the same
            ``labels``, ``class_names``, ``sources`` and sample duration [s], and its own
            ``fs`` [Hz] and signal length ``round(duration * fs)``.
    """

    channels: Mapping[str, SampleSet]

    def __post_init__(self) -> None:
        channels = dict(self.channels)
        if not channels:
            raise ValueError("a multichannel sample set needs at least one channel")
        name, first = next(iter(channels.items()))
        for other, samples in channels.items():
            if (samples.class_names, samples.sources) != (first.class_names, first.sources) or (
                not np.array_equal(samples.labels, first.labels)
            ):
                raise ValueError(
                    f"channel {other!r}: its samples are not those of channel {name!r} "
                    "(classes, labels and sources must agree sample by sample)"
                )
            if not np.isclose(samples.duration, first.duration):
                raise ValueError(
                    f"channel {other!r}: samples last {samples.duration:g} s, those of channel "
                    f"{name!r} {first.duration:g} s"
                )
        object.__setattr__(self, "channels", channels)

    def __len__(self) -> int:
        return len(self.first_set)

    @property
    def first_set(self) -> SampleSet:
        """The samples of the first channel (labels, sources and duration are every channel's)."""
        return next(iter(self.channels.values()))

    @property
    def names(self) -> tuple[str, ...]:
        """Channel names, in order."""
        return tuple(self.channels)

    @property
    def labels(self) -> np.ndarray:
        """Class index of every sample, shape ``(n,)``."""
        return self.first_set.labels

    @property
    def class_names(self) -> tuple[str, ...]:
        return self.first_set.class_names

    @property
    def n_classes(self) -> int:
        return self.first_set.n_classes

    @property
    def recordings(self) -> np.ndarray:
        """The recording of every sample, shape ``(n,)`` (:attr:`SampleSet.recordings`)."""
        return self.first_set.recordings

    @property
    def numbers(self) -> np.ndarray | None:
        """The recording number of every sample, shape ``(n,)`` (:attr:`SampleSet.numbers`)."""
        return self.first_set.numbers

    @property
    def name(self) -> str:
        """The first channel's set name (e.g. ``biotac-pac``)."""
        return self.first_set.name

    @property
    def duration(self) -> float:
        """Length of every sample [s]."""
        return self.first_set.duration

    def channel(self, name: str) -> SampleSet:
        """The samples of channel ``name``; ``ValueError`` naming the channels there are."""
        if name not in self.channels:
            raise ValueError(f"no channel {name!r} loaded; loaded: {', '.join(self.names)}")
        return self.channels[name]

    def select(self, names: Sequence[str]) -> MultiChannelSet:
        """The channels ``names`` only, in that order."""
        return MultiChannelSet({name: self.channel(name) for name in names})

    def subset(self, indices: Sequence[int] | np.ndarray) -> MultiChannelSet:
        """The samples at ``indices``, every channel (:meth:`SampleSet.subset`)."""
        return MultiChannelSet({n: s.subset(indices) for n, s in self.channels.items()})

    def openings(self) -> MultiChannelSet:
        """The first sample of every recording (the one whose span starts at 0 s), so every
        recording counts once; ``ValueError`` when none does."""
        starts = [
            m is not None and float(m.group(1)) == 0
            for m in map(_SPAN.search, self.first_set.sources)
        ]
        if not any(starts):
            raise ValueError("no sample starts a recording (sources lack a [0-... s] span)")
        return self.subset(np.flatnonzero(starts))

    def split_by(self, held_out: np.ndarray) -> tuple[MultiChannelSet, MultiChannelSet]:
        """``(the others, the held-out samples)`` for a boolean mask ``(n,)``
        (:meth:`SampleSet.split_by`, channel by channel)."""
        pairs = {name: s.split_by(held_out) for name, s in self.channels.items()}
        return (MultiChannelSet({n: p[0] for n, p in pairs.items()}),
                MultiChannelSet({n: p[1] for n, p in pairs.items()}))  # fmt: skip

    def first(self, seconds: float) -> MultiChannelSet:
        """The first ``seconds`` of every sample, every channel (sources say the new span).

        ``ValueError`` when ``seconds`` is not in ``(0, duration]`` or leaves a channel fewer
        than 2 values per sample.
        """
        if not 0 < seconds <= self.duration + 1e-9:
            raise ValueError(
                f"a window of {seconds!r} s is not within the {self.duration:g} s samples"
            )
        out = {}
        for name, samples in self.channels.items():
            length = int(round(seconds * samples.fs))
            if length < 2:
                raise ValueError(
                    f"channel {name!r}: {seconds:g} s at {samples.fs:g} Hz is fewer than 2 values"
                )
            sources = tuple(_SPAN.sub(_span(seconds), s) for s in samples.sources)
            out[name] = replace(samples, signals=samples.signals[:, :length], sources=sources)
        return MultiChannelSet(out)


def _span(seconds: float):
    """A ``re.sub`` replacement that rewrites ``" [a-b s]"`` as ``" [a-(a+seconds) s]"``."""

    def rewrite(match: re.Match) -> str:
        start = float(match.group(1))
        return f" [{start:g}-{start + seconds:g} s]"

    return rewrite
