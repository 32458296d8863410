"""The inputs of an export's check (:mod:`.check`): the network's own reference trains, a
user's trains, and the kinds ``check.json`` sorts them by.

:func:`reference_inputs` makes a Poisson and a periodic train at the network's lowest, middle
and highest free-running frequency, :data:`DURATION` = 1 s each; :func:`user_input` takes a
user's train; the encoded inputs of a network that carries an encoder are :mod:`.encoded`'s.
Every one is a :class:`CheckInput`, which ``check.json`` lists (:meth:`CheckInput.describe`)
and ``check_inputs.npz`` stores.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..network import Network
from ..simulate import poisson_spikes

#: Length [s] of every reference input.
DURATION = 1.0
#: Input rate [Hz] of the reference inputs of a network whose CCOs do not oscillate.
FALLBACK_RATE = 300.0
#: Kinds of the reference inputs (:func:`reference_inputs`), made again by every check.
REFERENCE_KINDS = ("poisson", "periodic")
#: Kinds of the inputs of the network's own kind of signal (:mod:`.encoded`): a recording's
#: window and a synthetic signal, each encoded by the network's encoder.
ENCODED_KINDS = ("encoded-recording", "synthetic-encoded")


@dataclass(frozen=True)
class CheckInput:
    """One input of the check.

    Attributes:
        label: what it is (``"poisson 56.2 Hz"``, or the file it came from).
        spikes: sorted input spike times [s], shape ``(n,)``.
        duration: run length [s].
        kind: ``"poisson"``, ``"periodic"`` (:data:`REFERENCE_KINDS`), ``"file"`` (the
            user's), ``"encoded-recording"`` or ``"synthetic-encoded"`` (:data:`ENCODED_KINDS`).
        rate: its rate [Hz] (NaN but for the reference trains).
        source: where an encoded input comes from (:mod:`.encoded`: the recording's file, its
            CSV line and window [s], or the synthetic signal's generator, seed and class, and
            the encoder), ``check.json``'s ``source``; empty for the others.
    """

    label: str
    spikes: np.ndarray
    duration: float
    kind: str
    rate: float = math.nan
    source: dict = field(default_factory=dict)

    def describe(self) -> dict:
        """The input as ``check.json`` lists it."""
        out = {"label": self.label, "kind": self.kind, "duration_s": self.duration,
               "n_spikes": int(self.spikes.size)}  # fmt: skip
        if not math.isnan(self.rate):
            out["rate_hz"] = self.rate
        if self.source:
            out["source"] = self.source
        return out


def reference_inputs(network: Network, duration: float = DURATION) -> list[CheckInput]:
    """A Poisson (seeds 0, 1, 2) and a periodic train (first spike half a period in) at the
    network's lowest, middle (that of its middle sPLL by frequency) and highest free-running
    frequency, ``duration`` [s] each; a frequency shared by two of them is used once, and
    :data:`FALLBACK_RATE` where no sPLL oscillates."""
    f = np.sort(network.free_frequencies())
    f = f[np.isfinite(f) & (f > 0)]
    f = f if f.size else np.array([FALLBACK_RATE])
    rates = dict.fromkeys(float(x) for x in (f[0], f[len(f) // 2], f[-1]))
    inputs = []
    for seed, rate in enumerate(rates):
        poisson = poisson_spikes(rate, duration, seed)
        inputs.append(CheckInput(f"poisson {rate:.1f} Hz", poisson, duration, "poisson", rate))
        periodic = np.arange(0.5 / rate, duration, 1.0 / rate)
        inputs.append(CheckInput(f"periodic {rate:.1f} Hz", periodic, duration, "periodic", rate))
    return inputs


def shifted(spikes: np.ndarray, shift: float, duration: float) -> np.ndarray:
    """``spikes`` (sorted times [s], shape ``(n,)``) ``shift`` [s] later, those past
    ``duration`` [s] dropped; ``shift`` >= 0."""
    out = np.asarray(spikes, dtype=float) + shift
    return out[out <= duration]


def user_input(label: str, spikes: np.ndarray, duration: float = DURATION) -> CheckInput:
    """A user's train as a check input, run for ``duration`` [s] or up to its last spike if
    that is later; ``ValueError`` naming ``label`` when the times are not sorted, finite and
    >= 0."""
    x = np.asarray(spikes, dtype=float).reshape(-1)
    if not np.all(np.isfinite(x)) or np.any(x < 0):
        raise ValueError(f"{label}: spike times must be finite and >= 0 s")
    if np.any(np.diff(x) < 0):
        raise ValueError(f"{label}: spike times must be sorted")
    last = float(x[-1]) if x.size else 0.0
    return CheckInput(label, x, max(duration, last), "file")
