"""The continuous sPLL (thesis section 2.4.1, eqs. 1-6) as data: neurons, synapses, jumps.

One sPLL is two leaky integrate-and-fire neurons with current synapses, the CCO and the TDE.
Each synapse current decays, ``dI/dt = -I / tau`` (eqs. 1-3); each membrane integrates its
drive, ``dv/dt = drive / C - v / tau`` (eqs. 4-5), fires when ``v >= v_thr``, is reset to 0 and
held at 0 for ``t_refr`` while its currents keep decaying. Events make currents jump
(:data:`JUMPS`):

* an input spike adds ``g_tde_fac`` to the TDE's facilitatory current ``I_fac``;
* a CCO spike adds ``g_tde_trg * I_fac`` to the TDE's trigger current ``I_trg`` (the gain is
  *added*, multiplied by the facilitatory current at that instant, not integrated as g/tau);
* a TDE spike adds ``g_cco`` to the CCO's synapse current ``I``.

**Simultaneous events** (same instant): every state is first advanced to that instant, then the
jumps are applied in the order of :data:`JUMPS`, so a CCO spike meets the facilitatory current
from before any input of the same instant.

The parameter names are the columns of the network matrix (:data:`spll_hw.params.PARAM_NAMES`);
:data:`UNITS` gives each one's SI unit. Targets build their equations from these tables
(``mappings/brian2/model.py`` writes its Brian2 equations and ``on_pre`` statements from them).
"""

from __future__ import annotations

from dataclasses import dataclass

#: SI unit of every sPLL parameter (Brian2's unit names; ``"1"``: dimensionless).
UNITS: dict[str, str] = {
    "tau_cco_syn": "second",
    "tau_cco": "second",
    "c_cco": "farad",
    "g_cco": "amp",
    "i_cco_offset": "amp",
    "t_cco_refr": "second",
    "v_cco_thr": "volt",
    "tau_tde_fac": "second",
    "tau_tde_trg": "second",
    "tau_tde": "second",
    "c_tde": "farad",
    "g_tde_fac": "amp",
    "g_tde_trg": "1",
    "t_tde_refr": "second",
    "v_tde_thr": "volt",
}


@dataclass(frozen=True)
class Synapse:
    """A decaying current ``dI/dt = -I / tau``: state ``current`` [A], time constant ``tau``
    (a parameter name)."""

    current: str
    tau: str


@dataclass(frozen=True)
class Membrane:
    """``dv/dt = (sum of drive) / c - v / tau``; fires when ``v >= v_thr``, reset to 0, held at
    0 for ``t_refr``. Every field but ``drive`` names a parameter; ``drive`` names the currents
    (synapse states or parameters) that charge it."""

    drive: tuple[str, ...]
    tau: str
    c: str
    v_thr: str
    t_refr: str


@dataclass(frozen=True)
class Neuron:
    """One neuron of an sPLL: its synapses, its membrane and every parameter it holds
    (including the gains of the jumps into it)."""

    name: str
    synapses: tuple[Synapse, ...]
    membrane: Membrane
    parameters: tuple[str, ...]


@dataclass(frozen=True)
class Jump:
    """On a ``source`` spike (``"input"``, ``"cco"`` or ``"tde"``), the current ``current`` of
    neuron ``target`` gains ``gain`` (a parameter), times the target's state ``factor`` at that
    instant when one is given."""

    source: str
    target: str
    current: str
    gain: str
    factor: str | None = None


#: The current-controlled oscillator: synapse (eq. 1) and membrane with offset current (eq. 4).
CCO = Neuron(
    "cco",
    synapses=(Synapse("I", "tau_cco_syn"),),
    membrane=Membrane(("I", "i_cco_offset"), "tau_cco", "c_cco", "v_cco_thr", "t_cco_refr"),
    parameters=(
        "tau_cco_syn", "tau_cco", "c_cco", "i_cco_offset", "v_cco_thr", "t_cco_refr", "g_cco",
    ),
)  # fmt: skip

#: The temporal difference encoder: facilitatory and trigger synapses (eqs. 2-3), membrane (5).
TDE = Neuron(
    "tde",
    synapses=(Synapse("I_fac", "tau_tde_fac"), Synapse("I_trg", "tau_tde_trg")),
    membrane=Membrane(("I_trg",), "tau_tde", "c_tde", "v_tde_thr", "t_tde_refr"),
    parameters=(
        "tau_tde_fac", "tau_tde_trg", "tau_tde", "c_tde", "v_tde_thr", "t_tde_refr",
        "g_tde_fac", "g_tde_trg",
    ),
)  # fmt: skip

NEURONS: tuple[Neuron, ...] = (CCO, TDE)

#: The jumps, in the order they are applied to simultaneous events.
JUMPS: tuple[Jump, ...] = (
    Jump("cco", "tde", "I_trg", "g_tde_trg", factor="I_fac"),
    Jump("input", "tde", "I_fac", "g_tde_fac"),
    Jump("tde", "cco", "I", "g_cco"),
)


def jump(source: str) -> Jump:
    """The jump a ``source`` spike (``"input"``, ``"cco"`` or ``"tde"``) causes."""
    found = [j for j in JUMPS if j.source == source]
    if len(found) != 1:
        raise ValueError(f"the model has {len(found)} jumps from {source!r}, expected 1")
    return found[0]


def synapse(neuron: Neuron, current: str) -> Synapse:
    """The synapse of ``neuron`` whose state is ``current``."""
    for s in neuron.synapses:
        if s.current == current:
            return s
    raise ValueError(f"neuron {neuron.name!r} has no synapse current {current!r}")


def constant_drive(neuron: Neuron) -> tuple[str, ...]:
    """The parameters among the membrane's drive: constant currents (the CCO's offset), as
    opposed to synapse states."""
    states = {s.current for s in neuron.synapses}
    return tuple(d for d in neuron.membrane.drive if d not in states)
