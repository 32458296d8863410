"""The exact sPLL as a NIR graph, and back: the builder of ``spll-hw export --to nir``.

Graph of an N-sPLL network (every node has shape ``(N,)`` except the input's ``(1,)``)::

    input (Input) ─> fanout (Linear, ones (N, 1)) ─> tde_fac (LI)
    tde_fac ─> tde_gate (Scale + metadata: the extension node) <─ cco (CubaLIF)
    tde_gate ─> tde (CubaLIF) ─> cco                          (the feedback)
                        └────> output (Output)

The fields are filled from the model's statement (:mod:`spll_hw.model.equations`: its jumps,
synapses and membranes, ``_Roles``), so the parameter names below are those of its tables.
NIR states its neurons in continuous time; an input spike is a Dirac delta, so a spike of weight
``w`` into ``tau dx/dt = -x + w S`` makes ``x`` jump by ``w / tau``. With that, the mapping is exact
for everything NIR can express:

==============  ==============================================================================
node            parameters (golden-model names, :data:`spll_hw.params.PARAM_NAMES`)
==============  ==============================================================================
``cco``         CubaLIF ``tau_syn dI/dt = -I + w_in S``, ``tau_mem dv/dt = v_leak - v + r I``:
                ``tau_syn = tau_cco_syn``, ``tau_mem = tau_cco``, ``r = tau_cco / c_cco``,
                ``w_in = g_cco * tau_cco_syn`` (a TDE spike adds ``g_cco``), ``v_threshold =
                v_cco_thr``, ``v_reset = 0`` and the **bias**: the offset current enters as the
                leak potential ``v_leak = r * i_cco_offset`` (a constant current ``I`` in
                ``tau dv/dt = -v + r I`` is exactly a leak potential ``r I``; CubaLIF has no other
                bias, and an Affine bias would pass through the synapse's low-pass filter)
``tde_fac``     LI (its state is the facilitatory current): ``tau = tau_tde_fac``,
                ``r = g_tde_fac * tau_tde_fac`` (an input spike adds ``g_tde_fac``), ``v_leak = 0``
``tde_gate``    the extension node, see below: ``scale = g_tde_trg``
``tde``         CubaLIF, the trigger synapse and TDE neuron: ``tau_syn = tau_tde_trg``,
                ``tau_mem = tau_tde``, ``r = tau_tde / c_tde``, ``w_in = tau_tde_trg`` (an input
                ``x`` from the gate adds ``x`` to the trigger current), ``v_leak = 0``,
                ``v_threshold = v_tde_thr``, ``v_reset = 0``
==============  ==============================================================================

Together ``tde_fac``, ``tde_gate`` and ``tde`` are the TDE composite (``metadata["spll_hw_part"]
= "tde"``). What NIR cannot express is carried in node metadata, which a generic NIR consumer
ignores, so it would simulate those parts differently:

* **The gate** (``tde_gate``, ``metadata["spll_hw_op"] = "gate"``). Its output is a spike of
  weight ``scale * I_fac(t-)`` at each spike on the edge from ``metadata["spll_hw_trigger"]``
  (the CCO), where ``I_fac`` is the state of the node ``metadata["spll_hw_gated_by"]``
  (``tde_fac``) just before the spike: the trigger current jumps by ``g_tde_trg * I_fac``. The edge
  ``tde_fac -> tde_gate`` carries a state, not spikes. A plain NIR ``Scale`` would instead scale
  the sum of its inputs.
* **Refractory periods** ``metadata["t_refr"]`` [s] on ``cco`` and ``tde``: after a spike the
  potential is held at ``v_reset`` for that long while the synaptic current keeps decaying.
* Edges have zero delay; simultaneous events follow the golden engine (all states advance, then
  all spikes are delivered; the gate samples ``I_fac`` before an input spike at the same time).

Graph metadata keeps the network's layout (``spll_hw_layout``, ``spll_hw_scales``,
``spll_hw_groups``), so :func:`from_nir` rebuilds the same :class:`~spll_hw.network.Network`. It
reads every parameter back from the NIR fields above; the products and quotients of the table
round, so a parameter can come back one unit in the last place off. To make the round trip
bit-exact, ``metadata["spll_hw_params"]`` keeps the ``(N, 15)`` parameter matrix
(:data:`~spll_hw.params.PARAM_NAMES` order), and a parameter read from a NIR field is replaced by
it only where the two agree to :data:`EXACT_RTOL`; a field edited in another tool takes effect.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spll_hw.model.roles import roles as model_roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

from .files import nir_package, read_graph, write_graph

#: Value of the graph's ``metadata["spll_hw_format"]``; :func:`from_nir` accepts only this.
FORMAT = "spll-hw sPLL network, NIR mapping v1"

#: The nodes :func:`to_nir` writes, with their NIR types.
NODES = {
    "input": "Input",
    "fanout": "Linear",
    "tde_fac": "LI",
    "tde_gate": "Scale",
    "tde": "CubaLIF",
    "cco": "CubaLIF",
    "output": "Output",
}
EDGES = [
    ("input", "fanout"),
    ("fanout", "tde_fac"),
    ("tde_fac", "tde_gate"),
    ("cco", "tde_gate"),
    ("tde_gate", "tde"),
    ("tde", "cco"),
    ("tde", "output"),
]

#: Relative distance within which a parameter read from a NIR field is the one in
#: ``metadata["spll_hw_params"]`` (a few rounding steps of the mapping's products and quotients).
EXACT_RTOL = 1e-14


def to_nir(network: Network):
    """The ``nir.NIRGraph`` of ``network`` (layout in the module docstring), its fields filled
    from the model's statement (:mod:`spll_hw.model.equations`)."""
    if not isinstance(network, Network):
        raise ValueError(f"to_nir needs a spll_hw Network, got {type(network).__name__}")
    nir = nir_package()
    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))  # name -> (N,) array
    n = network.n_spll
    zeros = np.zeros(n)
    roles = model_roles()
    tde, cco = roles.tde, roles.cco
    r_cco = p[cco.tau] / p[cco.c]
    nodes = {
        "input": nir.Input(input_type={"input": np.array([1])}),
        "fanout": nir.Linear(weight=np.ones((n, 1))),
        "tde_fac": nir.LI(
            tau=p[roles.fac.tau],
            r=p[roles.driven.gain] * p[roles.fac.tau],
            v_leak=zeros,
            metadata={"spll_hw_part": "tde"},
        ),
        "tde_gate": nir.Scale(
            scale=p[roles.gated.gain],
            metadata={
                "spll_hw_part": "tde",
                "spll_hw_op": "gate",
                "spll_hw_gated_by": "tde_fac",
                "spll_hw_trigger": "cco",
                "description": "output = scale * state(tde_fac)(t-) at each spike from cco",
            },
        ),
        "tde": nir.CubaLIF(
            tau_syn=p[roles.trg.tau],
            tau_mem=p[tde.tau],
            r=p[tde.tau] / p[tde.c],
            v_leak=zeros,
            v_threshold=p[tde.v_thr],
            v_reset=zeros,
            w_in=p[roles.trg.tau],
            metadata={"spll_hw_part": "tde", "t_refr": p[tde.t_refr]},
        ),
        "cco": nir.CubaLIF(
            tau_syn=p[roles.cco_syn.tau],
            tau_mem=p[cco.tau],
            r=r_cco,
            v_leak=r_cco * p[roles.offset],
            v_threshold=p[cco.v_thr],
            v_reset=zeros,
            w_in=p[roles.fed.gain] * p[roles.cco_syn.tau],
            metadata={"spll_hw_part": "cco", "t_refr": p[cco.t_refr]},
        ),
        "output": nir.Output(output_type={"output": np.array([n])}),
    }
    metadata = {
        "spll_hw_format": FORMAT,
        "spll_hw_layout": network.layout,
        "spll_hw_scales": np.asarray(network.scales, dtype=float),
        "spll_hw_groups": np.asarray(network.groups, dtype=np.int64),
        "spll_hw_params": network.matrix(),
    }
    return nir.NIRGraph(nodes=nodes, edges=list(EDGES), metadata=metadata)


