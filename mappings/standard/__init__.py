"""The sPLL from standard neurons: exports that chip toolchains and NIR consumers run as they are.

* :mod:`.construction`: the TDE's multiplicative gate from standard neurons, a K-level
  multiplier of level (comparator) and AND (coincidence) neurons, and where its levels go;
* :mod:`.reference`: the construction on a fine clock with exact integration between steps,
  so what the construction itself costs against the golden model is measurable per K;
* :mod:`.nir_graph`, :mod:`.nir_run`, :mod:`.consumers`, :mod:`.exporters`: the construction
  as a NIR graph of standard nodes only (``spll-hw export --to nir-standard``), a numpy executor
  of the clocked consumers' rules, and runs in snnTorch and Norse;
* :mod:`.lava_params`, :mod:`.lava_run`, :mod:`.lava_export`: the construction on lava-nc's
  own LIF and Dense processes in Loihi's integers (``--to lava-standard``), the project's
  bit-accurate reference of them, and the self-contained ``run.py``;
* :mod:`.backend`: ``standard-exact`` (the gate in the golden engine, event by event),
  ``nir-numpy``, ``nir-snntorch``, ``nir-norse``, ``standard-fixed-point`` and
  ``lava-standard`` backends.
"""

from .construction import DEFAULT_LEVELS, DEFAULT_PLACEMENT, PLACEMENTS, Gate, gate_levels

__all__ = ["DEFAULT_LEVELS", "DEFAULT_PLACEMENT", "PLACEMENTS", "Gate", "gate_levels"]
