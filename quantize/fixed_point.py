"""Fixed-point profiles: the integer parameters of an sPLL network on a digital chip.

The integer model (a digital chip stepping time by ``dt``) is specified in the module docs of
``engine/src/fixed_point.rs``; this module maps a continuous network onto its integers (the
``golden-fixed-point`` backend, ``mappings/fixed_point``, runs them).

**From SI values to integers** (per sPLL; ``D`` = decay bits, ``θ`` = profile threshold):

* each time constant ``τ`` becomes the decay constant ``δ = round(2^D (1 - e^{-dt/τ}))``,
  clamped to ``[1, 2^D - 1]`` (saturated otherwise); it realises ``τ' = -dt / ln(1 - δ/2^D)``;
* refractory periods become ``round(t_refr / dt)`` steps;
* the potential's LSB is ``q_v = V_thr / θ``; a current ``I`` into a membrane is the integer
  ``2^c I w / q_v`` with ``w = τ' (δ/2^D) / C`` (potential gained in one step from a constant
  current; ``C`` and ``V_thr`` only set scales and are realised exactly) and ``c`` fractional
  bits, the most the profile allows (``current_shift_max``) that keep the current of one
  facilitated trigger, or one CCO kick, below ``2^(state_bits - 1 - headroom_bits)``;
* the facilitatory current's LSB is ``q_f = g_fac / W_f`` with ``W_f`` the profile's
  facilitatory weight, a power of two, so ``g_fac`` itself is exact;
* the CCO weight ``2^c g_cco w / q_v`` and the offset ``2^c I_off w / q_v`` are rounded to
  mantissa × 2^exponent in the weight and bias formats; the trigger weight
  ``2^c g_trg q_f w / q_v`` (dimensionless) to mantissa × 2^-shift;
* the integer CCO's free-running period is a whole number of steps; with ``retune_offset``
  its bias is calibrated (bisection on the mantissa, on the integer CCO's free-running period
  from ``spll_hw._engine.cco_free_periods``, the reference's own membrane step) to the period
  nearest the requested one, for the realised ``τ_cco`` and refractory period;
* the realised offset current is the continuous one whose free-running period (eq. 6) is the
  integer CCO's, so the golden model of the realised network free-runs exactly like the chip.

Every realised value converts back to SI through the same factors, so the realised
:class:`~spll_hw.network.Network` is exactly the continuous network the integers stand for, and
the fixed-point reference converges to the golden simulation of it as ``dt → 0`` and the bit
widths grow.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spll_hw import _engine
from spll_hw.model.discrete import decay_constant, realised_tau
from spll_hw.model.grid import period_steps, refractory_steps
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES, SpllParams, offset_for_frequency

from .profiles import FixedPointProfile
from .report import ParamReport

#: Columns of the integer parameter matrix, defined by the Rust core (engine/src/fixed_point.rs).
FIXED_PARAM_NAMES: tuple[str, ...] = tuple(_engine.FIXED_PARAM_NAMES)

#: A time constant shorter than this many steps is resolved poorly; the report warns.
STIFF_STEPS = 5.0

_TAUS = (
    ("tau_cco_syn", "cco_syn_decay"),
    ("tau_cco", "cco_decay"),
    ("tau_tde_fac", "fac_decay"),
    ("tau_tde_trg", "trg_decay"),
    ("tau_tde", "tde_decay"),
)


@dataclass(frozen=True)
class FixedPointNetwork:
    """Integer parameters of every sPLL for the fixed-point reference.

    Attributes:
        matrix: shape ``(n_spll, 14)`` int64, columns :data:`FIXED_PARAM_NAMES`.
        dt: time step [s].
        state_bits: width of the state words.
        decay_bits: width of the decay constants.
        profile: name of the profile that produced it.
    """

    matrix: np.ndarray
    dt: float
    state_bits: int
    decay_bits: int
    profile: str

    def __getitem__(self, name: str) -> np.ndarray:
        """One column by name, shape ``(n_spll,)``."""
        if name not in FIXED_PARAM_NAMES:
            raise KeyError(f"unknown fixed-point parameter {name!r}; known: {FIXED_PARAM_NAMES}")
        return self.matrix[:, FIXED_PARAM_NAMES.index(name)]


def encode_decay(tau: float, dt: float, bits: int) -> tuple[int, float, bool]:
    """Decay constant of time constant ``tau`` [s] at step ``dt`` [s] with ``bits`` bits.

    Returns ``(delta, realised_tau, saturated)``: ``delta = round(2^bits (1 - e^{-dt/tau}))``
    clamped to ``[1, 2^bits - 1]`` (``saturated`` when clamped), and the time constant [s] it
    realises.
    """
    delta = decay_constant(tau, dt, bits)
    clamped = min(max(delta, 1), 2**bits - 1)
    return clamped, realised_tau(clamped, dt, bits), clamped != delta


def encode_scaled(
    x: float, mantissa_bits: int, exponent_min: int, exponent_max: int
) -> tuple[int, int, bool]:
    """Nearest ``mantissa · 2^exponent`` to ``x >= 0`` with a signed ``mantissa_bits``-bit
    mantissa (magnitude below ``2^(mantissa_bits-1)``) and ``exponent`` in the given range.

    The smallest exponent whose rounded mantissa fits is used (finest resolution). Returns
    ``(mantissa, exponent, saturated)``; a value above the largest representable one saturates
    to it, one below half the smallest step rounds to mantissa 0.
    """
    top = 2 ** (mantissa_bits - 1) - 1
    if x <= 0:
        return 0, exponent_min, False
    for e in range(exponent_min, exponent_max + 1):
        m = math.floor(math.ldexp(x, -e) + 0.5)
        if m <= top:
            return m, e, False
    return top, exponent_max, True


@dataclass
class _Bias:
    """The CCO bias of one sPLL while it is being chosen."""

    target: float  # requested free-running frequency [Hz] (0: the CCO is not to oscillate)
    mantissa: int
    exponent: int
    saturated: bool
    note: str
    scale: float  # LSB per step per ampere of offset current, 2^c w / q_v [1/A]


def quantize_fixed_point(network: Network, profile: FixedPointProfile, retune_offset: bool):
    """The fixed-point half of :func:`quantize.quantize` (module docstring for the mapping).

    Returns ``(realised_network, FixedPointNetwork, report_rows, header, warnings)``.
    """
    n = network.n_spll
    ints = np.zeros((n, len(FIXED_PARAM_NAMES)), dtype=np.int64)
    rows: list[ParamReport] = []
    kwargs: list[dict] = []
    biases: list[_Bias] = []
    stiff: dict[str, list[int]] = {}
    for i, p in enumerate(network.spll):
        values, spll_rows, params, bias = _encode_spll(i, p, profile, retune_offset)
        for column, value in values.items():
            ints[i, FIXED_PARAM_NAMES.index(column)] = value
        rows += spll_rows
        kwargs.append(params)
        biases.append(bias)
        for name, _ in _TAUS:
            if getattr(p, name) < STIFF_STEPS * profile.dt:
                stiff.setdefault(name, []).append(i)
    fixed = FixedPointNetwork(
        ints, profile.dt, profile.state_bits, profile.decay_bits, profile.name
    )
    if retune_offset:
        _calibrate(fixed, biases, profile)
    periods = _free_periods(fixed, [b.target for b in biases])
    realised = []
    for i, (p, params, bias) in enumerate(zip(network.spll, kwargs, biases, strict=True)):
        if bias.target > 0 and periods[i] == 0:
            raise ValueError(
                f"sPLL {i}: i_cco_offset cannot be represented by profile {profile.name!r}: the "
                f"integer CCO does not oscillate (bias {bias.mantissa << bias.exponent} LSB per "
                f"step against threshold {profile.threshold} LSB and decay "
                f"{fixed['cco_decay'][i]}/2^{profile.decay_bits}); raise bias_mantissa_bits or "
                "decay_bits"
            )
        frequency = 1.0 / (periods[i] * profile.dt) if periods[i] else 0.0
        if frequency > 0:
            # The continuous offset whose free-running period is the integer CCO's. Eq. 6 can
            # always be inverted here: a membrane of integers settles at least about one LSB
            # above its threshold, so it charges within ~ln(threshold) <= 21 time constants.
            offset = offset_for_frequency(
                frequency, params["tau_cco"], p.c_cco, p.v_cco_thr, params["t_cco_refr"]
            )
        else:
            offset = (bias.mantissa << bias.exponent) / bias.scale
        rows.append(
            ParamReport(i, "i_cco_offset", p.i_cco_offset, offset, bias.saturated, bias.note)
        )
        rows.append(
            ParamReport(
                i, "free_frequency", bias.target, frequency, note="integer CCO: whole-step period"
            )
        )
        realised.append(SpllParams(**params, i_cco_offset=offset))
    order = {name: k for k, name in enumerate(_REPORT_ORDER)}
    rows.sort(key=lambda r: (r.spll, order[r.name]))
    warnings = [
        f"dt = {profile.dt:g} s is not small against {name} (< {STIFF_STEPS:g} steps) in "
        f"{len(ids)} sPLL(s), e.g. sPLL {ids[0]}: {getattr(network.spll[ids[0]], name):.3g} s"
        for name, ids in stiff.items()
    ]
    saturated = sorted({r.name for r in rows if r.saturated})
    if saturated:
        warnings.append(f"saturated under {profile.name!r}: {', '.join(saturated)}")
    header = (
        f"{profile.description}; threshold {profile.threshold} LSB of a {profile.state_bits}-bit "
        f"state, facilitatory weight {profile.fac_weight} LSB"
    )
    ints.setflags(write=False)
    out = Network(
        tuple(realised), layout=network.layout, scales=network.scales, groups=network.groups
    )
    return out, fixed, rows, header, warnings


def _encode_spll(i: int, p: SpllParams, profile: FixedPointProfile, retune_offset: bool):
    """Integers of sPLL ``i`` except the final bias; returns ``(columns, report_rows,
    realised_kwargs_without_offset, _Bias)``."""
    dt, bits = profile.dt, profile.decay_bits
    values: dict[str, int] = {}
    rows: list[ParamReport] = []
    params: dict[str, float] = {}

    def add(name, requested, value, saturated=False, note=""):
        rows.append(ParamReport(i, name, float(requested), float(value), saturated, note))
        params[name] = float(value)

    deltas = {}
    for name, column in _TAUS:
        delta, tau, sat = encode_decay(getattr(p, name), dt, bits)
        values[column] = deltas[name] = delta
        note = f"{bits}-bit decay constant at dt = {dt:g} s"
        if sat:
            note = (
                "clamped to the slowest decay (delta = 1)"
                if delta == 1
                else "clamped to the fastest decay (delta = 2^D - 1)"
            )
        add(name, getattr(p, name), tau, sat, note)
    refr_max = 2**profile.refractory_bits - 1
    for name, column in (("t_cco_refr", "cco_refr"), ("t_tde_refr", "tde_refr")):
        steps = int(refractory_steps(getattr(p, name), dt))
        values[column] = min(steps, refr_max)
        sat = steps > refr_max
        note = f"{profile.refractory_bits}-bit counter full" if sat else "whole steps"
        add(name, getattr(p, name), values[column] * dt, sat, note)
    for name in ("c_cco", "c_tde"):
        add(name, getattr(p, name), getattr(p, name), note="scale only (exact)")
    theta = profile.threshold
    for name, column in (("v_cco_thr", "cco_threshold"), ("v_tde_thr", "tde_threshold")):
        values[column] = theta
        add(name, getattr(p, name), getattr(p, name), note=f"threshold = {theta} LSB (exact)")
    # Potential gained per step per unit current [V/A], and the potential LSB [V].
    w_tde = params["tau_tde"] * deltas["tau_tde"] / 2**bits / p.c_tde
    w_cco = params["tau_cco"] * deltas["tau_cco"] / 2**bits / p.c_cco
    q_tde, q_cco = p.v_tde_thr / theta, p.v_cco_thr / theta
    # Facilitatory current: its LSB makes g_fac exactly the profile's facilitatory weight.
    if p.g_tde_fac > 0:
        values["fac_weight"] = profile.fac_weight
        q_fac = p.g_tde_fac / profile.fac_weight
        add("g_tde_fac", p.g_tde_fac, p.g_tde_fac, note=f"{profile.fac_weight} LSB (exact)")
    else:
        q_fac = 1.0
        add("g_tde_fac", 0.0, 0.0, note="zero")
    # Trigger: g += (f * mantissa) >> shift, g with c fractional bits.
    per_lsb = p.g_tde_trg * q_fac * w_tde / q_tde
    c_tde = _fraction_bits(per_lsb * values.get("fac_weight", 0), profile)
    values["tde_current_shift"] = c_tde
    gain = math.ldexp(per_lsb, c_tde)
    m, e, sat = encode_scaled(gain, profile.weight_mantissa_bits, -profile.trigger_shift_max, 0)
    if m == 0 and p.g_tde_trg > 0 and p.g_tde_fac > 0:
        raise ValueError(
            f"sPLL {i}: g_tde_trg = {p.g_tde_trg!r} cannot be represented by profile "
            f"{profile.name!r}: the trigger weight {gain:.3g} rounds to 0 even at the largest "
            f"shift (trigger_shift_max = {profile.trigger_shift_max}); raise trigger_shift_max "
            "or dt"
        )
    values["trg_mantissa"], values["trg_shift"] = m, -e
    add(
        "g_tde_trg",
        p.g_tde_trg,
        math.ldexp(m, e - c_tde) * q_tde / (q_fac * w_tde),
        sat,
        "trigger mantissa full (shift 0)" if sat else "trigger mantissa >> shift",
    )
    # CCO weight: u += mantissa << exponent per TDE spike; u and the bias (the offset current)
    # carry c fractional bits: as many as one kick allows (headroom as for the trigger), as
    # long as the bias stays below a quarter of the state range.
    c_cco = _fraction_bits(p.g_cco * w_cco / q_cco, profile)
    if p.i_cco_offset > 0:
        room = profile.state_bits - 3 - math.log2(p.i_cco_offset * w_cco / q_cco)
        c_cco = min(c_cco, max(0, math.floor(room)))
    values["cco_current_shift"] = c_cco
    x = math.ldexp(p.g_cco * w_cco / q_cco, c_cco)
    m, e, sat = encode_scaled(
        x, profile.weight_mantissa_bits, profile.weight_exponent_min, profile.weight_exponent_max
    )
    if m == 0 and p.g_cco > 0:
        raise ValueError(
            f"sPLL {i}: g_cco = {p.g_cco!r} cannot be represented by profile {profile.name!r}: "
            f"it is {x:.3g} LSB, below half the smallest weight 2^{profile.weight_exponent_min}; "
            "raise state_bits or dt"
        )
    values["cco_weight"] = m << e
    add(
        "g_cco",
        p.g_cco,
        math.ldexp(m << e, -c_cco) * q_cco / w_cco,
        sat,
        "weight format full" if sat else "weight mantissa << exponent",
    )
    # Offset current (the CCO's bias), before calibration.
    target = p.free_frequency()
    offset, note = p.i_cco_offset, "bias mantissa << exponent; effective offset of its period"
    if retune_offset and target > 0:
        # Aim at the middle of the nearest whole-step period; _calibrate then fixes it.
        steps = max(values["cco_refr"] + 1, round(1.0 / (target * dt)))
        charge = (steps - values["cco_refr"] - 0.5) * dt
        try:
            offset = offset_for_frequency(
                1.0 / (charge + params["t_cco_refr"]),
                params["tau_cco"],
                p.c_cco,
                p.v_cco_thr,
                params["t_cco_refr"],
            )
        except ValueError as exc:
            raise ValueError(
                f"sPLL {i}: i_cco_offset cannot hold the free-running frequency {target:.6g} Hz "
                f"under profile {profile.name!r}: {exc}"
            ) from exc
        note = "retuned: bias calibrated to the nearest whole-step period"
    scale = math.ldexp(w_cco / q_cco, c_cco)
    m, e, sat = encode_scaled(
        offset * scale,
        profile.bias_mantissa_bits,
        profile.bias_exponent_min,
        profile.bias_exponent_max,
    )
    if m == 0 and offset > 0:
        raise ValueError(
            f"sPLL {i}: i_cco_offset = {offset!r} cannot be represented by profile "
            f"{profile.name!r}: it is {offset * scale:.3g} LSB per step, below half the smallest "
            f"bias 2^{profile.bias_exponent_min}; raise state_bits or dt"
        )
    values["cco_bias"] = m << e
    bias = _Bias(target, m, e, sat, "bias format full" if sat else note, scale)
    return values, rows, params, bias


def _fraction_bits(current: float, profile: FixedPointProfile) -> int:
    """Fractional bits for a current whose typical peak is ``current`` LSB per step: the most,
    up to ``current_shift_max``, that keep it below ``2^(state_bits - 1 - headroom_bits)``."""
    if current <= 0:
        return 0
    room = profile.state_bits - 1 - profile.headroom_bits - math.log2(current)
    return int(min(profile.current_shift_max, max(0, math.floor(room))))


def _free_periods(fixed: FixedPointNetwork, targets: Sequence[float]) -> np.ndarray:
    """Free-running period [steps] of each integer CCO (no input), shape ``(n_spll,)``; 0 for
    a CCO that does not fire within twice its target period (or at all, target 0)."""
    targets = np.asarray(targets, dtype=float)
    periods = np.zeros(len(targets), dtype=np.int64)
    active = targets > 0
    if not np.any(active):
        return periods
    slowest = round(1.0 / (targets[active].min() * fixed.dt))
    limit = 2 * slowest + 2 * int(fixed["cco_refr"].max()) + 2
    found = _engine.cco_free_periods(
        np.ascontiguousarray(fixed.matrix, dtype=np.int64), fixed.state_bits, fixed.decay_bits,
        limit,
    )  # fmt: skip
    periods[active] = found[active]
    return periods


def _calibrate(fixed: FixedPointNetwork, biases: list[_Bias], profile: FixedPointProfile) -> None:
    """Choose each CCO's bias mantissa (exponent kept) so its whole-step free-running period
    is the one nearest to the target: bisection for the smallest mantissa whose period is at
    most the target (the period falls as the bias grows), then the closer of it and the next
    smaller one. Updates ``biases`` and the bias column of ``fixed`` in place."""
    active = [i for i, b in enumerate(biases) if b.target > 0 and not b.saturated]
    if not active:
        return
    refr = fixed["cco_refr"]
    goal = period_steps([biases[i].target for i in active], fixed.dt, refr[active])
    targets = [b.target if i in active else 0.0 for i, b in enumerate(biases)]
    column = FIXED_PARAM_NAMES.index("cco_bias")
    exps = np.array([biases[i].exponent for i in active])

    def periods(mantissas: np.ndarray) -> np.ndarray:
        fixed.matrix[active, column] = mantissas << exps
        p = _free_periods(fixed, targets)[active]
        return np.where(p == 0, np.iinfo(np.int64).max, p)

    lo = np.ones(len(active), dtype=np.int64)
    hi = np.full(len(active), 2 ** (profile.bias_mantissa_bits - 1) - 1, dtype=np.int64)
    while np.any(lo < hi):
        mid = (lo + hi) // 2
        fast = periods(mid) <= goal
        hi = np.where(fast, mid, hi)
        lo = np.where(fast, lo, mid + 1)
    at, below = periods(lo), periods(np.maximum(lo - 1, 1))
    choice = np.where(np.abs(below - goal) < np.abs(at - goal), np.maximum(lo - 1, 1), lo)
    for k, i in enumerate(active):
        biases[i].mantissa = int(choice[k])
    fixed.matrix[active, column] = choice << exps


_REPORT_ORDER = (*PARAM_NAMES, "free_frequency")
