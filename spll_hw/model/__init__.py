"""The sPLL model, stated once: what every simulator and export of spll-hw derives from.

* :mod:`.equations`: the continuous model (thesis eqs. 1-5) as data: the neurons, their
  synapses and membranes, the jumps events cause and their order at one instant, and the SI
  unit of every parameter. Eq. 6 (the free-running frequency) is :func:`free_frequency` and its
  inverse :func:`offset_for_frequency`.
* :mod:`.roles`: the part each parameter plays (the facilitatory synapse's time constant, the
  trigger's gain, ...), read from :mod:`.equations`, for targets that build the sPLL from parts.
* :mod:`.grid`: the time grid of every clocked target: the step an input spike arrives in, a
  run's number of steps, refractory periods on the grid, free-running periods in steps.
* :mod:`.holds`: the refractory holds a clocked neuron can use (grid, compensated, dithered,
  counter-dithered) and which target uses which.
* :mod:`.discrete`: the discretisations clocked targets use: exact-step decays, membrane gains,
  the exact one-step propagator, integer decay constants.

Who derives what from it (``docs/extending.md`` keeps the list):

* the golden engine (``engine/src/``) is the exact event-driven solution of :mod:`.equations`;
  it is Rust and cannot import this, so it is tested against it (an independent integrator,
  ``tests/reference_integrator.py``, and the analytic checks of ``tests/test_analytic.py``);
* the fixed-point model (``engine/src/fixed_point.rs``, ``quantize/fixed_point.py``) applies
  :mod:`.grid` and encodes with :mod:`.discrete`;
* Brian2 (``mappings/brian2/model.py``) writes its equations from :mod:`.equations` and bins its
  input with :mod:`.grid`;
* Lava (``mappings/lava/parameters.py``), the standard construction's reference
  (``spll_hw/construction/reference.py``), NIR executor (``mappings/nir/executor.py``) and Lava
  export (``mappings/lava/standard.py``, ``integers.py``) and the USB board (``mappings/usb``)
  take their grid from :mod:`.grid`, their refractory hold from :mod:`.holds` and their
  coefficients from :mod:`.discrete`.
"""

from .equations import CCO, JUMPS, NEURONS, TDE, UNITS, Jump, Membrane, Neuron, Synapse
from .frequency import free_frequency, offset_for_frequency

__all__ = [
    "CCO",
    "JUMPS",
    "NEURONS",
    "TDE",
    "UNITS",
    "Jump",
    "Membrane",
    "Neuron",
    "Synapse",
    "free_frequency",
    "offset_for_frequency",
]
