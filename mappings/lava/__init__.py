"""Lava: the sPLL network as Lava processes, run on Lava's CPU simulator, in two constructions.

The exact sPLL on spll-hw's own TDE and CCO processes (backends ``lava-float``, ``lava-fixed``;
``spll-hw export --to lava``):

* :mod:`~mappings.lava.processes.process`: the CCO and TDE as custom Lava Processes with ports for
  the facilitatory input (``TDE.fac_in``), the trigger input (``TDE.trg_in``) and the feedback
  (``CCO.fb_in``); the input comes from Lava's spike generator (``RingBuffer``) through a fan-out
  ``Dense``, the feedback through a diagonal ``Dense``: standard processes wherever they express
  the behaviour exactly.
* :mod:`~mappings.lava.processes.models_float` (tag ``floating_pt``) and
  :mod:`~mappings.lava.processes.models_fixed` (tag ``fixed_pt``) implement them. Both run the
  discrete-time algorithm of ``quantize``'s fixed-point reference (``engine/src/fixed_point.rs``,
  summarised in :mod:`~mappings.lava.parameters`): in real numbers, or bit-accurately on the
  integers of ``quantize.quantize(network, "loihi2")``, spike for spike equal to the
  ``golden-fixed-point`` backend.
* :func:`simulate_lava` runs a :class:`~spll_hw.network.Network` with ``Loihi2SimCfg`` (every
  process in its own OS process) and returns the golden engine's
  :class:`~spll_hw.result.SimulationResult`; the backend registry names it ``lava-float`` and
  ``lava-fixed``. :func:`export_lava` writes the processes' parameters to a folder and
  :func:`load_export` reads them back for :func:`simulate_lava` or :func:`build`.

The standard construction (:mod:`spll_hw.construction.gate`) on Lava's own ``LIF`` and
``Dense`` in Loihi's integers (backends ``lava-standard``, ``standard-fixed-point``;
``--to lava-standard``):

* :mod:`~mappings.lava.standard`: the integers (:func:`~mappings.lava.standard.lava_standard`);
* :mod:`~mappings.lava.integers`: Loihi's integer arithmetic they are computed with (decays,
  thresholds, weights, biases, the refractory units);
* :mod:`~mappings.lava.loihi`: Loihi's LIF and Dense arithmetic (in the Rust core), their
  bit-accurate executor;
* :mod:`~mappings.lava.standalone_run`: the exported folder's self-contained ``run.py``;
* :mod:`~mappings.lava.clocks`: a clock per set of sPLLs (each refractory period held in
  exactly ``R + 1/2`` steps), the export's last rung where no one step passes.

Shared by both: :mod:`~mappings.lava.export` is the one folder writer (``export_lava``,
``write_standard``), :mod:`~mappings.lava.exporter` holds the two ``spll-hw export`` entry
points, :mod:`~mappings.lava.run` runs the exact processes (``simulate_lava``),
:mod:`~mappings.lava.standard_backend` an exported standard folder (``simulate_lava_standard``).

How the trigger gating maps to a programmable-neuron chip. The TDE's trigger synapse does not add a
fixed weight: a CCO spike adds ``g_tde_trg * I_fac``, the product of a constant and a state of the
receiving neuron. A ``Dense`` weight is constant, so Lava's standard ``LIF`` + ``Dense`` cannot
express it; hence the custom TDE. On a chip with programmable neurons (Loihi 2 runs neuron models as
microcode) the TDE is one neuron with three state words (``i_fac``, the trigger current ``u``, the
potential ``v``) and two inputs: the fan-out's weighted input spikes accumulate into one dendritic
accumulator, the CCO's 1-bit spikes into another. Each time step its program reads the trigger
accumulator and, if it is set, computes ``(i_fac * gate) >> gate_shift`` (one 24 x 8-bit multiply
and a barrel shift) and adds it to the decayed ``u``; it then decays ``i_fac`` and adds the input
accumulator, integrates ``v`` with ``u >> current_shift`` and compares it with the threshold:
exactly :class:`~mappings.lava.processes.models_fixed.PyTdeModelFixed`. The CCO is a standard
current-based LIF neuron with bias and refractory period (with ``current_shift = 0``, Loihi's own
compartment). On a chip without a multiplier the product needs graded spikes: a compartment holding
``i_fac`` sends it as the payload of a graded spike when the trigger arrives, and a synapse of
weight ``gate`` with exponent ``-gate_shift`` delivers it to ``u``.

lava-nc 0.10 needs ``pip install --ignore-requires-python -e '.[lava]'`` on Python 3.11 and the
import-time fix of :mod:`mappings.lava.compat`, which importing this package installs; Lava is
imported only when a network is built, so this package imports without it.
"""

import importlib

from . import compat

compat.install()

#: Names served lazily from the modules that import Lava.
_LAZY = {
    "simulate_lava": "run",
    "simulate_lava_batch": "run",
    "build": "run",
    "build_batch": "run",
    "export_lava": "export",
    "load_export": "export",
}


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["compat", *_LAZY]
