"""Stiff and extreme parameters through every backend, the golden model as truth.

Each case is a one-sPLL network pushed to an edge of the parameter space (time-constant ratios
of 1e-3 and 1e3, equal and nearly equal synapse/membrane constants, huge gains, input at the
refractory limit, microsecond time constants). Every backend runs it; its outcome is ``ok``
(TDE and CCO counts within ``tolerance`` of golden), ``diverges`` (counts off by more), or
``breaks`` (it raised an error) — with the backend's own warnings attached.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .. import backends
from ..network import Network
from ..params import SpllParams
from ..simulate import periodic_spikes, simulate

BASE = SpllParams(
    tau_cco_syn=7.5e-3, tau_cco=0.05, tau_tde_trg=1.25e-3, tau_tde_fac=9.6e-3, tau_tde=4.5e-3,
    g_cco=5.0, g_tde_trg=0.5, g_tde_fac=2000.0,
)  # fmt: skip


@dataclass(frozen=True)
class Case:
    """One extreme configuration: its sPLL, free-running frequency [Hz] and periodic input [Hz]."""

    name: str
    params: SpllParams
    free_freq: float = 100.0
    input_freq: float = 110.0
    duration: float = 1.0

    def network(self) -> Network:
        return Network.single(self.params, free_frequency=self.free_freq)

    def inputs(self) -> np.ndarray:
        return periodic_spikes(self.input_freq, self.duration)


CASES: tuple[Case, ...] = (
    Case("reference (thesis-like)", BASE),
    Case("synapse 1000x faster than membrane",
         replace(BASE, tau_cco_syn=5e-5, tau_tde_trg=4.5e-6, g_cco=500.0, g_tde_trg=500.0)),
    Case("synapse 1000x slower than membrane",
         replace(BASE, tau_cco_syn=50.0, tau_tde_trg=4.5, g_cco=0.005, g_tde_trg=1e-2)),
    Case("equal time constants", replace(BASE, tau_cco_syn=0.05, tau_tde_trg=4.5e-3)),
    Case("nearly equal time constants",
         replace(BASE, tau_cco_syn=0.05 * (1 + 1e-9), tau_tde_trg=4.5e-3 * (1 - 1e-9))),
    Case("huge gains", replace(BASE, g_tde_fac=1e6, g_tde_trg=5.0, g_cco=1e3)),
    Case("input at 1/t_refr", BASE, free_freq=500.0, input_freq=1000.0),
    Case("microsecond time constants",
         replace(BASE, tau_tde_trg=1e-6, tau_tde=3e-6, g_tde_trg=1e3)),
)  # fmt: skip


@dataclass(frozen=True)
class Outcome:
    case: str
    spec: str
    verdict: str  # "ok", "diverges" or "breaks"
    detail: str


def check(
    specs: Sequence[str], cases: Sequence[Case] = CASES, tolerance: float = 0.02
) -> list[Outcome]:
    """Run every case on every backend spec and judge it against the golden model."""
    out = []
    for case in cases:
        net, x = case.network(), case.inputs()
        truth = simulate(net, x, case.duration)
        for spec in specs:
            try:
                r = backends.run(spec, net, x, case.duration)
            except Exception as exc:  # a backend failing on a case is a result, not a crash
                out.append(Outcome(case.name, spec, "breaks", f"{type(exc).__name__}: {exc}"))
                continue
            errs = [
                abs(int(r.tde_counts[0]) - int(truth.tde_counts[0])) / max(1, truth.tde_counts[0]),
                abs(int(r.cco_counts[0]) - int(truth.cco_counts[0])) / max(1, truth.cco_counts[0]),
            ]
            verdict = "ok" if max(errs) <= tolerance else "diverges"
            detail = (f"TDE {r.tde_counts[0]} vs {truth.tde_counts[0]}, "
                      f"CCO {r.cco_counts[0]} vs {truth.cco_counts[0]}")  # fmt: skip
            warnings = r.info.get("warnings", ())
            if warnings:
                detail += "; " + "; ".join(warnings)
            out.append(Outcome(case.name, spec, verdict, detail))
    return out


def markdown(outcomes: Sequence[Outcome]) -> str:
    """Cases (rows) × backends (columns), each cell the verdict; details listed below."""
    cases = list(dict.fromkeys(o.case for o in outcomes))
    specs = list(dict.fromkeys(o.spec for o in outcomes))
    cell = {(o.case, o.spec): o for o in outcomes}
    lines = ["| case | " + " | ".join(f"`{s}`" for s in specs) + " |",
             "|---" * (len(specs) + 1) + "|"]  # fmt: skip
    for c in cases:
        lines.append(f"| {c} | " + " | ".join(cell[c, s].verdict for s in specs) + " |")
    lines.append("")
    lines += [f"- {o.case} / `{o.spec}`: {o.verdict} — {o.detail}" for o in outcomes]
    return "\n".join(lines)