def _check_graph(graph) -> None:
    """``ValueError`` naming the node or field where ``graph`` is not one :func:`to_nir` wrote:
    not a NIR graph, another format, missing nodes, other node types or edges
    (:func:`_check_neurons` for the nodes' fields)."""
    nir = nir_package()
    if not isinstance(graph, nir.NIRGraph):
        raise ValueError(f"from_nir needs a nir.NIRGraph, got {type(graph).__name__}")
    fmt = _text((graph.metadata or {}).get("spll_hw_format", ""))
    if fmt != FORMAT:
        raise ValueError(
            f"not an spll-hw NIR graph: metadata spll_hw_format is {fmt!r}, expected {FORMAT!r}"
        )
    for name, kind in NODES.items():
        node = graph.nodes.get(name)
        if node is None:
            raise ValueError(f"NIR graph has no node {name!r} (an sPLL graph has {list(NODES)})")
        if type(node).__name__ != kind:
            raise ValueError(f"NIR node {name!r} is a {type(node).__name__}, expected {kind}")
    if sorted(map(tuple, graph.edges)) != sorted(EDGES):
        raise ValueError(f"NIR graph edges {sorted(graph.edges)} differ from the sPLL's {EDGES}")
    _check_neurons(*(graph.nodes[k] for k in ("tde_fac", "tde_gate", "tde", "cco")))


