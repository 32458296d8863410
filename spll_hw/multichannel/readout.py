"""A spiking readout that decides while the finger slides: the ridge classifier as one
integrate-and-fire neuron per class, driven by the network's TDE spikes.

The standardised ridge classifier on TDE rates [Hz] over ``[0, t]`` scores class ``j`` as
``s_j(t) = sum_i a_ji (N_i(t) / t - mu_i) / sigma_i + b_j`` (``N_i(t)``: spikes of TDE ``i``
so far; ``a``, ``b``: the ridge's coefficients and intercepts; ``mu``, ``sigma``: the scaler's
means and scales). Multiplied by ``t``,

    v_j(t) = t s_j(t) = sum_i w_ji N_i(t) + beta_j t,
    w_ji = a_ji / sigma_i,   beta_j = b_j - sum_i a_ji mu_i / sigma_i,

is the membrane of a non-leaky integrate-and-fire neuron that gains ``w_ji`` per spike of TDE
``i`` and integrates a constant current ``beta_j`` [1/s]: the ridge's scores at every instant,
so at a fixed time the largest membrane is the ridge's decision. **Winner-take-all**: the first
readout neuron whose membrane reaches the threshold ``theta`` [score x s] fires, its class is
the decision and its spike time the time to decision; a higher threshold decides later and
more surely (:func:`decide`); where none fires within the run, the largest membrane decides at
its end (a fixed latency). Between TDE spikes each membrane is linear in time, so crossing
times are exact, not stepped. :func:`decide` is the Python reference; the golden engine makes
the same decisions, exactly and faster (:mod:`.decisions`), for :func:`.anytime.scored_decisions`.

:class:`Readout` holds ``w`` and ``beta`` in float or, :meth:`Readout.quantized`, as ``bits``-bit
signed integers of one scale per array (a chip's dense layer and bias), so the cost of the
integers is measured against the float ridge.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from ..datasets.multichannel import MultiChannelSet
from ..pipeline import encode_samples
from ..result import SimulationResult
from ..simulate import simulate_batch
from .config import ChannelGroup, MultichannelConfig

#: Seconds into a recording before which the readout does not decide (it is switched on then).
START = 0.1
#: Percentile of the magnitudes that sets an integer array's scale (:func:`_rounded`).
CLIP_PERCENTILE = 99.0
#: What :func:`_causal_runs` keeps of a run.
T = TypeVar("T")
#: Samples simulated at once with their spike times kept (the engine's memory check).
CHUNK = 16
#: Prefix times [s] a readout trained for early decisions learns from (:func:`.anytime.training`).
PREFIXES = (0.25, 0.5, 1.0, 2.0, 4.0)
#: Times [s] a :class:`StagedReadout` switches from one stage to the next, chosen with its
#: ridge penalty (:data:`.anytime.STAGE_ALPHA`) on training recordings 25-32 held out from 1-24
#: (recordings 33-40 unseen; benchmarks/multichannel_readout.py ``choose``,
#: docs/notes/2026-12-06-readout.md): with alpha 100 and these edges the readout decided
#: 76.9 % at a mean 0.64 s and 95.0 % at 4 s, the prefix readout 54.4 % at 0.52 s and 85.0 % at
#: 4 s.
STAGE_EDGES = (0.5, 1.0, 2.0, 3.0)


@dataclass(frozen=True)
class Readout:
    """One readout neuron per class.

    Attributes:
        weights: membrane gain per TDE spike, shape ``(k, d)`` (class, TDE) [score x s].
        bias: constant current, shape ``(k,)`` [score].
        class_names: the ``k`` classes.
        bits: integer width of ``weights`` and ``bias`` (``None``: float).
    """

    weights: np.ndarray
    bias: np.ndarray
    class_names: tuple[str, ...]
    bits: int | None = None

    @classmethod
    def from_ridge(
        cls,
        rates: np.ndarray,
        labels: np.ndarray,
        class_names: Sequence[str],
        alpha: float = 1.0,
        offset: float = 0.0,
    ) -> Readout:
        """Fit the standardised ridge classifier (:func:`spll_hw.classify.holdout`'s) on TDE
        ``rates`` [Hz] ``(n, d)`` with ``labels`` ``(n,)`` in ``0..k-1`` (``k >= 3``), and fold
        the scaler into the readout's weights and bias.

        ``offset`` [score] is added to every class's score (to every ``beta_j``): each
        membrane gains ``offset x t``, the same as a threshold that falls by ``offset`` per
        second, and the largest membrane at any fixed time is unchanged. The ridge's targets
        are +-1, so with many classes every score starts below 0 and a readout trained for
        early decisions needs it to fire early (:data:`.anytime.PREFIX_OFFSET`)."""
        from sklearn.linear_model import RidgeClassifier
        from sklearn.preprocessing import StandardScaler

        k = len(class_names)
        if k < 3 or np.unique(labels).size != k:
            raise ValueError(
                f"a readout needs >= 3 classes, each with training samples; got {k} classes, "
                f"{np.unique(labels).size} present"
            )
        scaler = StandardScaler().fit(rates)
        ridge = RidgeClassifier(alpha=alpha).fit(scaler.transform(rates), labels)
        weights = ridge.coef_ / scaler.scale_
        bias = ridge.intercept_ - weights @ scaler.mean_ + offset
        return cls(weights, bias, tuple(class_names))

    def quantized(
        self,
        bits: int,
        groups: np.ndarray | None = None,
        rates: np.ndarray | None = None,
        per_class: bool = False,
    ) -> Readout:
        """The readout with ``bits``-bit signed integer weights and bias.

        Weights: one power-of-two scale (a chip's weight exponent) per group of TDE inputs
        (``groups``: a group id per TDE, shape ``(d,)``, e.g. its channel, one dense layer each;
        ``None``: one group), set by the group's 99th-percentile magnitude (:func:`_rounded`);
        with ``per_class``, one scale per group and class (each readout neuron's synapses from
        a channel get their own exponent: a class whose weights are all small keeps its
        resolution instead of rounding to the largest class's steps).
        With the training ``rates`` [Hz] ``(n, d)``, the bias first absorbs the rounding's mean
        effect on the training scores, ``beta + mean_n((w - w_q) x_n)`` (each weight's error is
        multiplied by counts in the thousands: uncorrected, 8 bits lose most of the accuracy);
        then it is rounded on its own scale."""
        if not 2 <= bits <= 32:
            raise ValueError(f"readout bits must be in 2..32, got {bits}")
        groups = np.zeros(self.weights.shape[1], int) if groups is None else np.asarray(groups)
        if groups.shape != (self.weights.shape[1],):
            raise ValueError(f"groups must give one id per TDE ({self.weights.shape[1]})")
        weights = np.zeros_like(self.weights)
        rows = [slice(None)] if not per_class else range(self.weights.shape[0])
        for g in np.unique(groups):
            mine = groups == g
            for row in rows:
                weights[row, mine] = _rounded(self.weights[row, mine], bits, power_of_two=True)
        bias = self.bias
        if rates is not None:
            bias = bias + np.mean(np.asarray(rates) @ (self.weights - weights).T, axis=0)
        return Readout(weights, _rounded(bias, bits), self.class_names, bits)

    def scores(self, rates: np.ndarray) -> np.ndarray:
        """``s_j`` of TDE ``rates`` [Hz] ``(n, d)`` over a window: shape ``(n, k)``."""
        return rates @ self.weights.T + self.bias

    def membrane_path(self, spikes: Sequence[np.ndarray], duration: float) -> _Path:
        """Every readout membrane along one run: ``spikes[i]`` the spike times [s] of TDE ``i``
        (``d`` arrays), ``duration`` [s] the run's end."""
        d = self.weights.shape[1]
        if len(spikes) != d:
            raise ValueError(f"{len(spikes)} TDE spike trains, the readout takes {d}")
        times = np.concatenate([np.asarray(s, float) for s in spikes] + [np.zeros(0)])
        source = np.repeat(np.arange(len(spikes)), [len(s) for s in spikes])
        order = np.argsort(times, kind="stable")
        times, source = times[order], source[order]
        inside = times <= duration
        times, source = times[inside], source[inside]
        jumps = self.weights[:, source].T  # (events, k)
        after = np.cumsum(jumps, axis=0) + times[:, None] * self.bias  # just after each spike
        before = after - jumps  # just before it
        # points in time order: t = 0, then (before, after) of every spike, then the end
        n = times.size
        values = np.empty((2 * n + 2, self.bias.size))
        values[0] = 0.0
        values[1:-1:2], values[2:-1:2] = before, after
        values[-1] = (after[-1] if n else 0.0) + self.bias * (duration - (times[-1] if n else 0.0))
        at = np.r_[0.0, np.repeat(times, 2), duration]
        rise = np.r_[False, np.tile([True, False], n), True]  # reached along a linear stretch
        return _Path(values, at, rise, self.bias)


@dataclass(frozen=True)
class StagedReadout:
    """Readouts that take turns: stage ``i`` (a :class:`Readout`, ``k`` neurons of its own) is
    switched on at ``starts[i]`` and off at ``starts[i + 1]`` (the last stays on to the run's
    end); the first neuron of the stage on at the time to reach the threshold decides, and where
    none does the last stage's largest membrane decides at the end (:func:`decide_staged`).

    Why (issue 60): one set of weights cannot score every prefix of a run well. The ridge's best
    weights on the rates over the first 0.5 s and over the first 4 s differ (trained on
    recordings 1-24 and scored on 25-32: one readout trained on prefixes of 0.25-4 s decides
    85.0 % at 4 s, the ridge trained on the 4-s rates alone 95.0 %; standardising each prefix
    by its own means and scales does not close it), so each stage is trained on the prefixes
    of its own stretch (:func:`stages`). Every stage integrates from the start (its membrane at
    ``t`` is ``t`` times its ridge's score on the rates so far), so a stage switched on late
    decides on all the evidence.
    """

    stages: tuple[Readout, ...]
    starts: tuple[float, ...]

    def __post_init__(self) -> None:
        if not self.stages or len(self.starts) != len(self.stages):
            raise ValueError(f"{len(self.stages)} stages need as many start times")
        if any(b <= a for a, b in zip(self.starts, self.starts[1:], strict=False)):
            raise ValueError(f"stage start times must increase, got {list(self.starts)}")
        shapes = {r.weights.shape for r in self.stages}
        if len(shapes) != 1 or len({r.class_names for r in self.stages}) != 1:
            raise ValueError("every stage must read the same TDEs into the same classes")

    @property
    def class_names(self) -> tuple[str, ...]:
        return self.stages[0].class_names

    @property
    def bits(self) -> int | None:
        return self.stages[0].bits

    @property
    def weights(self) -> np.ndarray:
        """Every stage's weights, shape ``(stages, k, d)``."""
        return np.stack([r.weights for r in self.stages])

    def ends(self, duration: float) -> tuple[float, ...]:
        """When each stage is switched off [s] in a run of ``duration`` s."""
        return (*self.starts[1:], float(duration))


def stages(duration: float, edges: Sequence[float] = ()) -> tuple[tuple[float, tuple], ...]:
    """``(start [s], prefix times [s])`` of every stage of a :class:`StagedReadout` over a run
    of ``duration`` s with stages switched at ``edges`` (default :data:`STAGE_EDGES`, those
    inside the run): the first stage is on from :data:`START` and trains on the rates at 0.25 s
    and at its end, each middle stage on the rates at its start and end, and the last on the
    whole run's rates alone, so the decision at the end is the ridge of the whole run."""
    edges = tuple(e for e in (edges or STAGE_EDGES) if START < e < duration)
    bounds = (START, *edges, float(duration))
    out = []
    for i, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
        if i == len(bounds) - 2:
            out.append((lo, (float(duration),)))
        else:
            out.append((lo, (max(lo, PREFIXES[0]), hi) if hi > PREFIXES[0] else (hi,)))
    return tuple(out)


@dataclass(frozen=True)
class _Path:
    """One run's readout membranes at the points where they can peak: ``values`` ``(p, k)`` at
    times ``at`` ``(p,)``; ``rise[q]``: point ``q`` is reached from point ``q - 1`` along a
    straight stretch of slope ``bias`` (else by a spike's jump, at the same instant)."""

    values: np.ndarray
    at: np.ndarray
    rise: np.ndarray
    bias: np.ndarray

    @functools.cached_property
    def peak(self) -> np.ndarray:
        """The running maximum of ``values`` along the run, shape ``(p, k)``."""
        return np.maximum.accumulate(self.values, axis=0)

    def at_time(self, t: float) -> np.ndarray:
        """Every membrane at ``t`` [s] (after the jumps of spikes at ``t``): shape ``(k,)``."""
        q = int(np.searchsorted(self.at, t, side="right")) - 1
        return self.values[q] + self.bias * (t - self.at[q])

    def first_crossings(self, threshold: float) -> np.ndarray:
        """Time [s] each membrane first reaches ``threshold``, ``inf`` where it never does:
        shape ``(k,)``."""
        peak = self.peak
        out = np.full(self.values.shape[1], np.inf)
        for j in range(out.size):
            q = int(np.searchsorted(peak[:, j], threshold, side="left"))
            if q >= peak.shape[0]:
                continue
            if q == 0 or not self.rise[q]:
                out[j] = self.at[q]
            else:  # on the straight stretch from point q - 1
                out[j] = self.at[q - 1] + (threshold - self.values[q - 1, j]) / self.bias[j]
        return out


@dataclass(frozen=True)
class Decision:
    """One run's decision: ``label`` (class index), ``time`` [s] into the run, and whether a
    readout neuron fired (``False``: no membrane reached the threshold; the largest at the end
    decided)."""

    label: int
    time: float
    fired: bool


def decide(path: _Path, threshold: float, not_before: float = 0.0) -> Decision:
    """Winner-take-all at ``threshold`` [score x s] (module docstring): the first readout neuron
    to reach it decides, no earlier than ``not_before`` [s] (the readout is switched on then: a
    membrane already above decides at that instant, the largest first); ``inf`` decides at the
    run's end by the largest membrane, the ridge's decision on the whole run's rates."""
    if not threshold > 0:
        raise ValueError(f"readout threshold must be > 0 (score x s), got {threshold!r}")
    end = float(path.at[-1])
    if np.isfinite(threshold):
        crossed = np.maximum(path.first_crossings(threshold), not_before)
        first = float(crossed.min())
        if first <= end:
            tied = np.flatnonzero(crossed == first)
            return Decision(int(tied[np.argmax(path.at_time(first)[tied])]), first, True)
    return Decision(int(np.argmax(path.values[-1])), end, False)


def decide_staged(
    staged: StagedReadout,
    spikes: Sequence[np.ndarray],
    duration: float,
    threshold: float,
    not_before: float = 0.0,
) -> Decision:
    """:class:`StagedReadout`'s decision on one run (``spikes[i]``: TDE ``i``'s spike times
    [s]): stage by stage, :func:`decide` on the run up to the stage's end, switched on at its
    start (or ``not_before``, if later); the first stage whose neuron fires while it is on
    decides; none: the last stage's largest membrane at ``duration``. The Python reference of
    :func:`.decisions.engine_decisions`."""
    ends = staged.ends(duration)
    for i, (readout, start, end) in enumerate(zip(staged.stages, staged.starts, ends,
                                                  strict=True)):  # fmt: skip
        made = decide(readout.membrane_path(spikes, end), threshold, max(start, not_before))
        if made.fired or i == len(staged.stages) - 1:
            return made
    raise AssertionError("unreachable")


def _rounded(values: np.ndarray, bits: int, power_of_two: bool = False) -> np.ndarray:
    """``values`` as ``bits``-bit signed integers times one scale: the 99th percentile of the
    magnitudes maps to the largest integer (rounded up to a power of two with
    ``power_of_two``) and the few larger values saturate (the ridge's weights span decades: a
    scale set by the largest leaves most weights a few steps); zeros stay zeros."""
    magnitude = np.abs(values)
    top = float(np.percentile(magnitude, CLIP_PERCENTILE))
    if top == 0.0:
        return np.zeros_like(values)
    largest = 2 ** (bits - 1) - 1
    step = top / largest
    if power_of_two:
        step = 2.0 ** np.ceil(np.log2(step))
    return np.clip(np.round(values / step), -largest, largest) * step


def tde_spikes(
    samples: MultiChannelSet,
    config: MultichannelConfig,
    levels: dict[str, float],
    jobs: int = 1,
    progress: bool = False,
) -> list[list[np.ndarray]]:
    """TDE spike times [s] of every sPLL of ``config`` (channel order, as its features) for
    every sample, from the golden engine, encoded causally (:func:`_causal_runs`):
    ``out[sample][tde]``."""
    runs = _causal_runs(samples, config, levels, lambda run: run.tde_spikes, True, jobs, progress)
    return [[t for spikes in row for t in spikes] for row in runs]


def causal_counts(
    samples: MultiChannelSet,
    config: MultichannelConfig,
    levels: dict[str, float],
    times: Sequence[float],
    jobs: int = 1,
    progress: bool = False,
) -> np.ndarray:
    """TDE spike counts ``N_i(t)`` (spikes at or before ``t``) at each of ``times`` [s] along
    the same causal runs as :func:`tde_spikes`, shape ``(len(samples), len(times),
    config.n_spll)``. Only the run's end: the engine's counts, no spike times recorded;
    otherwise each chunk's spike times become counts as soon as it has run, so no more than
    :data:`CHUNK` samples' spikes are held. ``ValueError`` for a time outside
    ``(0, duration]``."""
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or not np.all((times > 0) & (times <= samples.duration)):
        raise ValueError(
            f"prefix times must lie in (0, {samples.duration:g}] s, got {times.tolist()}"
        )

    def counted(run: SimulationResult) -> np.ndarray:
        return np.array([np.searchsorted(s, times, side="right") for s in run.tde_spikes])

    if np.array_equal(times, [samples.duration]):
        runs = _causal_runs(samples, config, levels, lambda run: run.tde_counts[:, None],
                            False, jobs, progress)  # fmt: skip
    else:
        runs = _causal_runs(samples, config, levels, counted, True, jobs, progress)
    out = np.array([np.concatenate(row) for row in runs], dtype=np.int64)  # (n, d, times)
    return out.reshape(len(samples), config.n_spll, times.size).transpose(0, 2, 1)


def _causal_runs(
    samples: MultiChannelSet,
    config: MultichannelConfig,
    levels: dict[str, float],
    keep: Callable[[SimulationResult], T],
    record_spikes: bool,
    jobs: int,
    progress: bool,
    center: Callable[[np.ndarray, float], np.ndarray] | None = None,
) -> list[list[T]]:
    """What ``keep`` takes of every channel's golden run of every sample, ``out[sample]
    [channel]``, encoded causally (``center(signals, rate [Hz])``: another causal centering
    than :func:`causal_centered`, for studies).

    Each channel is scaled by ``levels`` (:func:`.features.input_levels`) and, at every row,
    its mean so far is subtracted (:func:`causal_centered`) instead of the whole sample's,
    which the LIF encoder removes for features and which a decision before the end cannot
    know; its LIF encoder then runs with ``center=False``. Only LIF-encoded channels qualify
    (``ValueError`` naming the channels). With ``record_spikes``, samples run
    :data:`CHUNK` at a time (the engine's memory check) and each run is reduced by ``keep``
    before the next chunk."""
    out: list[list[T]] = [[] for _ in range(len(samples))]
    for group in config.groups:
        network = group.network.build()
        for channel in group.channels:
            trains = causal_trains(samples, group, channel, levels[channel], jobs, progress,
                                   center)  # fmt: skip
            chunk = CHUNK if record_spikes else max(1, len(trains))
            for first in range(0, len(trains), chunk):
                runs = simulate_batch(network, trains[first : first + chunk], samples.duration,
                                      record_spikes=record_spikes, threads=jobs)  # fmt: skip
                for row, run in zip(out[first : first + chunk], runs, strict=True):
                    row.append(keep(run))
    return out


def causal_trains(
    samples: MultiChannelSet,
    group: ChannelGroup,
    channel: str,
    level: float,
    jobs: int = 1,
    progress: bool = False,
    center: Callable[[np.ndarray, float], np.ndarray] | None = None,
) -> list[np.ndarray]:
    """The input spike times [s] of ``channel`` (of ``group``) in every sample, as the readout
    sees them (:func:`_causal_runs`): divided by ``level`` [the channel's raw unit], its mean so
    far subtracted at every row (or ``center(signals, rate [Hz])``), encoded by the group's LIF
    encoder with ``center=False``. ``ValueError`` naming the channels where the group's encoder
    is not causal."""
    encoder = group.make_encoder()
    if not hasattr(encoder, "center"):
        raise ValueError(
            f"channels {', '.join(group.channels)}: the spiking readout needs a causal "
            f"encoder; {encoder.name!r} looks at the whole sample (use the LIF encoder)"
        )
    encoder = dataclasses.replace(encoder, center=False)
    signals = samples.channel(channel).normalized(level, "its input level")
    x = signals.signals
    x = causal_centered(x) if center is None else center(x, x.shape[-1] / signals.duration)
    return encode_samples(encoder, dataclasses.replace(signals, signals=x), jobs, progress)


def causal_centered(signals: np.ndarray) -> np.ndarray:
    """``signals`` ``(n, L)`` minus, at every row ``l``, the mean of rows ``0..l`` (a mean that
    uses no later sample)."""
    x = np.asarray(signals, dtype=float)
    return x - np.cumsum(x, axis=-1) / np.arange(1, x.shape[-1] + 1)
