"""Lava backend: the sPLL network as Lava processes, run on Lava's CPU simulator.

* :mod:`~mappings.lava.process`: the CCO and TDE as custom Lava Processes with ports for the
  facilitatory input, the trigger input and the feedback; the input comes from Lava's spike
  generator (``RingBuffer``) through a fan-out ``Dense``, the feedback through a ``Dense``.
* :mod:`~mappings.lava.models_float` (tag ``floating_pt``) and :mod:`~mappings.lava.models_fixed`
  (tag ``fixed_pt``, bit-accurate Loihi-2-like integers) implement them; the discrete-time model
  and the quantization are in :mod:`~mappings.lava.parameters`.
* :func:`simulate_lava` runs a :class:`~spll_hw.network.Network` with ``Loihi2SimCfg`` and returns
  the golden engine's :class:`~spll_hw.result.SimulationResult`; :func:`export_lava` writes the
  processes' parameters to a folder that :func:`load_export` turns back into processes.

How the trigger gating maps to a programmable-neuron chip. The TDE's trigger synapse does not
add a fixed weight: a CCO spike adds ``g_tde_trg * I_fac``, a product of a constant and another
state of the same neuron. Lava's standard ``LIF`` + ``Dense`` cannot express that (a ``Dense``
weight is constant), hence the custom TDE. On a chip with programmable neurons (Loihi 2 runs
neuron models as microcode) the TDE is one neuron with three state registers (``i_fac``, ``u``,
``v``) and two input channels: the fan-out's weighted input spikes accumulate into the first
dendritic accumulator, the CCO's spikes (a unit weight) into the second. Each time step the
program decays the three states, reads the second accumulator and, if it is nonzero, adds
``(i_fac * gate_mant) >> gate_shift`` to ``u`` (one multiply and one shift), adds the first
accumulator to ``i_fac``, integrates ``v`` and compares it with the threshold: exactly
:class:`~mappings.lava.models_fixed.PyTdeModelFixed`. On a chip with fixed LIF neurons only, the
gate needs a graded spike: the CCO would have to send ``I_fac`` as its payload, which it does
not know, so such chips need the facilitatory current mirrored in the CCO's neuron instead.

lava-nc 0.10 needs ``pip install --ignore-requires-python -e '.[lava]'`` on Python 3.11 and the
import-time fix of :mod:`mappings.lava.compat`, which importing this package installs; Lava is
imported only when a simulation is built, so this package imports without it.
"""

from . import compat

compat.install()

#: Names served lazily from the modules that import Lava.
_LAZY = {
    "simulate_lava": "run",
    "build": "run",
    "export_lava": "export",
    "load_export": "export",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["compat", *_LAZY]
