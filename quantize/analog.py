"""Analog profiles: device mismatch, a bank of offset currents and a circuit budget.

Quantizing for an analog profile, in this order:

1. **Circuit budget.** The network may use at most ``max_groups`` distinct sPLL circuits
   (parameter sets apart from the offset, :func:`spll_hw.layouts.circuit_count`); more is an
   error suggesting a grouped layout, never a silent truncation.
2. **Offset levels.** The CCO offset currents are snapped to at most ``offset_levels``
   distinct values, placed by :func:`spll_hw.layouts.partition` over the distinct positive
   offsets (optimal in squared log error; each level the geometric mean of the offsets it
   serves). A zero offset stays zero and uses one level.
3. **Mismatch.** Every time constant and gain of every sPLL is multiplied by its own lognormal
   factor ``exp(sigma z)``, ``z ~ N(0, 1)`` drawn with ``numpy.random.default_rng(seed)`` as an
   ``(n_spll, 8)`` array: columns ``tau_cco_syn, tau_cco, tau_tde_fac, tau_tde_trg, tau_tde``
   (``tau_sigma``) then ``g_cco, g_tde_fac, g_tde_trg`` (``gain_sigma``). Capacitances,
   thresholds and refractory periods are exact.
"""

from __future__ import annotations

import numpy as np

from spll_hw.layouts import circuit_count, partition
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES, SpllParams

from .profiles import AnalogProfile
from .report import ParamReport

#: Time constants under ``tau_sigma`` mismatch, in the column order of the draw.
TAU_NAMES = ("tau_cco_syn", "tau_cco", "tau_tde_fac", "tau_tde_trg", "tau_tde")
#: Gains under ``gain_sigma`` mismatch, after the time constants in the draw.
GAIN_NAMES = ("g_cco", "g_tde_fac", "g_tde_trg")


#: What a network of several inputs (a multichannel one, one sPLL network per channel) can
#: change when its circuits exceed an analog chip's groups: fit's ``grouped:auto`` takes one.
CHANNELS_FIX = (
    "every channel's sPLL circuits count: give the [[channel]] tables layouts with fewer "
    "circuits in all (vary-offset with spread = 0 is one per channel), or choose a chip with more"
)


class CircuitBudgetError(ValueError):
    """A network with more distinct sPLL circuits than an analog chip's groups: ``need``,
    what it needs in words, and ``fix``, what makes one network fit; ``for_channels`` says the
    same for a network of several inputs (:data:`CHANNELS_FIX`, where the fix is a layout)."""

    def __init__(self, need: str, fix: str, layout_fix: bool) -> None:
        super().__init__(f"{need}; {fix}")
        self.need, self.fix, self.layout_fix = need, fix, layout_fix

    def for_channels(self) -> str:
        return f"{self.need}; {CHANNELS_FIX}" if self.layout_fix else str(self)


def check_group_budget(network: Network, max_groups: int, profile: str | None = None) -> int:
    """The number of circuits :func:`circuit_count` of ``network``; a
    :class:`CircuitBudgetError` naming the fix when it exceeds ``max_groups`` of chip
    ``profile`` (a name)."""
    count = circuit_count(network)
    if count > max_groups:
        groups = len(np.unique(network.groups))
        spread = network.layout in ("grouped", "vary-offset") and groups <= max_groups
        fix = (
            f"every sPLL of its {groups} group(s) differs (a spread gives each sPLL its own "
            "circuit): set spread = 0 in the network file"
            if spread
            else f"a grouped layout of at most {max_groups} groups holds the circuits, and "
            f"`spll-hw fit --layouts grouped:auto --profiles {profile or 'NAME'}` finds the "
            "largest that also fits the chip's cores"
        )
        chip = "the chip" if profile is None else f"profile {profile!r}"
        need = (
            f"the network does not fit {chip} (max_groups = {max_groups}): it needs {count} "
            f"distinct sPLL circuits (time-scale groups) but at most {max_groups} are available"
        )
        raise CircuitBudgetError(need, fix, layout_fix=not spread)
    return count


def offset_levels(offsets: np.ndarray, n_levels: int) -> np.ndarray:
    """``offsets`` [A] (shape ``(n,)``, >= 0) snapped to at most ``n_levels`` distinct values
    (module docstring), same shape."""
    offsets = np.asarray(offsets, dtype=float)
    positive = np.unique(offsets[offsets > 0])
    available = n_levels - int(np.any(offsets == 0))
    if positive.size <= available:
        return offsets.copy()
    if available < 1:
        raise ValueError(
            f"offset_levels = {n_levels} cannot provide both zero and non-zero offset currents"
        )
    part = partition(positive, available, "squared")
    level_of = dict(zip(positive, part.centres[part.groups], strict=True))
    return np.array([level_of[x] if x > 0 else 0.0 for x in offsets])


def quantize_analog(network: Network, profile: AnalogProfile, seed: int | None):
    """The analog half of :func:`quantize.quantize`; returns ``(realised_network, rows,
    header, warnings)``."""
    check_group_budget(network, profile.max_groups, profile.name)
    requested = network.matrix()
    n = network.n_spll
    realised = requested.copy()
    col = PARAM_NAMES.index
    realised[:, col("i_cco_offset")] = offset_levels(
        requested[:, col("i_cco_offset")], profile.offset_levels
    )
    rng = np.random.default_rng(profile.seed if seed is None else seed)
    z = rng.standard_normal((n, len(TAU_NAMES) + len(GAIN_NAMES)))
    sigmas = [profile.tau_sigma] * len(TAU_NAMES) + [profile.gain_sigma] * len(GAIN_NAMES)
    for k, name in enumerate(TAU_NAMES + GAIN_NAMES):
        realised[:, col(name)] *= np.exp(sigmas[k] * z[:, k])
    params = [SpllParams.from_row(r) for r in realised]
    n_offsets = len(np.unique(requested[:, col("i_cco_offset")]))
    notes = {name: "lognormal mismatch" for name in TAU_NAMES + GAIN_NAMES}
    notes["i_cco_offset"] = f"one of {profile.offset_levels} offset levels"
    rows = []
    for i, p in enumerate(network.spll):
        for k, name in enumerate(PARAM_NAMES):
            rows.append(
                ParamReport(i, name, requested[i, k], realised[i, k], note=notes.get(name, "exact"))
            )
        rows.append(
            ParamReport(
                i,
                "free_frequency",
                p.free_frequency(),
                params[i].free_frequency(),
                note="eq. 6 on the realised parameters",
            )
        )
    warnings = []
    if n_offsets > profile.offset_levels:
        warnings.append(
            f"{n_offsets} distinct offset currents share {profile.offset_levels} levels: "
            "several sPLLs now free-run at the same frequency"
        )
    silent = [
        i
        for i, p in enumerate(params)
        if p.free_frequency() == 0 < network.spll[i].free_frequency()
    ]
    if silent:
        warnings.append(
            f"mismatch leaves {len(silent)} CCO(s) below rheobase (no free-running "
            f"oscillation), e.g. sPLL {silent[0]}"
        )
    header = f"{profile.description}; seed {profile.seed if seed is None else seed}"
    out = Network(
        tuple(params), layout=network.layout, scales=network.scales, groups=network.groups
    )
    return out, rows, header, warnings
