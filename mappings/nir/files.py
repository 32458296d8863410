"""NIR files, written and read one way for both graphs (:mod:`.exact`, :mod:`.standard`).

The ``nir`` package is an optional dependency (``pip install -e '.[nir]'``), imported only when a
graph is built, written or read (:func:`nir_package`).
"""

from __future__ import annotations

import dataclasses
import io
from pathlib import Path

import numpy as np

from mappings.folder import ExportFolder
from spll_hw.files import writing

INSTALL_HINT = "pip install -e '.[nir]'"
#: The graph's file in an export folder.
GRAPH_FILE = "network.nir"
#: The clocked graph's loader in its folder (:mod:`.loader`): each consumer at the file's step.
LOADER_FILE = "load_consumer.py"


def nir_package(what: str = "NIR export"):
    """The ``nir`` module; ``ImportError`` naming ``what`` needs it and how to install it."""
    try:
        import nir
    except ImportError as exc:
        raise ImportError(f"{what} needs the nir package: {INSTALL_HINT}") from exc
    return nir


def write_graph(path: str | Path, graph) -> Path:
    """Write the NIR graph ``graph`` to the file ``path``: serialised by HDF5 in memory, then
    written with one plain write, so that a full disk is one ``OSError`` naming ``path``
    (HDF5 writing to a full disk itself raises ``RuntimeError`` from its cleanup, and on a
    large graph crashes the process); ``ValueError`` where ``nir`` cannot serialise it."""
    nir = nir_package()
    buffer = io.BytesIO()
    try:
        nir.write(buffer, graph)
    except RuntimeError as exc:  # an HDF5 failure in memory: no disk involved
        raise ValueError(f"{path}: HDF5 could not serialise the NIR graph: {exc}") from exc
    with writing(path) as target:
        target.write_bytes(buffer.getbuffer())
    return Path(path)


def as_imported(nodes: dict) -> dict:
    """``nodes`` (name -> NIR node) with every float array's values rounded to float32, kept as
    float64 arrays: the values the consumers' NIR imports read (Norse's and snnTorch's build
    float32 tensors), so that spll-hw's executor, whose runs are the folder's check, runs the
    parameters the consumers run. A slow sPLL near the edge of lock counts otherwise: rounded
    alone, the tuned time-scaled network's sPLL 15 fired 76 TDE spikes on a 41.6-Hz Poisson
    input against 159 (docs/notes/2026-12-06-consumer-parameters.md)."""

    def rounded(value):
        if isinstance(value, np.ndarray) and np.issubdtype(value.dtype, np.floating):
            return value.astype(np.float32).astype(np.float64)
        return value

    return {
        name: dataclasses.replace(
            node,
            **{f.name: rounded(getattr(node, f.name)) for f in dataclasses.fields(node) if f.init},
        )
        for name, node in nodes.items()
    }


def read_graph(path: str | Path):
    """The ``nir.NIRGraph`` in the NIR (HDF5) file ``path``; ``FileNotFoundError`` or
    ``ValueError`` naming the file when there is none or it is not one."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such NIR file")
    nir = nir_package()
    try:
        return nir.read(path)
    except (OSError, KeyError, ValueError) as exc:
        raise ValueError(f"{path}: not a readable NIR file: {exc}") from exc


def graph_difference(a, b) -> str | None:
    """Where NIR graph ``a`` first differs from ``b`` (``"node c_level: tau_syn"``, say), or
    ``None`` where they are the same graph: the same nodes of the same types with equal
    fields (arrays equal element for element, bit for bit), the same edges and metadata. A
    graph read back from a file equals the graph written (``nir.read`` returns metadata
    numbers as numpy scalars, which compare equal to the numbers written)."""
    if sorted(a.nodes) != sorted(b.nodes):
        return f"nodes {sorted(a.nodes)} against {sorted(b.nodes)}"
    for name in sorted(a.nodes):
        x, y = a.nodes[name], b.nodes[name]
        if type(x) is not type(y):
            return f"node {name}: {type(x).__name__} against {type(y).__name__}"
        for f in dataclasses.fields(x):
            if not _same(getattr(x, f.name), getattr(y, f.name)):
                return f"node {name}: {f.name}"
    if sorted(map(tuple, a.edges)) != sorted(map(tuple, b.edges)):
        return "edges"
    return None if _same(a.metadata, b.metadata) else "metadata"


def _same(x, y) -> bool:
    """Whether two field values of NIR nodes are equal (dicts key by key, arrays and numbers
    element for element with equal shapes)."""
    if isinstance(x, dict) or isinstance(y, dict):
        return (isinstance(x, dict) and isinstance(y, dict) and x.keys() == y.keys()
                and all(_same(x[k], y[k]) for k in x))  # fmt: skip
    if isinstance(x, str) or isinstance(y, str):
        return x == y
    x, y = np.asarray(x), np.asarray(y)
    return x.shape == y.shape and bool(np.array_equal(x, y))


def write_folder(
    out: str | Path, graph, *, info: dict | None = None, readme: str | None = None
) -> list[Path]:
    """Write an export folder ``out``: ``network.nir`` (``graph``, a ``nir.NIRGraph``) and, for
    a clocked graph (``info`` given), ``standard.json`` (``info``: what the graph was built
    from and its conventions), ``README.md`` (``readme``), ``spll_grid.py`` (the grid rule
    its inputs are binned by), ``check_consumer.py`` and ``check_counts.py`` (which run the
    export check's inputs in Norse or snnTorch and compare their counts with ``check.json``),
    ``load_consumer.py`` (which loads the graph in them at its step).
    Returns the files in that order."""
    nir_package()
    with ExportFolder(out) as folder:
        write_graph(folder.file(GRAPH_FILE), graph)
        if info is not None:
            folder.json("standard.json", info)
            folder.text("README.md", readme or "")
            folder.grid()
            folder.copy("check_consumer.py", Path(__file__).with_name("standalone_check.py"))
            folder.counts()
            folder.copy(LOADER_FILE, Path(__file__).with_name("loader.py"))
    return folder.files
