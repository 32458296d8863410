"""How many bits one sPLL occupies on a fixed-point chip: its parameters and its state at the
profile's word widths (the footprint NeuroBench counts, :mod:`spll_hw.harness.neurobench`).

**Parameters**, one field per column of :data:`quantize.fixed_point.FIXED_PARAM_NAMES`: a decay
constant ``decay_bits``; a weight (``cco_weight``, ``fac_weight``) a signed mantissa of
``weight_mantissa_bits`` plus an exponent wide enough for ``weight_exponent_min ..
weight_exponent_max``; the trigger gain a mantissa of ``weight_mantissa_bits`` plus a shift of
``0 .. trigger_shift_max``; a current shift ``0 .. current_shift_max`` (0 bits on Loihi, which
has none); the bias mantissa ``bias_mantissa_bits`` plus its exponent; a refractory period
``refractory_bits``; a threshold ``threshold_mantissa_bits`` (its fixed shift is the chip's,
not stored). **State**: the five state words of :data:`STATE_WORDS` at ``state_bits`` each and
the two refractory counters at ``refractory_bits``.

Every sPLL is counted with its own parameters: a chip that shares configurations between the
neurons of a core (Loihi's compartment profiles) stores fewer.
"""

from __future__ import annotations

from .fixed_point import FIXED_PARAM_NAMES
from .profiles import FixedPointProfile, Profile

#: The state words of one sPLL on a fixed-point chip (``engine/src/fixed_point.rs``,
#: ``FixedState``): facilitatory and trigger currents, TDE potential, CCO current and potential.
STATE_WORDS = ("fac", "trg", "v_tde", "u_cco", "v_cco")
#: Its refractory counters (TDE, CCO).
COUNTERS = ("tde_refr_left", "cco_refr_left")


def _range_bits(low: int, high: int) -> int:
    """Bits of an unsigned field holding ``low .. high`` (0 when it holds one value)."""
    return (high - low).bit_length()


def parameter_bits(profile: FixedPointProfile) -> dict[str, int]:
    """Bits of each fixed-point parameter of one sPLL (module docstring), by name."""
    p = profile
    weight = p.weight_mantissa_bits + _range_bits(p.weight_exponent_min, p.weight_exponent_max)
    by_kind = {
        "decay": p.decay_bits,
        "weight": weight,
        "current_shift": _range_bits(0, p.current_shift_max),
        "bias": p.bias_mantissa_bits + _range_bits(p.bias_exponent_min, p.bias_exponent_max),
        "refr": p.refractory_bits,
        "threshold": p.threshold_mantissa_bits,
        "trg_mantissa": p.weight_mantissa_bits,
        "trg_shift": _range_bits(0, p.trigger_shift_max),
    }
    out = {}
    for name in FIXED_PARAM_NAMES:
        kind = next(k for k in by_kind if name.endswith(k))
        out[name] = by_kind[kind]
    return out


def storage_bits(profile: Profile) -> tuple[int, int] | None:
    """``(parameter bits, state bits)`` of one sPLL on ``profile``'s chip; ``None`` for a
    profile without word widths (an analog chip)."""
    if not isinstance(profile, FixedPointProfile):
        return None
    state = len(STATE_WORDS) * profile.state_bits + len(COUNTERS) * profile.refractory_bits
    return sum(parameter_bits(profile).values()), state
