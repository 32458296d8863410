"""``quantize(network, profile)``: an sPLL network under a chip's constraints, and what it lost.

The result holds the **realised network**, an ordinary :class:`~spll_hw.network.Network` of the
parameter values the chip actually implements (the golden engine simulates them exactly), and a
per-parameter **report**: requested against realised value, relative error and what saturated.
For a fixed-point profile it also holds the integer parameters that the discrete-time
fixed-point reference (the ``golden-fixed-point`` backend, :mod:`mappings.fixed_point`) runs
bit for bit.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from spll_hw.network import Network
from spll_hw.params import SpllParams

from .analog import quantize_analog
from .fixed_point import quantize_fixed_point
from .profiles import FixedPointProfile, Profile, load_profile
from .report import QuantizationReport
from .steps import check_step, is_stepped


@dataclass(frozen=True)
class QuantizedNetwork:
    """A network under a chip profile.

    Attributes:
        network: the realised network (what the chip implements, in SI units); simulate it
            with the golden engine (``spll_hw.simulate``) for the exact continuous-time
            behaviour of the quantized parameters.
        requested: the network that was asked for.
        profile: the chip profile.
        report: the per-parameter :class:`QuantizationReport`.
        fixed: integer parameters for the fixed-point reference
            (:class:`quantize.fixed_point.FixedPointNetwork`; ``None`` for analog profiles).
    """

    network: Network
    requested: Network
    profile: Profile
    report: QuantizationReport
    fixed: object | None = field(default=None, repr=False)

    @property
    def n_spll(self) -> int:
        return self.network.n_spll

    def report_markdown(self, per_spll: bool = False) -> str:
        """The report as Markdown (:meth:`QuantizationReport.table`)."""
        return self.report.table(per_spll)


def quantize(
    network: Network | SpllParams,
    profile: Profile | str | Path,
    *,
    retune_offset: bool = True,
    seed: int | None = None,
) -> QuantizedNetwork:
    """Constrain ``network`` to chip ``profile`` and report what each parameter became.

    Args:
        network: the requested network (a bare :class:`SpllParams` is a one-sPLL network).
        profile: a loaded profile, a bundled profile's name or a TOML path.
        retune_offset: fixed-point profiles only: re-solve each CCO offset current for the
            realised time constant and refractory period so the free-running frequency stays
            the requested one (eq. 6) before the offset itself is quantized; ``False``
            quantizes the requested offset as is.
        seed: analog profiles only: overrides the profile's mismatch seed.

    Returns:
        A :class:`QuantizedNetwork`. The last :data:`KEPT` realisations are kept, keyed on
        what a realisation depends on (the network's parameters, layout, scales and groups;
        the profile less its ``chip`` tables, which no realisation reads; ``retune_offset``;
        ``seed``): a call that repeats one (a report placing a network at the ends of its
        profile's placement ranges, then costing and simulating it) gets the same realised
        network and integers again, not a second realisation, so treat them as read-only.

    Raises:
        ValueError: when a profile named at a step (``loihi2@80us``, :mod:`quantize.steps`)
            cannot write a time constant or refractory period at that step (the message names
            them and the steps that work), or a parameter cannot be represented at all (a
            non-zero gain or offset that rounds to zero, a CCO that no longer oscillates) or
            the network does not fit
            the chip (more time-scale groups than allowed); the message names the sPLL, the
            parameter and the profile key to change.
    """
    if isinstance(network, SpllParams):
        network = Network.single(network)
    if not isinstance(network, Network):
        raise ValueError(f"expected a Network or SpllParams, got {type(network).__name__}")
    profile = load_profile(profile)
    key = (_network_key(network), replace(profile, chip=None), retune_offset, seed)
    found = _kept.pop(key, None) or _realised(network, profile, retune_offset, seed)
    _kept[key] = found
    while len(_kept) > KEPT:
        _kept.popitem(last=False)
    return replace(found, requested=network, profile=profile)


#: How many realisations :func:`quantize` keeps (the most recently used).
KEPT = 8

_kept: OrderedDict[tuple, QuantizedNetwork] = OrderedDict()


def _network_key(network: Network) -> tuple:
    """Everything of ``network`` a realisation reads, hashable."""
    arrays = (np.asarray(a) for a in (network.scales, network.groups))
    return (network.spll, network.layout, *((a.dtype.str, a.shape, a.tobytes()) for a in arrays))


def _realised(
    network: Network, profile: Profile, retune_offset: bool, seed: int | None
) -> QuantizedNetwork:
    """:func:`quantize` of a loaded profile, realised anew."""
    if isinstance(profile, FixedPointProfile):
        if is_stepped(profile):
            check_step(network, profile)
        if seed is not None:
            raise ValueError("seed applies to analog profiles only (fixed point is deterministic)")
        realised, fixed, rows, header, warnings = quantize_fixed_point(
            network, profile, retune_offset
        )
    else:
        realised, rows, header, warnings = quantize_analog(network, profile, seed)
        fixed = None
    report = QuantizationReport(profile.name, tuple(rows), header, tuple(warnings))
    return QuantizedNetwork(realised, network, profile, report, fixed)
