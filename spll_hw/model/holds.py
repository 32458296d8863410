"""The refractory hold of a clocked neuron: how many whole steps a refractory period holds it.

A clocked neuron fires at the end of the step in which its membrane crosses the threshold (the
time grid of :mod:`.grid`), on average half a step after the exact crossing. How long it is
then held is the target's choice among these rules, stated once here (``hold`` names them):

* **grid** (:func:`.grid.refractory_steps`): ``round(t_refr / dt)`` steps, halves up. The
  clocked two-compartment models use it (the fixed-point model ``engine/src/fixed_point.rs``
  via ``quantize/fixed_point.py``, Lava's sPLL processes ``mappings/lava``, the USB board),
  as Loihi does. Its restart is on average ``dt / 2`` later than the exact model's, every
  cycle: a neuron firing every few steps runs slow by that much.
* **compensated** (:func:`compensated_hold`): ``round(t_refr / dt - 1/2)`` steps, halves up,
  at least 0: the grid hold less the mean half step, rounded. The NIR standard construction
  (``mappings/nir/standard.py``) holds its timers this long.
* **dithered** (:func:`fractional_hold` + :class:`DitheredHold`): the mean-correct
  ``t_refr / dt - 1/2`` steps, as ``floor`` or ``floor + 1`` chosen by error diffusion over a
  neuron's spikes: what a neuron with an accumulator could do; the standard construction's
  reference (``hold="dithered"``) uses it.
* **counter-dithered** (:func:`counter_dither`): the nearest mean a counter that resets to 0
  can make, one spike in ``n <= 16`` held a step longer or shorter: the Lava standard
  construction (``mappings/lava/integers.py``) holds its refractory units this way.

:data:`HOLDS` maps the names to the mean hold [steps] of each. Which rule each target uses and
what each costs in rate error is measured in ``docs/backends.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .grid import refractory_steps, round_half_up


def fractional_hold(t_refr, dt: float) -> np.ndarray:
    """The mean-correct hold ``t_refr / dt - 1/2`` steps (at least 0, float64, the shape of
    ``t_refr`` [s]) of a neuron that fires at the end of its crossing's step ``dt`` [s]."""
    return np.maximum(np.asarray(t_refr, dtype=np.float64) / dt - 0.5, 0.0)


def compensated_hold(t_refr, dt: float) -> np.ndarray:
    """Whole steps ``round(t_refr / dt - 1/2)`` (halves up, at least 0) that hold a clocked
    neuron of refractory period ``t_refr`` [s] (any shape) at step ``dt`` [s], int64.

    A clocked neuron fires at the end of the step in which its membrane crosses the threshold,
    on average half a step after the crossing; held ``round(t_refr / dt)`` steps from there, it
    starts integrating again on average ``dt / 2`` later than the exact model, every cycle. A
    neuron that fires every few steps (the TDEs' bursts of the time-scaled presets, refractory
    periods of 75 µs to 1 ms) runs slow by that much: 26-29 % TDE-rate error at 100 µs on
    ``biotac-time-scaled-pacinian`` and ``biotac-tuned-time-scaled-lif``, 16-18 % with this
    hold (docs/backends.md). The restart is then late by ``round(h) - h`` steps on average,
    ``h = t_refr / dt - 1/2``: at most half a step, 0 where ``h`` is whole.
    """
    return round_half_up(fractional_hold(t_refr, dt)).astype(np.int64)


#: Longest period of a :class:`CounterDither` [spikes]: one step in 16 spikes is the finest
#: adjustment of the mean hold (a Loihi counter's 8-bit weights, :func:`counter_dither`).
MAX_DITHER_PERIOD = 16
#: Fewest base steps a counter can lengthen (+1) and shorten (-1): its count reaches the
#: refractory unit in the third held step (``mappings/lava/integers.py``).
DITHER_MIN_STEPS = {1: 3, -1: 4}


class CounterDither(NamedTuple):
    """Whole-step refractory holds that a counter dithers (:func:`counter_dither`), per neuron
    (the shape of ``t_refr``): every ``period``-th spike of a neuron (counting its spikes from
    the start, the count reset each time it reaches ``period``) is held ``base + step``
    steps, the others ``base``; ``step`` is ``-1``, ``0`` or ``+1`` (``period`` 0 where it is
    0). The mean hold is ``base + step / period``."""

    base: np.ndarray
    step: np.ndarray
    period: np.ndarray

    @property
    def mean(self) -> np.ndarray:
        """The mean hold [steps] over a neuron's spikes, float64."""
        return self.base + np.divide(
            self.step, self.period, out=np.zeros(self.base.shape), where=self.period > 0
        )


