"""The part each parameter plays in one sPLL, read from the model's tables.

A target that builds the sPLL from other parts (NIR nodes, Lava processes, a gate of standard
neurons, a clocked simulator) needs to know which parameter is the facilitatory synapse's time
constant, which the trigger's gain, and so on. :func:`roles` reads that from
:mod:`.equations` once, so a target names roles (``r.fac.tau``, ``r.gated.gain``,
``r.cco.v_thr``) instead of parameter names, and a change to the model's tables reaches it::

    r = roles()
    p = dict(zip(PARAM_NAMES, network.matrix().T))      # parameter name -> (N,) array
    decay_fac = np.exp(-dt / p[r.fac.tau])              # the facilitatory synapse
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from .equations import CCO, TDE, Jump, Membrane, Synapse, constant_drive, jump, synapse


@dataclass(frozen=True)
class Roles:
    """The model's parts, by what they do in an sPLL (each field names parameters)."""

    #: a CCO spike into the TDE's trigger current, times the facilitatory current
    gated: Jump
    #: an input spike into the TDE's facilitatory current
    driven: Jump
    #: a TDE spike into the CCO's synapse current
    fed: Jump
    #: the TDE's facilitatory synapse (the gate's input)
    fac: Synapse
    #: the TDE's trigger synapse (its membrane's drive)
    trg: Synapse
    #: the CCO's synapse
    cco_syn: Synapse
    #: the TDE's membrane
    tde: Membrane
    #: the CCO's membrane
    cco: Membrane
    #: the CCO's constant drive (its offset current)
    offset: str

    @property
    def time_constants(self) -> tuple[str, ...]:
        """Every time constant: the three synapses', then the TDE's and the CCO's membrane."""
        return (self.fac.tau, self.trg.tau, self.cco_syn.tau, self.tde.tau, self.cco.tau)


@functools.cache
def roles() -> Roles:
    """The :class:`Roles` of :mod:`.equations` (``ValueError`` if the tables no longer have
    the structure targets build: one jump per source, the gate on the input's current)."""
    gated, driven, fed = jump("cco"), jump("input"), jump("tde")
    if driven.current != gated.factor or gated.target != driven.target:
        raise ValueError("the model's gate is not the facilitatory current of the input jump")
    if gated.target != TDE.name or fed.target != CCO.name:
        raise ValueError("the model's jumps no longer go CCO -> TDE and TDE -> CCO")
    (offset,) = constant_drive(CCO)
    return Roles(
        gated=gated,
        driven=driven,
        fed=fed,
        fac=synapse(TDE, gated.factor),
        trg=synapse(TDE, gated.current),
        cco_syn=synapse(CCO, fed.current),
        tde=TDE.membrane,
        cco=CCO.membrane,
        offset=offset,
    )
