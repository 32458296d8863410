"""How the export check (:mod:`spll_hw.exporters.check`) runs a NIR folder again: the
``read_back`` of ``spll-hw export --to nir`` and ``--to nir-standard``.

* ``nir``: ``network.nir`` read back with spll-hw's NIR reader (:func:`~mappings.nir.read_nir`,
  the only reader that knows the gate node) and run in the golden model, which is what the
  graph states: the check measures the round trip, and passes only with identical rates.
* ``nir-standard``: ``network.nir`` run by spll-hw's executor of the clocked NIR consumers'
  stepping (:mod:`mappings.nir.executor`; snnTorch and Norse compute the same spikes,
  ``tests/test_standard_nir.py``) at the file's own ``dt``; its tolerance is ``nir-numpy``'s
  at that ``dt``. A folder whose ``network.nir`` reads back as the graph ``nir-numpy`` builds
  for the network (:func:`~mappings.nir.files.graph_difference`) runs as that backend does,
  so the check the export ran from memory while choosing its ``dt`` is the folder's
  (:attr:`~spll_hw.exporters.FolderRun.reads_as`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from spll_hw import backends
from spll_hw.exporters import FolderCost, FolderRun
from spll_hw.exporters.dt_ladder import more_levels
from spll_hw.network import Network

from .consumers import STEPS_RUN, run_consumer
from .dt_choice import LADDER
from .exact import read_nir
from .files import GRAPH_FILE, graph_difference, read_graph
from .neuron_graph import nir_graph
from .standard import EXPORT_LEVELS


def read_exact(folder: str | Path, network: Network) -> FolderRun:
    """The ``read_back`` of ``--to nir`` (module docstring); ``network`` is not used: the file
    holds its own."""
    read = read_nir(Path(folder) / GRAPH_FILE)
    return FolderRun.by_backend(
        "`network.nir` read back with spll-hw's NIR reader (mappings.nir.read_nir) and run in "
        "the golden model",
        backends.get("golden"),
        read,
        ["export again: the graph read back is not the network in params.toml (was network.nir "
         "edited, or written by another spll-hw version?)"],
    )  # fmt: skip


def read_standard(folder: str | Path, network: Network) -> FolderRun:
    """The ``read_back`` of ``--to nir-standard`` (module docstring)."""
    folder = Path(folder)
    graph = read_graph(folder / GRAPH_FILE)
    info_path = folder / "standard.json"
    try:
        info = json.loads(info_path.read_text())
        gate = info["gate"]
        options = {"levels": int(gate["levels"]), "placement": str(gate["placement"]),
                   "refractory": str(info["refractory"])}  # fmt: skip
    except (OSError, KeyError, ValueError) as exc:
        raise ValueError(
            f"{info_path}: not the standard.json of a nir-standard export: {exc}"
        ) from exc
    dt = float(np.asarray(graph.metadata["dt"]))
    backend = backends.get("nir-numpy", dt=dt, **options)
    ladder = ", ".join(f"{step * 1e6:g}" for step in LADDER)
    return FolderRun(
        runs=f"`network.nir` run by spll-hw's executor of the NIR consumers' stepping "
        f"(mappings/nir/executor.py, whose stepping snnTorch's and Norse's imports follow, in "
        f"float32) at the file's dt = {dt:g} s",
        backend=backend,
        simulate=lambda trains, duration: run_consumer("numpy", graph, trains, duration),
        remedies=(
            f"a smaller --dt than {dt:g} s (the clock's error falls with dt; {STEPS_RUN}), "
            f"or no --dt: the export then takes the coarsest of {ladder} µs whose check "
            "passes, or says why none does",
            more_levels(options["levels"], "mappings.nir.standard.to_standard_nir",
                        EXPORT_LEVELS),
            "another construction: --to lava-standard (Loihi's integers at 10 µs) or --to nir "
            "(the exact sPLL, run by spll-hw's NIR reader)",
        ),
        # the folder runs as nir-numpy runs the network where the file holds, to the bit, the
        # graph nir-numpy builds for it (kept by the backend that built it: not built again)
        reads_as=lambda same_rules, net: graph_difference(
            graph, same_rules.prepared(net).graph) is None,
    )  # fmt: skip


def cost_exact(folder: str | Path, network: Network) -> FolderCost:
    """The ``cost_of`` of ``--to nir``: the two-compartment sPLL of ``network.nir``, a
    continuous-time graph with no step of its own (costed at a clocked profile's own)."""
    return FolderCost(
        "the two-compartment sPLL (a TDE and a CCO per sPLL) of network.nir, run by its "
        "golden model (a continuous-time graph: costed at the profile's own step)"
    )


def cost_standard(folder: str | Path, network: Network) -> FolderCost:
    """The ``cost_of`` of ``--to nir-standard``: every neuron and synapse of ``network.nir``
    (:func:`mappings.nir.neuron_graph.nir_graph`) at the file's ``dt``."""
    graph = nir_graph(read_graph(Path(folder) / GRAPH_FILE))
    return FolderCost(
        f"every neuron and synapse of the standard construction in network.nir "
        f"({graph.description})",
        graph.dts[0],
        None,
        graph,
    )