def counter_dither(t_refr, dt: float) -> CounterDither:
    """The :class:`CounterDither` whose mean hold is nearest ``h = t_refr / dt - 1/2`` steps
    (:func:`fractional_hold`, the mean-correct hold of a neuron that fires at the end of its
    crossing's step) of a refractory period ``t_refr`` [s] (any shape) at step ``dt`` [s].

    The candidates are ``floor(h)`` and ``floor(h) + 1`` held always, ``floor(h) + 1/n``
    (lengthen one spike in ``n``) and ``floor(h) + 1 - 1/n`` (shorten one in ``n``) for ``n =
    2 ..`` :data:`MAX_DITHER_PERIOD`, those that :data:`DITHER_MIN_STEPS` allow; a tie keeps
    the undithered hold, halves up as :func:`compensated_hold`. A counter that resets to 0 (a
    Loihi neuron) makes these, not error diffusion's ``floor(h)`` or ``floor(h) + 1`` chosen
    from a running remainder (:class:`DitheredHold`); on the export
    check's inputs the two were within half a point of each other in 28 of 35 preset x dt cells
    (docs/backends.md).
    """
    h = fractional_hold(t_refr, dt)
    low = np.floor(h).astype(np.int64)
    n = np.arange(2, MAX_DITHER_PERIOD + 1)
    # Candidates along the last axis: (base offset from floor(h), step, period).
    offset = np.r_[1, 0, np.zeros(n.size, np.int64), np.ones(n.size, np.int64)]
    step = np.r_[0, 0, np.ones(n.size, np.int64), -np.ones(n.size, np.int64)]
    period = np.r_[0, 0, n, n]
    base = low[..., None] + offset
    mean = CounterDither(base, *np.broadcast_arrays(step, period, base)[:2]).mean
    allowed = (step == 0) | (base >= np.where(step > 0, DITHER_MIN_STEPS[1], DITHER_MIN_STEPS[-1]))
    distance = np.where(allowed, np.abs(mean - h[..., None]), np.inf)
    # np.argmin takes the first of equals: the undithered candidates come first.
    best = np.argmin(distance + 1e-12 * (step != 0), axis=-1)
    return CounterDither(
        np.take_along_axis(base, best[..., None], -1)[..., 0], step[best], period[best]
    )


#: Mean refractory holds [steps] of a period ``t_refr`` [s] at step ``dt`` [s], by name; a
#: fractional one is dithered over a neuron's spikes (:class:`DitheredHold`); the module
#: docstring says which target uses which.
HOLDS = {"grid": refractory_steps, "compensated": compensated_hold, "dithered": fractional_hold}


class DitheredHold:
    """Whole-step holds whose mean over a neuron's spikes is ``mean`` [steps] (shape ``(N,)``):
    error diffusion, ``floor(mean)`` steps plus one whenever the neuron's accumulator of the
    fractional parts reaches 1 (it then drops by 1). A whole ``mean`` is held as it is.

    Args:
        mean: the mean hold per sPLL [steps], shape ``(N,)``.
        shape: ``(rows, N)``, the batch's neurons; each keeps its own accumulator.
    """

    def __init__(self, mean: np.ndarray, shape: tuple[int, int]):
        self.base = np.floor(mean).astype(np.int64)
        self.fraction = np.asarray(mean, dtype=np.float64) - self.base
        self.dithered = bool(self.fraction.any())
        self.accumulator = np.zeros(shape)

    def after(self, spiked: np.ndarray) -> np.ndarray:
        """The holds [whole steps] of the neurons after this step's spikes ``spiked`` (bool,
        ``(rows, N)``), advancing the spiking neurons' accumulators."""
        if not self.dithered:
            return self.base
        self.accumulator += spiked * self.fraction
        carry = self.accumulator >= 1.0 - 1e-9  # ten additions of 0.1 make 0.999...
        self.accumulator -= carry
        return self.base + carry
