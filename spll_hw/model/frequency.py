"""Eq. 6 of the thesis: the free-running frequency of a LIF neuron with a constant input current,
and its inverse (the offset current that sets a CCO's free-running frequency).

Units are SI: seconds, amperes, farads, volts, hertz. The golden engine states the same period
in ``engine/src/membrane.rs`` and is tested against these (``tests/test_analytic.py``).
"""

from __future__ import annotations

import math


def free_frequency(
    i_offset: float, tau: float, c: float = 1.0, v_thr: float = 1.0, t_refr: float = 1e-3
) -> float:
    """Free-running frequency [Hz] of a LIF neuron with constant input current (thesis eq. 6).

    ``1 / (t_refr + tau * ln(I tau / (I tau - V_thr C)))``; 0.0 when ``I tau <= V_thr C``
    (the membrane never reaches threshold).
    """
    drive = i_offset * tau
    if drive <= v_thr * c:
        return 0.0
    # ln(I tau / (I tau - V C)) = -log1p(-V C / (I tau)), accurate when the drive is large.
    period = t_refr - tau * math.log1p(-v_thr * c / drive)
    return 1.0 / period


def offset_for_frequency(
    frequency: float, tau: float, c: float = 1.0, v_thr: float = 1.0, t_refr: float = 1e-3
) -> float:
    """Offset current [A] that makes a LIF neuron free-run at ``frequency`` [Hz] (eq. 6 inverted).

    ``I = V_thr C / (tau (1 - exp(-(1/f - t_refr) / tau)))``. Raises ``ValueError`` when the
    frequency is not positive or unreachable (``1/f <= t_refr``: the refractory period alone is
    longer than the requested period).
    """
    if not (math.isfinite(frequency) and frequency > 0):
        raise ValueError(f"free-running frequency must be finite and > 0 Hz, got {frequency!r}")
    charge_time = 1.0 / frequency - t_refr
    if charge_time <= 0:
        raise ValueError(
            f"free-running frequency {frequency!r} Hz is unreachable: its period "
            f"{1.0 / frequency:.6g} s is not longer than the refractory period {t_refr!r} s "
            f"(reachable frequencies are below {1.0 / t_refr:.6g} Hz)"
        )
    ratio = charge_time / tau
    # The period depends on I - V_thr C / tau, which shrinks like e^{-ratio}: past ~30 time
    # constants the double-precision offset can no longer hold the requested frequency.
    sensitivity = math.inf if ratio > 700 else _EPS * math.exp(ratio) / ratio
    if sensitivity > _MAX_FREQUENCY_ERROR:
        raise ValueError(
            f"free-running frequency {frequency!r} Hz cannot be set with membrane time constant "
            f"{tau!r} s: the charge time {charge_time:.6g} s is {ratio:.3g} time constants, so the "
            f"offset current would sit at the rheobase to within rounding (relative frequency "
            f"error {sensitivity:.2g}); use a longer time constant or a time-scaled layout"
        )
    return v_thr * c / (tau * -math.expm1(-ratio))


_EPS = 2.220446049250313e-16
#: Largest relative error of a free-running frequency that offset_for_frequency accepts.
_MAX_FREQUENCY_ERROR = 1e-6