def _check_neurons(fac, gate, tde, cco) -> None:
    """``ValueError`` naming the field where the facilitatory, gate, TDE and CCO nodes do not
    hold what :func:`to_nir` writes: the gate's op, no reset potential, a refractory period in
    metadata, no leak potential of the TDE, ``w_in = tau_syn`` at the TDE."""
    if _text(gate.metadata.get("spll_hw_op", "")) != "gate":
        raise ValueError("NIR node 'tde_gate' lacks metadata spll_hw_op = 'gate'")
    for name, node in (("tde", tde), ("cco", cco)):
        if np.any(np.asarray(node.v_reset) != 0):
            raise ValueError(f"NIR node {name!r}: v_reset must be 0 (the sPLL resets to 0)")
        if "t_refr" not in node.metadata:
            raise ValueError(f"NIR node {name!r} has no metadata 't_refr' (refractory period)")
    for name, value in (("tde_fac.v_leak", fac.v_leak), ("tde.v_leak", tde.v_leak)):
        if np.any(np.asarray(value) != 0):
            raise ValueError(f"NIR field {name} must be 0 (the TDE has no leak potential)")
    if not np.allclose(tde.w_in, tde.tau_syn, rtol=1e-12, atol=0):
        raise ValueError("NIR field tde.w_in must equal tde.tau_syn (the gate sets the jump)")


def from_nir(graph) -> Network:
    """Rebuild the :class:`Network` from a graph written by :func:`to_nir`.

    Raises ``ValueError`` naming the node or field when the graph is not such a graph (missing
    nodes, other node types or edges, a nonzero reset or TDE leak, a missing refractory period).
    """
    _check_graph(graph)
    meta = graph.metadata or {}
    fac, gate, tde, cco = (graph.nodes[k] for k in ("tde_fac", "tde_gate", "tde", "cco"))
    roles = model_roles()
    tde_m, cco_m = roles.tde, roles.cco
    values = {  # the inverse of to_nir's table
        roles.cco_syn.tau: cco.tau_syn,
        cco_m.tau: cco.tau_mem,
        cco_m.c: cco.tau_mem / cco.r,
        roles.fed.gain: cco.w_in / cco.tau_syn,
        roles.offset: cco.v_leak / cco.r,
        cco_m.t_refr: cco.metadata["t_refr"],
        cco_m.v_thr: cco.v_threshold,
        roles.fac.tau: fac.tau,
        roles.trg.tau: tde.tau_syn,
        tde_m.tau: tde.tau_mem,
        tde_m.c: tde.tau_mem / tde.r,
        roles.driven.gain: fac.r / fac.tau,
        roles.gated.gain: gate.scale,
        tde_m.t_refr: tde.metadata["t_refr"],
        tde_m.v_thr: tde.v_threshold,
    }
    n = np.asarray(cco.tau_mem).shape[0]
    columns = []
    for name in PARAM_NAMES:
        column = np.asarray(values[name], dtype=float).reshape(-1)
        if column.shape != (n,):
            raise ValueError(f"NIR field for {name} has shape {column.shape}, expected ({n},)")
        columns.append(column)
    matrix = np.stack(columns, axis=1)
    exact = np.asarray(meta.get("spll_hw_params", np.full_like(matrix, np.nan)), dtype=float)
    if exact.shape == matrix.shape:
        matrix = np.where(np.isclose(matrix, exact, rtol=EXACT_RTOL, atol=0), exact, matrix)
    return Network(
        Network.from_matrix(matrix).spll,
        layout=_text(meta.get("spll_hw_layout", "custom")),
        scales=meta.get("spll_hw_scales"),
        groups=meta.get("spll_hw_groups"),
    )


def write_nir(network: Network, path: str | Path) -> Path:
    """Write ``network`` as a NIR HDF5 file (``nir.write``); returns the path."""
    return write_graph(path, to_nir(network))


def read_nir(path: str | Path) -> Network:
    """Read a NIR HDF5 file written by :func:`write_nir` back into a :class:`Network`."""
    return from_nir(read_graph(path))


def _text(value) -> str:
    """Metadata strings come back from HDF5 as bytes."""
    return value.decode("utf8") if isinstance(value, bytes) else str(value)
