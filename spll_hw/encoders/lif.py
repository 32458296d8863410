"""LIF encoder: the pressure signal is the input current of one leaky integrate-and-fire neuron.

Thesis 2.2 ("Leaky integrate and fire"): no pre-processing, the (mean-free) pressure signal drives
the neuron directly, so negative pressure silences it (the "gaps" of thesis 3.2).

Model (normalised, capacitance 1, threshold 1, reset 0)::

    dV/dt = -V / tau + I(t),    I(t) = gain * x(t) / scale + bias

where ``x`` is the (mean-free) pressure signal held constant over each sample interval
(zero-order hold) and ``scale`` is 1 (``normalize="none"``, the default: ``gain`` is current per
signal unit) or the sample's own RMS (``normalize="rms"``). ``I`` is in 1/s. The defaults are
tuned for signals in units of their dataset's median sample RMS
(:meth:`~spll_hw.datasets.SampleSet.normalized`), which keeps amplitude differences between
samples: on BioTac (11 classes) ``tau`` = 2 ms and ``gain`` = 5000/s give ~250 spikes/s and
sFFT/ISI accuracies close to the thesis's Table 1 (docs/pipeline_results.md). After a spike
``V`` is held at 0 for ``t_ref`` seconds.

Within a sample interval the ODE is linear with constant input, so the membrane potential and
threshold crossing times are computed in closed form: spike times are exact, not quantised to
the sampling grid, and several spikes per interval are possible when ``t_ref`` is short. The
recursion over intervals is vectorized over a batch of equal-length signals.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

_NORMALIZE = ("rms", "none")


def lif_spike_times(current: np.ndarray, fs: float, tau: float, t_ref: float) -> list[np.ndarray]:
    """Exact spike times [s] of a LIF neuron driven by a piecewise-constant current.

    Args:
        current: input current [1/s], shape ``(n, L)``; row ``j`` drives neuron ``j`` and
            ``current[j, k]`` holds on ``[k / fs, (k + 1) / fs)``.
        fs: sampling rate of ``current`` [Hz].
        tau: membrane time constant [s].
        t_ref: refractory period [s] (``V`` held at 0 after each spike).

    Returns:
        ``n`` sorted arrays of spike times in ``[0, L / fs)``.
    """
    drive = np.ascontiguousarray(np.atleast_2d(np.asarray(current, dtype=float)).T)  # (L, n)
    n_steps, n = drive.shape
    dt = 1.0 / fs
    v = np.zeros(n)
    refr_end = np.zeros(n)  # time at which each neuron leaves its refractory period
    decay = np.exp(-dt / tau)
    out_neuron: list[np.ndarray] = []
    out_time: list[np.ndarray] = []
    for k in range(n_steps):
        t0 = k * dt
        t1 = t0 + dt
        target = drive[k] * tau  # V relaxes towards I * tau
        refractory = refr_end > t0
        if not refractory.any():
            v_end = target + (v - target) * decay
            crossing = v_end >= 1.0
            if not crossing.any():
                v = v_end
                continue
        # Slow path: some neuron spikes or leaves its refractory period inside this interval.
        start = np.maximum(t0, refr_end)
        v = np.where(refractory, 0.0, v)
        pending = np.flatnonzero(start < t1)
        v_next = np.zeros(n)
        while pending.size:
            tp, vp, ip = start[pending], v[pending], target[pending]
            with np.errstate(divide="ignore", invalid="ignore"):
                to_spike = tau * np.log((ip - vp) / (ip - 1.0))
            fires = (ip > 1.0) & (vp < 1.0) & (tp + to_spike < t1)
            quiet = pending[~fires]
            # a neuron that started the interval at t0 decays exactly as on the fast path
            elapsed_decay = np.where(tp == t0, decay, np.exp(-(t1 - tp) / tau))
            v_next[quiet] = ip[~fires] + (vp[~fires] - ip[~fires]) * elapsed_decay[~fires]
            fired = pending[fires]
            t_spike = tp[fires] + to_spike[fires]
            out_neuron.append(fired)
            out_time.append(t_spike)
            refr_end[fired] = t_spike + t_ref
            start[fired] = refr_end[fired]
            v[fired] = 0.0
            pending = fired[start[fired] < t1]
        v = v_next
    if not out_time:
        return [np.zeros(0) for _ in range(n)]
    neuron = np.concatenate(out_neuron)
    times = np.concatenate(out_time)
    order = np.lexsort((times, neuron))
    neuron, times = neuron[order], times[order]
    return np.split(times, np.searchsorted(neuron, np.arange(1, n)))


@dataclass(frozen=True)
class LIFEncoder:
    """Pressure → spikes by one LIF neuron per sample (module docstring for the model).

    Attributes:
        tau: membrane time constant [s].
        t_ref: refractory period [s].
        gain: input current per unit of normalised pressure [1/s].
        bias: constant input current [1/s] (0: the neuron is silent without pressure).
        normalize: ``"rms"`` divides each sample by its RMS, ``"none"`` uses it as is.
        center: remove each sample's mean first (the thesis; the mean is the whole sample's, so
            an early spike depends on later pressure); ``False`` uses the signal as given (a
            causal pipeline removes its own baseline, :mod:`spll_hw.multichannel.readout`).
    """

    tau: float = 2e-3
    t_ref: float = 1e-3
    gain: float = 5000.0
    bias: float = 0.0
    normalize: str = "none"
    center: bool = True

    name = "lif"

    def __post_init__(self) -> None:
        if not self.tau > 0:
            raise ValueError(f"LIF tau must be > 0 s, got {self.tau!r}")
        if not self.t_ref >= 0:
            raise ValueError(f"LIF t_ref must be >= 0 s, got {self.t_ref!r}")
        if not np.isfinite(self.gain) or not np.isfinite(self.bias):
            raise ValueError("LIF gain and bias must be finite")
        if self.normalize not in _NORMALIZE:
            raise ValueError(f"LIF normalize must be one of {_NORMALIZE}, got {self.normalize!r}")

    def current(self, signals: np.ndarray) -> np.ndarray:
        """Input current [1/s] for ``signals`` of shape ``(n, L)``."""
        x = np.atleast_2d(np.asarray(signals, dtype=float))
        if self.center:
            x = x - x.mean(axis=-1, keepdims=True)
        if self.normalize == "rms":
            rms = np.sqrt(np.mean(x**2, axis=-1, keepdims=True))
            x = np.divide(x, rms, out=np.zeros_like(x), where=rms > 0)
        return self.gain * x + self.bias

    def encode(
        self, signals: np.ndarray, fs: float, ids: Sequence[int] | None = None
    ) -> list[np.ndarray]:
        """Spike times [s] for each row of ``signals`` ``(n, L)`` sampled at ``fs`` [Hz].

        ``ids`` is accepted for interface symmetry with the stochastic encoders and unused:
        this encoder is deterministic.
        """
        del ids
        return lif_spike_times(self.current(signals), fs, self.tau, self.t_ref)
