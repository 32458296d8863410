"""Which parameters a fixed time step cannot resolve, before anything runs.

The golden engine places every event at its exact time; Brian2 moves every event onto the grid
of its time step ``dt`` (an input or a threshold crossing acts at the end of the step it falls
in) and counts refractory periods in whole steps. That is accurate to O(dt) as long as every
time scale of the network spans many steps. :func:`dt_warnings` lists where it does not, so a
result computed anyway says so instead of being silently wrong.
"""

from __future__ import annotations

import math

import numpy as np

from spll_hw.params import PARAM_NAMES

#: A time constant or refractory period shorter than this many steps is flagged.
MIN_STEPS = 10
#: Time constants of one neuron closer than this (relative) make Brian2's exact update unreliable.
DEGENERATE_GAP = 1e-6
#: Above this ``dt / tau`` Brian2's exact update overflows (it evaluates ``exp(dt / tau)``).
EXP_OVERFLOW = 700.0

_TIME_CONSTANTS = ("tau_cco_syn", "tau_cco", "tau_tde_fac", "tau_tde_trg", "tau_tde")
_REFRACTORY = ("t_cco_refr", "t_tde_refr")
#: (membrane, synapse) pairs whose difference Brian2's exact solution divides by.
_PAIRS = (("tau_cco", "tau_cco_syn"), ("tau_tde", "tau_tde_trg"))


class DtResolutionWarning(UserWarning):
    """A parameter of the network is not resolved by the simulation's time step."""


def steps(t: float | np.ndarray, dt: float) -> np.ndarray:
    """Whole time steps Brian2 counts in the duration ``t`` [s] (its ``timestep`` function:
    ``floor(t / dt + 1e-3)``), shape of ``t``."""
    return np.floor(np.asarray(t, dtype=float) / dt + 1e-3).astype(np.int64)


def n_steps(duration: float, dt: float) -> int:
    """Steps Brian2 simulates for a run of ``duration`` [s]: the nearest whole number when
    ``duration / dt`` is one to within 1e-4, the next one up otherwise (``Clock.set_interval``)."""
    ratio = duration / dt
    nearest = round(ratio)
    return int(nearest if abs(ratio - nearest) < 1e-4 else math.ceil(ratio))


def _where(mask: np.ndarray) -> str:
    idx = np.flatnonzero(mask)
    shown = ", ".join(str(i) for i in idx[:5])
    return f"sPLL {shown}" + (f" and {idx.size - 5} more" if idx.size > 5 else "")


def dt_warnings(
    matrix: np.ndarray, dt: float, duration: float | None = None, method: str = "exact"
) -> list[str]:
    """Human-readable reasons why a Brian2 run at time step ``dt`` may differ from the golden
    model by more than O(dt); empty when every time scale spans at least :data:`MIN_STEPS` steps.

    Args:
        matrix: network parameters, shape ``(n_spll, 15)`` in :data:`PARAM_NAMES` order.
        dt: time step [s].
        duration: run length [s]; flagged when it is not a whole number of steps.
        method: Brian2 integration method; ``"exact"`` adds its two failure modes (equal
            membrane and synapse time constants, ``exp(dt / tau)`` overflow).

    Returns:
        One message per offending parameter, naming it, the affected sPLLs and the value.
    """
    m = np.asarray(matrix, dtype=float)
    col = {name: m[:, k] for k, name in enumerate(PARAM_NAMES)}
    out: list[str] = []
    limit = MIN_STEPS * dt
    for name in _TIME_CONSTANTS:
        short = col[name] < limit
        if short.any():
            worst = col[name][short].min()
            out.append(
                f"{name} = {worst:.3g} s is only {worst / dt:.3g} dt in {_where(short)} "
                f"(< {MIN_STEPS} dt = {limit:.3g} s): events are rounded to the dt grid, so "
                "what this time constant shapes is not resolved"
            )
        if method == "exact":
            overflow = col[name] * EXP_OVERFLOW < dt
            if overflow.any():
                out.append(
                    f"{name}: dt / {name} > {EXP_OVERFLOW:g} in {_where(overflow)}: Brian2's "
                    "exact update evaluates exp(dt / tau), which overflows to NaN"
                )
    for name in _REFRACTORY:
        value = col[name]
        realised = steps(value, dt) * dt
        short = value < limit
        if short.any():
            out.append(
                f"{name} = {value[short].min():.3g} s in {_where(short)} is shorter than "
                f"{MIN_STEPS} dt = {limit:.3g} s: a neuron can fire at most once per step and "
                "its dead time is counted in whole steps"
            )
        off_grid = np.abs(realised - value) > 1e-9 * np.maximum(value, dt)
        if off_grid.any():
            k = np.flatnonzero(off_grid)[0]
            out.append(
                f"{name} is not a multiple of dt in {_where(off_grid)}: Brian2 truncates it "
                f"to whole steps ({value[k]:.6g} s becomes {realised[k]:.6g} s)"
            )
    if method == "exact":
        for tau, tau_syn in _PAIRS:
            a, b = col[tau], col[tau_syn]
            near = np.abs(a - b) <= DEGENERATE_GAP * np.maximum(a, b)
            if near.any():
                out.append(
                    f"{tau} and {tau_syn} are equal to within {DEGENERATE_GAP:g} (relative) in "
                    f"{_where(near)}: Brian2's exact solution divides by their difference "
                    "(NaN when equal, cancellation error otherwise)"
                )
    if duration is not None:
        steps_run = n_steps(duration, dt)
        if abs(steps_run * dt - duration) > 1e-9 * max(duration, dt):
            out.append(
                f"duration {duration:.6g} s is not a multiple of dt: Brian2 runs {steps_run} "
                f"steps ({steps_run * dt:.6g} s)"
            )
    return out
