"""Pressure → spike-time encoders (thesis 2.2).

Every encoder has a ``name`` and ``encode(signals, fs, ids=None) -> list[np.ndarray]``: one row of
``signals`` (shape ``(n, L)``, sampled at ``fs`` Hz) per sample in, one sorted array of spike
times [s] per sample out. ``ids`` name the samples so that stochastic encoders seed their noise
per sample, independent of batching.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from .lif import LIFEncoder
from .pacinian import PacinianEncoder
from .peak_oscillator import PeakOscillatorEncoder


class Encoder(Protocol):
    name: str

    def encode(self, signals: np.ndarray, fs: float, ids=None) -> list[np.ndarray]: ...


#: Encoder classes by CLI name.
ENCODERS: dict[str, type] = {
    "lif": LIFEncoder,
    "pacinian": PacinianEncoder,
    "peak": PeakOscillatorEncoder,
}


def make_encoder(name: str, **params) -> Encoder:
    """Build the encoder called ``name`` (a key of :data:`ENCODERS`) with keyword ``params``."""
    if name not in ENCODERS:
        raise ValueError(f"unknown encoder {name!r}; choose from {sorted(ENCODERS)}")
    try:
        return ENCODERS[name](**params)
    except TypeError as exc:
        raise ValueError(f"bad parameters for encoder {name!r}: {exc}") from exc


__all__ = [
    "ENCODERS",
    "Encoder",
    "LIFEncoder",
    "PacinianEncoder",
    "PeakOscillatorEncoder",
    "make_encoder",
]
