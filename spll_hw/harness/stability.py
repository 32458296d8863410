"""Stiff and extreme parameters through every backend, the golden model as truth.

Each case is a one-sPLL network pushed to an edge of the parameter space (time-constant ratios
of 1e-3 and 1e3, equal and nearly equal synapse/membrane constants, huge gains, input at the
refractory limit, microsecond time constants). Every backend runs it; its outcome is ``ok``
(TDE and CCO counts within ``tolerance`` of golden, or within ``slack`` spikes: a clocked
backend may move one spike across the end of the run), ``diverges`` (counts off by more), or
``breaks`` (it raised an error) — with the backend's own warnings attached. A user's own network
can be added as a case (:meth:`Case.of_network`).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np

from .. import backends
from ..activity import SilentNetworkWarning
from ..network import Network
from ..params import SpllParams
from ..simulate import periodic_spikes, simulate

BASE = SpllParams(
    tau_cco_syn=7.5e-3, tau_cco=0.05, tau_tde_trg=1.25e-3, tau_tde_fac=9.6e-3, tau_tde=4.5e-3,
    g_cco=5.0, g_tde_trg=0.5, g_tde_fac=2000.0,
)  # fmt: skip


@dataclass(frozen=True)
class Case:
    """One extreme configuration: its sPLL, free-running frequency [Hz], periodic input [Hz]
    and run length [s]; or a whole network given as it is (``given``)."""

    name: str
    params: SpllParams | None
    free_freq: float = 100.0
    input_freq: float = 110.0
    duration: float = 1.0
    given: Network | None = None

    @classmethod
    def of_network(cls, name: str, network: Network, input_freq: float, duration: float):
        """A case of a user's ``network`` under periodic input at ``input_freq`` [Hz]."""
        return cls(name, None, input_freq=input_freq, duration=duration, given=network)

    def network(self) -> Network:
        if self.given is not None:
            return self.given
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


def diverges(counts, truth, tolerance: float, slack: int) -> bool:
    """Whether spike counts (any shape) are off the golden ``truth`` by more than both
    ``slack`` spikes and the relative ``tolerance``, in any neuron."""
    diff = np.abs(np.asarray(counts, dtype=np.int64) - np.asarray(truth, dtype=np.int64))
    return bool(np.any((diff > slack) & (diff > tolerance * np.asarray(truth))))


def check(
    specs: Sequence[str], cases: Sequence[Case] = CASES, tolerance: float = 0.02,
    slack: int = 1, on_outcome=None,
) -> list[Outcome]:  # fmt: skip
    """Run every case on every backend spec and judge it against the golden model: ``ok``
    unless a TDE or CCO count is off by more than ``slack`` spikes *and* by more than the
    relative ``tolerance``. ``on_outcome(outcome)`` is called as each one is known."""
    out = []
    for case in cases:
        net, x = case.network(), case.inputs()
        with _edges_are_meant():
            truth = simulate(net, x, case.duration)
        for spec in specs:
            try:
                with _edges_are_meant():
                    r = backends.run(spec, net, x, case.duration)
            except Exception as exc:  # a backend failing on a case is a result, not a crash
                outcome = Outcome(case.name, spec, "breaks", f"{type(exc).__name__}: {exc}")
            else:
                bad = any(
                    diverges(getattr(r, k), getattr(truth, k), tolerance, slack)
                    for k in ("tde_counts", "cco_counts")
                )
                detail = ", ".join(
                    f"{k.upper()} {_counts(getattr(r, f'{k}_counts'))} vs "
                    f"{_counts(getattr(truth, f'{k}_counts'))}"
                    for k in ("tde", "cco")
                )
                warnings = r.info.get("warnings", ())
                if warnings:
                    detail += "; " + "; ".join(warnings)
                outcome = Outcome(case.name, spec, "diverges" if bad else "ok", detail)
            out.append(outcome)
            if on_outcome is not None:
                on_outcome(outcome)
    return out


@contextmanager
def _edges_are_meant():
    """A context without :class:`~spll_hw.activity.SilentNetworkWarning`: the cases push
    sPLLs to silence and to their refractory limit on purpose."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SilentNetworkWarning)
        yield


def _counts(counts) -> str:
    """One sPLL's count as a number, several as their total (``sum 1234``)."""
    c = np.asarray(counts)
    return str(int(c[0])) if c.size == 1 else f"sum {int(c.sum())}"


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
