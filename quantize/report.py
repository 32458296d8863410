"""What a chip profile did to each parameter of a network: requested against realised values.

:class:`QuantizationReport` holds one :class:`ParamReport` per parameter and sPLL (the 15
parameters of :data:`spll_hw.params.PARAM_NAMES` and the derived free-running frequency) and
renders them as Markdown.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from spll_hw.params import PARAM_NAMES

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
