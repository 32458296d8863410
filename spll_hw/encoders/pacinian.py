"""Pacinian (PC) afferent encoder: the TouchSim transduction model.

Saal, Delhaye et al., "Simulating tactile signals from the whole hand with millisecond
precision", PNAS 2017 (TouchSim). The PC afferent's transduction stage, applied to a skin
displacement trace ``x(t)`` [mm] sampled at 5 kHz:

1. velocity ``v`` [mm/s] by central differences, ``(x[i+1] - x[i-1]) / 2 * fs``, ends copied;
2. ``v`` low-pass filtered by a causal 3rd-order Butterworth filter with cutoff ``10 * p[0]`` Hz
   (TouchSim filters the position term only for SA1 afferents; for PC its weights are 0 anyway);
3. input current, rectified and weighted: ``I = w(x; p1, p2) + w(v; p3, p4) + w(a; p5, p6)`` with
   ``w(s; wp, wn) = wp * s`` for ``s >= 0`` and ``-wn * s`` otherwise, where the "acceleration"
   ``a[i] = v[i+1] - v[i]`` is a per-sample difference of the filtered velocity (``a`` = 0 at the
   last sample);
4. optional Gaussian noise ``p[8] * N(0, 1)`` per sample;
5. saturation ``I <- p[7] * I / (p[7] + |I|)``;
6. a discrete-time LIF neuron (one step per sample, membrane time constant ``p[9]`` samples,
   threshold 1, reset to 0) with a post-spike current ``p[10] * b0 + p[11] * b1`` over the
   190 samples after each spike (two raised-cosine basis functions in log time,
   :func:`post_spike_basis`); a spike needs ``V > 1`` and at least 6 samples since the previous
   one. A spike at sample ``i`` is reported at ``(i + 1) / fs``.

Everything but the LIF recursion is vectorized over time; the recursion runs once over time and is
vectorized over a batch of signals, so encoding many equal-length samples at once is cheap.
Conduction delay (``p[12]``) is not modelled (TouchSim's default).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
from scipy import signal

#: TouchSim's fixed sampling rate [Hz].
PC_FS = 5000.0

#: The four published PC afferent models (Saal, Delhaye et al. 2017; TouchSim ``affparamsPC``),
#: one row per model. Columns: 0 filter cutoff / 10 Hz; 1, 2 position weights (+, -);
#: 3, 4 velocity weights (+, -); 5, 6 acceleration weights (+, -); 7 saturation; 8 noise sd;
#: 9 membrane time constant [samples]; 10, 11 post-spike current weights; 12 delay [ms].
PC_PARAMETERS = np.array(
    [
        [27.50213623046875, 0.0, 0.0, -257.79678911169367, -185.6558443855175,
         1455.1497846354166, 592.888733969869, 10.196911334991455, 0.0499999925494194,
         8.9628642201423645, -11.321471893787383, -0.58635234832763672, 6.2203119344329831],
        [36.996826171875, 0.0, 0.0, -35.398131107042232, -22.653872497720371,
         157.5796183803252, 174.77248278118313, 4.882041722536087, 0.0499999925494194,
         4.5575849264860153, -4.5480041742324815, -0.9200621098279953, 3.5259496516799924],
        [34.4921875, 0.0, 0.0, -10.02273802522215, 0.42768528444781173,
         18.534118547148648, 27.073339950470697, 7.5830078125, 0.041318236291408537,
         6.6578885763883591, -6.2153930902481065, -0.4205046147108078, 6.7759496516799924],
        [30.25, 0.0, 0.0, -16.097870690375565, -49.807295116767989, 110.51101718984899,
         277.7479292097546, 5.665244847536087, 0.0499999925494194, 4.7331220358610153,
         -6.1505432367324815, -0.2100401371717453, 3.6196996516799924],
    ]
)  # fmt: skip
PC_PARAMETERS.setflags(write=False)

#: Samples after a spike during which no new spike can occur (absolute refractory period).
_REFRACTORY_SAMPLES = 5
#: Post-spike basis: log-time offset [samples], peak positions [samples], length [samples].
_BASIS_OFFSET = 5.0
_BASIS_PEAKS = (0.0, 40.0)
_BASIS_LENGTH = 190


def post_spike_basis() -> np.ndarray:
    """TouchSim's post-spike current basis, shape ``(2, 190)``, one row per basis function.

    Raised cosines ``(1 + cos(theta)) / 2`` in log time, ``theta = clip(k * (ln(n + 5) -
    ln(c + 5)), -pi, pi)`` for sample ``n`` after the spike, centres ``c`` = 0 and 40 samples and
    ``k = 3 pi / (2 ln 9)`` (``ln 9`` is the log distance between the centres), the log-time
    raised-cosine basis of Pillow et al.'s GLM post-spike filters.
    """
    n = np.arange(_BASIS_LENGTH, dtype=float)
    log_t = np.log(n + _BASIS_OFFSET)
    centres = np.log(np.asarray(_BASIS_PEAKS) + _BASIS_OFFSET)
    width = (centres[1] - centres[0]) / 3.0
    theta = np.clip((log_t[None, :] - centres[:, None]) * np.pi / (2.0 * width), -np.pi, np.pi)
    return (1.0 + np.cos(theta)) / 2.0


def central_velocity(x: np.ndarray, fs: float) -> np.ndarray:
    """Velocity of ``x`` along its last axis by central differences, ends copied.

    ``v[i] = (x[i+1] - x[i-1]) / 2 * fs``, ``v[0] = v[1]``, ``v[-1] = v[-2]``. Units: those of
    ``x`` per second. Needs at least 3 samples.
    """
    x = np.asarray(x, dtype=float)
    if x.shape[-1] < 3:
        raise ValueError(f"need at least 3 samples to take a central difference, got {x.shape[-1]}")
    v = np.empty_like(x)
    v[..., 1:-1] = (x[..., 2:] - x[..., :-2]) / 2.0 * fs
    v[..., 0] = v[..., 1]
    v[..., -1] = v[..., -2]
    return v


def _rectified(s: np.ndarray, w_pos: float, w_neg: float) -> np.ndarray:
    return np.where(s >= 0, w_pos * s, -w_neg * s)


def pc_input_current(x: np.ndarray, velocity: np.ndarray, params: np.ndarray) -> np.ndarray:
    """Input current of the PC model before noise and saturation, same shape as ``x``.

    ``x`` [mm] and ``velocity`` [mm/s] are sampled at :data:`PC_FS` along the last axis.
    """
    p = np.asarray(params, dtype=float)
    b, a = signal.butter(3, p[0] * 4.0 / 1000.0)  # cutoff 10 * p[0] Hz at fs = 5 kHz
    v = signal.lfilter(b, a, velocity, axis=-1)
    acc = np.zeros_like(v)
    acc[..., :-1] = v[..., 1:] - v[..., :-1]
    current = _rectified(x, p[1], p[2])
    current = current + _rectified(v, p[3], p[4])
    return current + _rectified(acc, p[5], p[6])


def pc_spike_indices(
    current: np.ndarray, params: np.ndarray, noise: np.ndarray | None = None
) -> list[np.ndarray]:
    """Noise, saturation and LIF stage: sample indices of the spikes of each row of ``current``.

    Args:
        current: input currents, shape ``(n, L)`` (one row per signal, 5 kHz samples).
        params: one row of :data:`PC_PARAMETERS`.
        noise: standard-normal noise of shape ``(n, L)`` scaled by ``params[8]``, or ``None``.

    Returns:
        ``n`` int arrays of spike sample indices, ascending.
    """
    p = np.asarray(params, dtype=float)
    current = np.atleast_2d(np.asarray(current, dtype=float))
    if noise is not None:
        current = current + p[8] * noise
    if p[7] > 0:
        current = p[7] * current / (p[7] + np.abs(current))
        current[np.isnan(current)] = 0.0
    basis = post_spike_basis()
    post = np.append(p[10] * basis[0] + p[11] * basis[1], 0.0)
    n_post = post.size - 1
    tau = p[9]
    drive = np.ascontiguousarray(current.T)  # (L, n): one contiguous row per time step
    n_steps, n = drive.shape
    v = np.zeros(n)
    since = np.full(n, n_post)  # samples since the last spike, saturating at n_post
    spikes = np.zeros((n_steps, n), dtype=bool)
    for i in range(n_steps):
        v = v + ((-v / tau + drive[i]) + post[since])
        since = since + (since < n_post)
        fired = (v > 1.0) & (since > _REFRACTORY_SAMPLES)
        if fired.any():
            v[fired] = 0.0
            since[fired] = 0
            spikes[i] = fired
    rows, cols = np.nonzero(spikes.T)
    return np.split(cols, np.searchsorted(rows, np.arange(1, n)))


def pc_spike_times(
    x_mm: np.ndarray,
    params: np.ndarray,
    noise: np.ndarray | None = None,
    velocity: np.ndarray | None = None,
) -> list[np.ndarray]:
    """Spike times [s] of the PC model for displacement traces ``x_mm`` [mm] at 5 kHz.

    ``x_mm`` has shape ``(n, L)`` or ``(L,)``; ``velocity`` [mm/s] defaults to
    :func:`central_velocity`. Returns ``n`` sorted float arrays, spike ``i`` at ``(i + 1) / fs``.
    """
    x = np.atleast_2d(np.asarray(x_mm, dtype=float))
    v = central_velocity(x, PC_FS) if velocity is None else np.atleast_2d(velocity)
    indices = pc_spike_indices(pc_input_current(x, v, params), params, noise)
    return [(idx + 1) / PC_FS for idx in indices]


def resample_to(signals: np.ndarray, fs: float, fs_new: float) -> np.ndarray:
    """Polyphase resampling of ``signals`` (last axis) from ``fs`` to ``fs_new`` [Hz]."""
    ratio = Fraction(fs_new / fs).limit_denominator(1000)
    if ratio == 1:
        return np.asarray(signals, dtype=float)
    return signal.resample_poly(signals, ratio.numerator, ratio.denominator, axis=-1)


@dataclass(frozen=True)
class PacinianEncoder:
    """Pressure → spikes through the TouchSim PC afferent (module docstring).

    The pressure signal, resampled to 5 kHz, is taken as skin displacement: each sample is
    scaled to ``rms_um`` micrometres RMS (``rms_um=None``: multiplied by ``gain_mm`` instead, so
    amplitude differences between samples are kept). ``model`` picks one of the four published
    parameter sets; ``noisy`` adds TouchSim's membrane noise, seeded per sample by
    ``(seed, sample id)`` so results do not depend on batching (the pipeline's ids name the
    sample's recording window, :attr:`~spll_hw.datasets.samples.SampleSet.noise_ids`).
    """

    model: int = 0
    rms_um: float | None = 20.0
    gain_mm: float = 1e-3
    noisy: bool = True
    seed: int = 0

    name = "pacinian"

    def __post_init__(self) -> None:
        if self.model not in range(len(PC_PARAMETERS)):
            raise ValueError(f"PC model must be 0..{len(PC_PARAMETERS) - 1}, got {self.model}")
        if self.rms_um is not None and not self.rms_um > 0:
            raise ValueError(f"rms_um must be > 0 (micrometres), got {self.rms_um!r}")
        if not self.gain_mm > 0:
            raise ValueError(f"gain_mm must be > 0 (mm per signal unit), got {self.gain_mm!r}")

    def displacement(self, signals: np.ndarray, fs: float) -> np.ndarray:
        """Skin displacement [mm] at 5 kHz for ``signals`` of shape ``(n, L)`` sampled at ``fs``."""
        x = resample_to(np.atleast_2d(signals), fs, PC_FS)
        x = x - x.mean(axis=-1, keepdims=True)
        if self.rms_um is None:
            return x * self.gain_mm
        rms = np.sqrt(np.mean(x**2, axis=-1, keepdims=True))
        return np.divide(x * (self.rms_um * 1e-3), rms, out=np.zeros_like(x), where=rms > 0)

    def encode(
        self, signals: np.ndarray, fs: float, ids: Sequence[int] | None = None
    ) -> list[np.ndarray]:
        """Spike times [s] for each row of ``signals`` ``(n, L)`` sampled at ``fs`` [Hz].

        ``ids`` (default ``0..n-1``) name the samples for the per-sample noise seed.
        """
        x = self.displacement(signals, fs)
        noise = None
        if self.noisy:
            ids = range(len(x)) if ids is None else ids
            noise = np.stack(
                [
                    np.random.default_rng([self.seed, int(i)]).standard_normal(x.shape[1])
                    for i in ids
                ]
            )
        return pc_spike_times(x, PC_PARAMETERS[self.model], noise)
