"""The sPLL from standard neurons: a construction, one variant of every target's export.

The construction lives here, in the core; its targets live with the exact sPLL's, in the
target's package, and share that package's writer and runner:

* :mod:`.gate`: the TDE's multiplicative gate from standard neurons, a K-level multiplier of
  level (comparator) and AND (coincidence) neurons, where its levels go, and the
  self-inhibition that stands in for refractory periods where a target has none;
* :mod:`.reference`: the construction on a fine clock with exact integration between steps,
  so what the construction itself costs against the golden model is measurable per K.

Beside them in the core: ``standard-exact`` (the gate in the golden engine, event by event,
and what the clocked targets' backends share) is :mod:`spll_hw.backends.standard_exact`, and
the time step of a clocked export, chosen by the export's own check, is
:mod:`spll_hw.exporters.dt_ladder`. None of them imports a mapping folder: the targets import
them. The targets' backends live beside their writers (``nir-numpy``, ``nir-snntorch``,
``nir-norse`` in :mod:`mappings.nir.standard_backend`; ``standard-fixed-point``,
``lava-standard`` in :mod:`mappings.lava.standard_backend`), as do the graphs a chip costs
(:mod:`mappings.nir.neuron_graph`, :mod:`mappings.lava.neuron_graph`).

Its targets:

* NIR (``spll-hw export --to nir-standard``): the graph of standard nodes is
  :mod:`mappings.nir.standard`, written by :mod:`mappings.nir`'s one writer; the numpy
  executor of the clocked consumers' rules is :mod:`mappings.nir.executor`, runs in snnTorch
  and Norse :mod:`mappings.nir.consumers`.
* Lava (``--to lava-standard``): the integers on Lava's own LIF and Dense are
  :mod:`mappings.lava.standard`, their bit-accurate numpy executor :mod:`mappings.lava.loihi`,
  the folder is written by :mod:`mappings.lava.export` and run by :mod:`mappings.lava.run`
  (the folder's self-contained ``run.py`` is :mod:`mappings.lava.standalone_run`).
"""

from .gate import DEFAULT_LEVELS, DEFAULT_PLACEMENT, PLACEMENTS, Gate, GateOptions, gate_levels

__all__ = [
    "DEFAULT_LEVELS",
    "DEFAULT_PLACEMENT",
    "PLACEMENTS",
    "Gate",
    "GateOptions",
    "gate_levels",
]
