"""Run a standard-sPLL NIR graph in third-party consumers: snnTorch, Norse, or spll-hw's executor.

Each consumer loads the graph with its own NIR import (``snntorch.import_nir.import_from_nir``,
``norse.torch.from_nir(graph, dt=...)``) and steps it once per ``dt`` of the graph's
``metadata["dt"]``; the input is the count of input spikes in each step (a spike at ``t``
counts in step ``max(1, ceil(t/dt))``), the output row ``k`` the TDE and CCO spikes of step
``k`` (reported at ``k dt``). ``"numpy"`` is spll-hw's own executor,
:func:`~mappings.nir.executor.chunks_nir` (in the Rust core since 2026-12-07; the name is
that of its first, numpy, implementation), which follows the same rules a few thousand steps
at a time (a check of 10 s at 1 µs would hold 10^7 steps of output in memory at once: 48 GB
for its six inputs).
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from spll_hw.neuron_graph import COUNTS_KEY
from spll_hw.result import SimulationResult

from .executor import chunks_nir, input_steps, neuron_nodes
from .files import read_graph
from .loader import load_module, run

#: Consumers :func:`run_consumer` knows, with the modules each needs.
CONSUMERS = {"numpy": ("nir",), "snntorch": ("snntorch", "torch", "nir"), "norse": ("norse",)}
#: The one time step [s] snnTorch's NIR import steps by: it takes no ``dt`` and assumes this.
SNNTORCH_DT = 1e-4
#: Why Spyx (1.0.0) cannot run the graph, whatever its node names.
SPYX_UNSUPPORTED = (
    "Spyx cannot run it: its NIR import (spyx.nir.from_nir) builds a Sequential chain by "
    "following the first edge from a node named `input` to one named `output` and reads only "
    "thresholds and decays (not r, w_in, v_leak, v_reset); this graph has loops "
    "(e_gate -> f_synapses -> g_spll -> h_refractory -> i_spikes -> j_fanout -> e_gate), which "
    "no chain holds. Named "
    "`a_input` here, it loads as an empty model; renamed, it would load a chain without the "
    "feedback and run silently wrong"
)

#: What the folder says of Norse: its loader runs it in float64 on the file's values (float32,
#: as its import reads them: :func:`~mappings.nir.files.as_imported`), the executor's arithmetic
#: on the executor's parameters; measured (docs/notes/2026-12-06-consumer-parameters.md) at
#: 50 µs on ``biotac-tuned-time-scaled-lif`` (2026-12-06), where it had failed in float32, and
#: at 1 µs on ``vibtac-time-scaled-peak`` (2026-12-07), where float32 had been 15-42 % off.
NORSE_EXACT = (
    ", computing in float64 on the file's float32 values as check.json's run does (every "
    "sPLL's counts within 1 spike of check.json's at 50 µs on biotac-tuned-time-scaled-lif and "
    "at 1 µs on vibtac-time-scaled-peak)"
)
#: The finest step [s] at which the folder names Norse as running the graph: the finest the
#: step ladder writes (``mappings.nir.dt_choice.LADDER``), where the loader's float64 was
#: measured (:data:`NORSE_EXACT`); a finer ``--dt`` is not measured, so the folder does not
#: promise Norse there. (In float32, below 20 µs a CCO's current beside its refractory unit's
#: force kept too few bits: docs/notes/2026-11-28-norse-below-20us.md.)
NORSE_MIN_DT = 1e-6

#: Which consumers run which steps, in a sentence (refusals and remedies say it).
STEPS_RUN = (
    f"nir-numpy runs any dt, Norse down to {NORSE_MIN_DT:g} s, snnTorch only {SNNTORCH_DT:g} s"
)

#: What the folder says of snnTorch (float32 arithmetic) at its step: measured 2026-11-28
#: (docs/backends.md, "The start pulse"), its totals are check.json's within 0.2 %, and on a
#: few inputs one slow sPLL near the edge of lock may not be.
FLOAT32_AT = (
    "; its float32 arithmetic can move a slow sPLL near the edge of lock beyond "
    "check_consumer.py's tolerance on some inputs (snnTorch: 2 of 300 sPLL-inputs of "
    "biotac-tuned-vary-offset-pacinian, totals within 0.2 %), which then exits 1 naming them"
)


def support(dt: float) -> dict[str, str]:
    """Which NIR consumers run a graph written for time step ``dt`` [s], and how (consumer ->
    one line, starting "runs it" or "cannot run it"): the export folder's ``standard.json``
    and ``README.md`` list them."""
    snntorch = (
        "runs it: load_consumer.load('snntorch'), i.e. snntorch.import_nir.import_from_nir(graph) "
        "(its import assumes dt = 1e-4 s)" + FLOAT32_AT
        if dt == SNNTORCH_DT
        else f"cannot run it: its NIR import assumes dt = {SNNTORCH_DT:g} s and takes no dt; "
        f"this graph is written for {dt:g} s (export with --dt {SNNTORCH_DT:g} for snnTorch)"
    )
    if dt < NORSE_MIN_DT * (1 - 1e-9):
        norse = (
            f"cannot run it at dt = {dt:g} s: below {NORSE_MIN_DT:g} s its loader's float64 is "
            f"not measured; export with --dt {NORSE_MIN_DT:g} or coarser for Norse"
        )
    else:
        norse = (f"runs it: load_consumer.load('norse'), i.e. norse.torch.from_nir(graph, "
                 f"dt={dt!r}) (the file's dt, passed on import; at another the step guard makes "
                 "every output spike in every step)" + NORSE_EXACT)  # fmt: skip
    return {
        "nir-numpy": "runs it: spll-hw's mappings/nir/executor.py (any dt)",
        "norse": norse,
        "snntorch": snntorch,
        "spyx": SPYX_UNSUPPORTED.replace("Spyx cannot run it", "cannot run it", 1),
    }


def folder_consumers(folder: str | Path) -> str:
    """What ``spll-hw export`` prints of an export folder's consumers: ``standard.json``'s
    table (:func:`support`, written with the graph), one line per consumer, those that run the
    file first, each line ending in a newline; ``""`` for a folder without that table (an
    export of another target)."""
    path = Path(folder) / "standard.json"
    table = json.loads(path.read_text()).get("consumers") if path.is_file() else None
    if not table:
        return ""
    ordered = sorted(table.items(), key=lambda item: not item[1].startswith("runs it"))
    width = max(len(name) for name in table)
    lines = [f"  {name:<{width}}  {line}" for name, line in ordered]
    head = f"Consumers of {Path(folder) / 'network.nir'} (standard.json):"
    return "".join(f"{line}\n" for line in [head, *lines])


def load_graph(graph_or_path):
    """A ``nir.NIRGraph`` from a graph or a ``.nir`` file."""
    if isinstance(graph_or_path, str | Path):
        return read_graph(graph_or_path)
    return graph_or_path


def run_consumer(
    consumer: str,
    graph_or_path,
    trains: Sequence[np.ndarray],
    duration: float,
    *,
    record_spikes: bool = False,
) -> list[SimulationResult]:
    """Simulate every train through the graph in ``consumer``.

    Args:
        consumer: ``"numpy"``, ``"snntorch"`` or ``"norse"``.
        graph_or_path: a graph of :func:`~mappings.nir.standard.to_standard_nir` or its
            file.
        trains: sorted input spike times [s] per sample.
        duration: run length [s] (``round(duration / dt)`` steps).
        record_spikes: keep spike times (``k dt`` for a spike in step ``k``).

    Returns:
        One :class:`SimulationResult` per train; ``info`` has ``dt`` and ``consumer``, and
        for ``"numpy"`` the spikes of every neuron of the graph
        (:data:`~spll_hw.neuron_graph.COUNTS_KEY`, :func:`~.executor.neuron_nodes`' order).
    """
    if consumer not in CONSUMERS:
        raise ValueError(f"unknown NIR consumer {consumer!r}; known: {', '.join(CONSUMERS)}")
    graph = load_graph(graph_or_path)
    dt = float(np.asarray(graph.metadata["dt"]))
    n = int(np.asarray(graph.metadata["n_spll"]))
    steps = np.stack([input_steps(x, duration, dt) for x in trains], axis=1)  # (T, B)
    start = time.perf_counter()
    neurons: dict = {}  # spll-hw's executor's spikes of every neuron node
    if consumer == "numpy":  # step by step: memory of the spikes, not of every step
        counts, events = _stepped(chunks_nir(graph, steps[:, :, None], dt, neurons),
                                  (len(trains), 2 * n), record_spikes)  # fmt: skip
    else:
        # The export folder's load_consumer.py (.loader) loads and steps them the same way.
        out = run(load_module(consumer, graph, dt), steps, dt)  # (T, B, 2N)
        counts, events = out.sum(axis=0), np.nonzero(out) if record_spikes else None
    wall = (time.perf_counter() - start) / max(1, len(trains))
    counts = np.asarray(counts).astype(np.int64)  # (B, 2N)
    results = []
    for b in range(len(trains)):
        res = SimulationResult(
            tde_counts=counts[b, :n],
            cco_counts=counts[b, n:],
            duration=duration,
            backend=f"nir-{consumer}",
            wall_time=wall,
            info={"dt": dt, "consumer": consumer},
        )
        if neurons:
            res.info[COUNTS_KEY] = np.concatenate(
                [neurons[name][b] for name in neuron_nodes(graph)]
            ).astype(np.int64)
        if record_spikes:
            step, sample, neuron = events
            mine = sample == b
            t, which = (step[mine] + 1) * dt, neuron[mine]
            res.tde_spikes = [t[which == i] for i in range(n)]
            res.cco_spikes = [t[which == n + i] for i in range(n)]
        results.append(res)
    return results


def _stepped(chunks, shape: tuple[int, int], record_spikes: bool) -> tuple[np.ndarray, tuple]:
    """The output's sums over the runs of steps ``chunks`` yields (each ``(steps,) + shape``,
    ``shape`` ``(B, 2N)``), and, with ``record_spikes``, where it spiked: ``(step, sample,
    neuron)`` index arrays in step order, as ``np.nonzero`` of every step stacked would give
    them."""
    counts = np.zeros(shape)
    found = [(np.zeros(0, int), np.zeros(0, int), np.zeros(0, int))]
    first = 0
    for y in chunks:
        counts += y.sum(axis=0)
        if record_spikes:
            step, sample, neuron = np.nonzero(y)
            found.append((step + first, sample, neuron))
        first += y.shape[0]
    return counts, tuple(np.concatenate(parts) for parts in zip(*found, strict=True))
