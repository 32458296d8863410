"""NIR export: an sPLL network as a Neuromorphic Intermediate Representation graph.

:func:`to_nir` turns a :class:`~spll_hw.network.Network` into a ``nir.NIRGraph`` (CCO as a
``CubaLIF`` node with its offset current as bias, the TDE as a documented composite of standard
nodes plus one extension node), :func:`from_nir` reads such a graph back, and
:func:`write_nir` / :func:`read_nir` go through NIR's HDF5 file format. The ``nir`` package is an
optional dependency (``pip install -e '.[nir]'``), imported only when a function runs. The graph
layout and its semantics are documented in :mod:`mappings.nir.graph`.
"""

from .graph import FORMAT, from_nir, read_nir, to_nir, write_nir

__all__ = ["FORMAT", "from_nir", "read_nir", "to_nir", "write_nir"]
