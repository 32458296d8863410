"""The discretisations the clocked targets use: exact-step decays, membrane gains, the exact
one-step propagator of a synapse into a membrane, and integer decay constants.

A clocked target advances each state over a step of ``dt`` [s]. For the linear equations of
:mod:`spll_hw.model.equations` the exact update over a step is:

* a current decays by the factor ``e^{-dt/tau}``, i.e. loses the fraction
  :func:`decay_fraction` ``= 1 - e^{-dt/tau}`` (Lava's ``du``/``dv`` convention);
* a membrane ``(tau, C)`` driven by a constant current ``I`` over the step gains
  ``I * membrane_gain(tau, C, dt)`` with ``membrane_gain = tau (1 - e^{-dt/tau}) / C`` [V/A]:
  a constant current charges the membrane exactly as in continuous time;
* a membrane driven by a decaying synapse current: :func:`exact_propagator`.

On integers (a profile's ``decay_bits`` = ``D``), a time constant is the decay constant
``delta = round(2^D (1 - e^{-dt/tau}))`` (:func:`decay_constant`, halves up) and realises the
time constant :func:`realised_tau` ``= -dt / ln(1 - delta / 2^D)``; clamping it to a target's
range is the target's business (``quantize.fixed_point.encode_decay``,
``mappings/lava/integers.py``).

Every function takes Python floats or numpy arrays; Python floats are computed with :mod:`math`
(the per-sPLL profile encodings are pinned bit for bit to it), arrays elementwise with numpy.
"""

from __future__ import annotations

import math

import numpy as np

from .grid import round_half_up


def decay_fraction(tau, dt: float):
    """Fraction ``1 - e^{-dt/tau}`` of a current with time constant ``tau`` [s] lost in one step
    of ``dt`` [s]."""
    if isinstance(tau, float | int):
        return -math.expm1(-dt / tau)
    return -np.expm1(-dt / np.asarray(tau, dtype=np.float64))


def membrane_gain(tau, c, dt: float):
    """Potential [V] a membrane ``(tau [s], C [F])`` gains in one step of ``dt`` [s] per ampere
    of constant current: ``tau (1 - e^{-dt/tau}) / C`` [V/A]."""
    return tau * decay_fraction(tau, dt) / c


def decay_constant(tau, dt: float, bits: int):
    """Integer decay constant ``round(2^bits (1 - e^{-dt/tau}))`` (halves up, not clamped) of a
    time constant ``tau`` [s] at step ``dt`` [s]: an ``int`` for a float ``tau``, else int64."""
    scaled = decay_fraction(tau, dt) * 2**bits
    if isinstance(scaled, float):
        return int(round_half_up(scaled))
    return round_half_up(scaled).astype(np.int64)


def realised_tau(delta, dt: float, bits: int):
    """Time constant [s] that the integer decay ``delta`` (of ``2^bits``) realises at step
    ``dt`` [s]: ``-dt / ln(1 - delta / 2^bits)`` (``inf`` for ``delta = 0``)."""
    if isinstance(delta, int | float):
        return math.inf if delta == 0 else -dt / math.log1p(-delta / 2**bits)
    d = np.asarray(delta, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return -dt / np.log1p(-d / 2**bits)


def exact_propagator(tau_syn, tau_mem, c, dt: float):
    """Exact one-step factors of ``dI/dt = -I/tau_syn``, ``dv/dt = I/C - v/tau_mem`` over ``dt``
    [s]: ``I' = e_s I``, ``v' = e_m v + k I``. Returns ``(e_s, k, e_m)`` (arrays over sPLLs);
    ``k = dt e_m / C`` where the two time constants coincide (to 1e-9 of a step)."""
    tau_syn, tau_mem = np.asarray(tau_syn, dtype=float), np.asarray(tau_mem, dtype=float)
    e_s = np.exp(-dt / tau_syn)
    e_m = np.exp(-dt / tau_mem)
    rate = 1.0 / tau_mem - 1.0 / tau_syn
    close = np.abs(rate) * dt < 1e-9
    safe = np.where(close, 1.0, rate)
    k = np.where(close, dt * e_m, (e_s - e_m) / safe) / c
    return e_s, k, e_m
