"""NIR export: an sPLL network as a Neuromorphic Intermediate Representation graph.

:func:`to_nir` turns a :class:`~spll_hw.network.Network` into a ``nir.NIRGraph`` (CCO as a
``CubaLIF`` node with its offset current as bias, the TDE as a documented composite of standard
nodes plus one extension node), :func:`from_nir` reads such a graph back, and
:func:`write_nir` / :func:`read_nir` go through NIR's HDF5 file format. The ``nir`` package is an
optional dependency (``pip install -e '.[nir]'``), imported only when a function runs. The graph
layout and its semantics are documented in :mod:`mappings.nir.graph`.
"""

from pathlib import Path

from .graph import FORMAT, from_nir, read_nir, to_nir, write_nir


def export_folder(network, out: str | Path, *, profile=None, dt=None) -> list[Path]:
    """network.nir: NIR graph (HDF5; the TDE gate in metadata, so running it needs spll-hw's
    reader mappings.nir.read_nir).

    The ``spll_hw.exporters`` entry point of ``spll-hw export --to nir``. The graph is the
    continuous-time float network: ``profile`` and ``dt`` do not apply and raise ``ValueError``.
    """
    if profile is not None or dt is not None:
        raise ValueError("NIR export is the continuous-time float network: drop --profile/--dt")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    return [write_nir(network, out / "network.nir")]


__all__ = ["FORMAT", "export_folder", "from_nir", "read_nir", "to_nir", "write_nir"]
