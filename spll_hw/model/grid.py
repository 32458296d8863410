"""The time grid of every clocked target: which step an input spike arrives in, how many steps a
run has, how many steps a refractory period holds on the grid, how many steps a free-running
period takes.

A clocked target steps time by ``dt``. Step ``k = 1, 2, ..., K`` covers ``((k - 1) dt, k dt]``:
every state advances over it, then the spikes of step ``k`` are delivered, and a spike emitted in
step ``k`` is reported at ``k dt``. The rules, stated once here and used by every clocked target
(the fixed-point model, Lava, NIR, the standard construction, the USB board, Brian2's input):

* **arrival**: an input spike at ``t`` [s] arrives in step ``max(1, ceil(t / dt))``, the first
  step whose end is not before ``t``. A spike *on* a step's end (``t = k dt``) belongs to step
  ``k``, also when ``t / dt`` comes out a few ulps above ``k`` in floating point (``0.49e-3 /
  1e-5`` is ``49.00000000000001``): ``t / dt`` is read as ``k`` when it is within a relative
  :data:`GRID_RTOL` of it. A spike after the last step is not delivered.
* **run length**: a run of ``duration`` [s] has ``K = round(duration / dt)`` steps, halves
  rounded away from zero (a run shorter than half a step is an error).
* **refractory periods** on the grid: ``t_refr`` [s] holds a neuron for ``round(t_refr / dt)``
  whole steps, halves rounded away from zero (:func:`refractory_steps`). This is the *grid*
  hold of the clocked two-compartment models and Loihi; the standard constructions hold for
  ``round(t_refr / dt - 1/2)`` steps or a dithered mean of ``t_refr / dt - 1/2``, the rules of
  :mod:`.holds`, which says which target uses which.
* **free-running periods**: a clocked oscillator fires every whole number of steps; one asked to
  run at ``f`` [Hz] is given the period ``round(1 / (f dt))`` steps, halves up, and at least its
  hold plus one step (:func:`period_steps`; the fixed-point CCO's bias calibration,
  ``quantize/fixed_point.py``).

The Rust core applies the same arithmetic (``engine/src/fixed_point.rs``, ``input_steps``); the
conformance suite checks every clocked backend against :func:`spike_steps` on trains whose spikes
lie exactly on step ends (:func:`spll_hw.backends.conformance.check_input_grid`).

This module needs only numpy: exports that run without spll-hw (``spll-hw export --to
lava-standard``) carry a copy of it, so the target applies the same rule.
"""

from __future__ import annotations

import numpy as np

#: Relative tolerance within which ``t / dt`` counts as a whole number of steps. The quotient of
#: two doubles is off by a few ulps (about 1e-16 relative), so 1e-12 catches every spike written
#: on a step's end while moving no other spike by more than 1e-12 of its time.
GRID_RTOL = 1e-12


def round_half_up(x) -> np.ndarray:
    """``x >= 0`` rounded to the nearest whole number, halves up, as float64 of the shape of
    ``x`` (exact: ``x - floor(x)`` is exact in floating point, unlike ``floor(x + 0.5)``). Every
    "round" of the model (steps, decay constants) is this one."""
    x = np.asarray(x, dtype=np.float64)
    whole = np.floor(x)
    return whole + (x - whole >= 0.5)


def spike_steps(times, dt: float) -> np.ndarray:
    """Step in which each input spike arrives: ``max(1, ceil(t / dt))``, with ``t / dt`` within
    a relative :data:`GRID_RTOL` of a whole number read as that number.

    Args:
        times: spike times [s], any shape, each ``>= 0``.
        dt: time step [s], ``> 0``.

    Returns:
        int64 steps (1-based), the shape of ``times``.
    """
    x = np.asarray(times, dtype=np.float64) / dt
    return np.maximum(1, np.ceil(x - x * GRID_RTOL)).astype(np.int64)


def n_steps(duration: float, dt: float) -> int:
    """Steps ``K = round(duration / dt)`` of a run of ``duration`` [s] (halves away from zero).

    Raises:
        ValueError: when ``duration`` is shorter than half a step (no step at all).
    """
    steps = int(round_half_up(np.float64(duration) / dt))
    if steps < 1:
        raise ValueError(
            f"duration {duration!r} s is shorter than half a time step (dt = {dt!r} s): no step"
        )
    return steps


def refractory_steps(seconds, dt: float) -> np.ndarray:
    """Whole steps ``round(t_refr / dt)`` (halves away from zero) a refractory period of
    ``seconds`` [s] holds a neuron; int64, the shape of ``seconds``."""
    return round_half_up(np.asarray(seconds, dtype=np.float64) / dt).astype(np.int64)


def period_steps(frequency, dt: float, hold) -> np.ndarray:
    """Whole steps ``max(hold + 1, round(1 / (f dt)))`` (halves up) of the free-running period
    of a clocked oscillator asked to run at ``frequency`` [Hz] (> 0) at step ``dt`` [s], held
    ``hold`` steps after each spike; int64, the broadcast shape of ``frequency`` and ``hold``."""
    f = np.asarray(frequency, dtype=np.float64)
    steps = round_half_up(1.0 / (f * dt)).astype(np.int64)
    return np.maximum(np.asarray(hold, dtype=np.int64) + 1, steps)


def arrival_counts(times, steps: int, dt: float) -> np.ndarray:
    """Input spikes arriving in each step ``k = 1 .. steps``, shape ``(steps,)`` int64; spikes
    after the last step are dropped.

    Args:
        times: one train's spike times [s], 1-D (need not be sorted).
        steps: number of steps of the run (:func:`n_steps`).
        dt: time step [s].
    """
    k = spike_steps(np.asarray(times, dtype=np.float64).reshape(-1), dt)
    return np.bincount(k[k <= steps] - 1, minlength=steps).astype(np.int64)


def mid_step_times(times, dt: float) -> np.ndarray:
    """Times [s] moved to the middle of the step each arrives in, ``(k - 1/2) dt``: a train
    that every clocked target must treat exactly as ``times`` (same shape)."""
    return (spike_steps(times, dt) - 0.5) * dt
