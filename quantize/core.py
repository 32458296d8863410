"""``quantize(network, profile)``: an sPLL network under a chip's constraints, and what it lost.

The result holds the **realised network**, an ordinary :class:`~spll_hw.network.Network` of the
parameter values the chip actually implements (the golden engine simulates them exactly), and a
per-parameter **report**: requested against realised value, relative error and what saturated.
For a fixed-point profile it also holds the integer parameters that the discrete-time
fixed-point reference (:func:`quantize.simulate_fixed_point`) runs bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES, SpllParams

from .profiles import FixedPointProfile, Profile, load_profile

#: Report rows per sPLL: the 15 parameters, then the derived free-running frequency [Hz].
REPORT_NAMES: tuple[str, ...] = (*PARAM_NAMES, "free_frequency")


@dataclass(frozen=True)
class ParamReport:
    """One parameter of one sPLL: what was asked for and what the chip realises.

    Attributes:
        spll: sPLL index.
        name: parameter name (:data:`REPORT_NAMES`; SI units as in :class:`SpllParams`).
        requested: value in the requested network.
        realised: value the chip implements.
        saturated: the value was clipped at a limit of the format (or clamped to the slowest
            or fastest decay it can express).
        note: what happened (rounding format, mismatch, offset level, retuning, ...).
    """

    spll: int
    name: str
    requested: float
    realised: float
    saturated: bool = False
    note: str = ""

    @property
    def rel_error(self) -> float:
        """``(realised - requested) / |requested|``; 0 if both are 0, ``inf`` if only the
        requested value is 0."""
        if self.requested == 0:
            return 0.0 if self.realised == 0 else math.inf
        return (self.realised - self.requested) / abs(self.requested)


@dataclass(frozen=True)
class QuantizationReport:
    """Every :class:`ParamReport` of a network (``n_spll × 16`` rows) plus warnings."""

    profile: str
    rows: tuple[ParamReport, ...]
    header: str = ""
    warnings: tuple[str, ...] = ()

    def of(self, name: str) -> list[ParamReport]:
        """The rows of parameter ``name``, one per sPLL in order."""
        if name not in REPORT_NAMES:
            raise ValueError(f"unknown parameter {name!r}; known: {REPORT_NAMES}")
        return [r for r in self.rows if r.name == name]

    def rel_errors(self, name: str) -> np.ndarray:
        """Relative error of parameter ``name`` per sPLL, shape ``(n_spll,)``."""
        return np.array([r.rel_error for r in self.of(name)])

    def saturated(self) -> list[ParamReport]:
        """The rows whose value saturated."""
        return [r for r in self.rows if r.saturated]

    def summary(self) -> list[dict]:
        """One dict per parameter: requested and realised ranges, the relative error of largest
        magnitude (signed) and the mean absolute one, how many sPLLs saturated, the notes."""
        out = []
        for name in REPORT_NAMES:
            rows = self.of(name)
            if not rows:
                continue
            err = np.array([r.rel_error for r in rows])
            out.append(
                {
                    "name": name,
                    "requested": (min(r.requested for r in rows), max(r.requested for r in rows)),
                    "realised": (min(r.realised for r in rows), max(r.realised for r in rows)),
                    "worst_rel_error": float(err[np.argmax(np.abs(err))]),
                    "mean_abs_rel_error": float(np.mean(np.abs(err))),
                    "saturated": sum(r.saturated for r in rows),
                    "n": len(rows),
                    "notes": sorted({r.note for r in rows if r.note}),
                }
            )
        return out

    def table(self, per_spll: bool = False) -> str:
        """The report as Markdown: one row per parameter (ranges over sPLLs), or with
        ``per_spll`` one row per parameter and sPLL."""
        lines = [f"Profile **{self.profile}**" + (f": {self.header}" if self.header else ""), ""]
        if per_spll:
            lines += [
                "| sPLL | parameter | requested | realised | rel. error | saturated | note |",
                "|---|---|---|---|---|---|---|",
            ]
            for r in self.rows:
                lines.append(
                    f"| {r.spll} | {r.name} | {r.requested:.6g} | {r.realised:.6g} | "
                    f"{_percent(r.rel_error)} | {'yes' if r.saturated else ''} | {r.note} |"
                )
        else:
            lines += [
                "| parameter | requested | realised | worst rel. error | mean abs. rel. error "
                "| saturated | note |",
                "|---|---|---|---|---|---|---|",
            ]
            for s in self.summary():
                sat = f"{s['saturated']}/{s['n']}" if s["saturated"] else ""
                lines.append(
                    f"| {s['name']} | {_range(s['requested'])} | {_range(s['realised'])} | "
                    f"{_percent(s['worst_rel_error'])} | "
                    f"{_percent(s['mean_abs_rel_error'], signed=False)} | "
                    f"{sat} | {'; '.join(s['notes'])} |"
                )
        if self.warnings:
            lines += ["", *[f"- warning: {w}" for w in self.warnings]]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


def _range(pair: tuple[float, float]) -> str:
    low, high = pair
    return f"{low:.4g}" if low == high else f"{low:.4g} … {high:.4g}"


def _percent(x: float, signed: bool = True) -> str:
    if math.isinf(x):
        return "inf"
    return f"{100 * x:+.3g} %" if signed else f"{100 * x:.3g} %"


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
        A :class:`QuantizedNetwork`.

    Raises:
        ValueError: when a parameter cannot be represented at all (a non-zero gain or offset
            that rounds to zero, a CCO that no longer oscillates) or the network does not fit
            the chip (more time-scale groups than allowed); the message names the sPLL, the
            parameter and the profile key to change.
    """
    if isinstance(network, SpllParams):
        network = Network.single(network)
    if not isinstance(network, Network):
        raise ValueError(f"expected a Network or SpllParams, got {type(network).__name__}")
    profile = load_profile(profile)
    if isinstance(profile, FixedPointProfile):
        if seed is not None:
            raise ValueError("seed applies to analog profiles only (fixed point is deterministic)")
        from .fixed_point import quantize_fixed_point

        realised, fixed, rows, header, warnings = quantize_fixed_point(
            network, profile, retune_offset
        )
    else:
        from .analog import quantize_analog

        realised, rows, header, warnings = quantize_analog(network, profile, seed)
        fixed = None
    report = QuantizationReport(profile.name, tuple(rows), header, tuple(warnings))
    return QuantizedNetwork(realised, network, profile, report, fixed)
