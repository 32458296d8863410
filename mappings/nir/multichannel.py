"""A multichannel sPLL network and its spiking readout as one NIR graph, and back.

The whole network (:func:`spll_hw.multichannel.chips.whole_network`: every channel's sPLLs in
feature order, ``N`` in all) is the exact graph of :mod:`.exact` with ``C`` inputs instead of
one, and the readout (:mod:`spll_hw.multichannel.readout`, ``k`` classes) follows its TDEs::

    input (Input, (C,)) ─> fanout (Linear, channel one-hot (N, C)) ─> tde_fac ... tde ─> output
    tde ─> readout (Affine, weight w (k, N), bias beta (k,)) ─> decision (IF) ─> decision_output

``fanout[i, c] = 1`` where sPLL ``i`` belongs to channel ``c``: input ``c`` carries the encoded
spikes of channel ``c``. The readout is exact in continuous time: a TDE spike (a Dirac delta)
through the ``Affine`` adds ``w_ji`` to ``decision``'s membrane (``IF``: ``dv/dt = r I``,
``r = 1``), its bias is the constant slope ``beta_j`` [1/s], so the membrane is
``v_j(t) = sum_i w_ji N_i(t) + beta_j t`` and ``v_threshold = theta`` is the decision
threshold [score x s] (``inf``: no neuron fires, the end decides). ``v_reset = 0``: after the
first spike nothing matters.

What NIR cannot say is in metadata (graph and ``decision`` node) and in the export folder's
README: **winner-take-all** (the first readout spike decides: its neuron is the class, its time
the time to decision; ties at one instant go to the larger membrane, then the lower class), the
**switch-on** at ``spll_hw_not_before`` [s] (no decision earlier; a membrane above ``theta``
then decides at that instant), and the **fallback** when no neuron fires in the run: the largest
membrane at its end (a membrane, not a spike count). NIR's ``IF`` fires at ``v > v_threshold``,
the readout at ``v >= theta``: they differ only when a TDE jump lands exactly on ``theta``.

:func:`from_nir_multichannel` reads the network back through :func:`.exact.from_nir` (so the same
parameters, bit for bit) and the readout from the ``readout`` and ``decision`` nodes;
:meth:`MultichannelGraph.decisions` decides runs of the read-back networks in the golden engine
(:func:`spll_hw.multichannel.decisions.engine_decisions`).
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mappings.folder import ExportFolder
from spll_hw.multichannel.chips import whole_network
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.decisions import engine_decisions
from spll_hw.multichannel.readout import START, Readout, StagedReadout
from spll_hw.multichannel.readout_file import SavedReadout
from spll_hw.network import Network

from . import exact
from .files import GRAPH_FILE, nir_package, read_graph, write_graph

#: Value of the graph's ``metadata["spll_hw_format"]``.
FORMAT = "spll-hw multichannel sPLL network with spiking readout, NIR mapping v1"
#: The readout's nodes and edges, after the network's (:data:`.exact.NODES`, ``EDGES``).
READOUT_NODES = {"readout": "Affine", "decision": "IF", "decision_output": "Output"}
READOUT_EDGES = [("tde", "readout"), ("readout", "decision"), ("decision", "decision_output")]
#: The exact graph's metadata keys, handed to :func:`.exact.from_nir` as they are.
NETWORK_KEYS = ("spll_hw_layout", "spll_hw_scales", "spll_hw_groups", "spll_hw_params")
#: The graph's metadata keys of the readout (with ``readout`` and ``decision`` nodes).
READOUT_KEYS = (
    "spll_hw_classes",
    "spll_hw_readout_bits",
    "spll_hw_levels",
    "spll_hw_not_before",
    "spll_hw_decision",
)
#: The configuration's file in an export folder (``MultichannelConfig.load`` reads it).
CONFIG_FILE = "multichannel.toml"
#: What NIR cannot say about the readout (metadata ``description`` and the README).
DECISION_RULE = (
    "winner-take-all: the first spike of a decision neuron decides (its index is the class, its "
    "time the time to decision; ties at one instant go to the larger membrane, then the lower "
    "class); no decision before spll_hw_not_before [s] (a membrane already at v_threshold then "
    "decides at that instant); no spike within the run: the largest membrane at its end decides"
)


@dataclass(frozen=True)
class MultichannelGraph:
    """What :func:`from_nir_multichannel` reads back.

    Attributes:
        config: the multichannel configuration (channels, encoders, levels; metadata).
        network: the whole network from the graph's fields, ``N`` sPLLs in feature order.
        inputs: the channel (index into ``config.channels``) of each sPLL, shape ``(N,)``.
        readout: the readout and its channels' input levels, or ``None`` (network only).
        threshold: the decision threshold [score x s] (``inf``: the end decides).
        not_before: the switch-on [s].
    """

    config: MultichannelConfig
    network: Network
    inputs: np.ndarray
    readout: SavedReadout | None = None
    threshold: float = float("inf")
    not_before: float = START

    def channel_networks(self) -> list[Network]:
        """Each channel's sPLLs as a network of its own (``config.channels`` order): what the
        golden engine runs on that channel's encoded spikes."""
        spll = self.network.spll
        return [
            Network(
                tuple(spll[i] for i in np.flatnonzero(self.inputs == c)),
                "custom",
                self.network.scales[self.inputs == c],
            )
            for c in range(len(self.config.channels))
        ]

    def decisions(self, runs: Sequence[Sequence[np.ndarray]], duration: float):
        """The readout's decision of every run (:class:`~spll_hw.multichannel.decisions.
        Decisions`, one column): ``runs[r][i]`` the spike times [s] of TDE ``i`` of run ``r``
        (feature order), each ``duration`` s long. ``ValueError`` without a readout."""
        if self.readout is None:
            raise ValueError("this NIR graph has no readout (exported without --readout)")
        return engine_decisions(
            self.readout.readout, runs, duration, [self.threshold], self.not_before
        )


def to_nir_multichannel(
    config: MultichannelConfig,
    saved: SavedReadout | None = None,
    threshold: float = float("inf"),
    not_before: float = START,
):
    """The ``nir.NIRGraph`` of ``config``'s whole network with the readout ``saved`` deciding
    at ``threshold`` [score x s] no earlier than ``not_before`` [s] (module docstring);
    ``saved=None``: the network only. ``ValueError`` when the readout does not take this
    network's TDEs (channels or count) or the threshold is not > 0."""
    nir = nir_package()
    network, inputs = whole_network(config)
    graph = exact.to_nir(network)
    nodes, edges = dict(graph.nodes), list(graph.edges)
    channels = config.channels
    nodes["input"] = nir.Input(input_type={"input": np.array([len(channels)])})
    nodes["fanout"] = nir.Linear(weight=np.eye(len(channels))[inputs])
    metadata = {
        **{key: graph.metadata[key] for key in NETWORK_KEYS},
        "spll_hw_format": FORMAT,
        "spll_hw_channels": json.dumps(list(channels)),
        "spll_hw_multichannel": config.to_toml(),
    }
    if saved is not None:
        saved.check_network(channels, network.n_spll, f"multichannel network {config.source}")
        if isinstance(saved.readout, StagedReadout):
            raise ValueError(
                f"a staged readout ({len(saved.readout.stages)} stages switched on at "
                f"{', '.join(f'{t:g}' for t in saved.readout.starts)} s): --to nir's graph holds "
                "one readout; --to nir-standard writes the stages' switching in standard nodes"
            )
        if not threshold > 0:
            raise ValueError(f"readout threshold must be > 0 (score x s), got {threshold!r}")
        nodes.update(_readout_nodes(nir, saved.readout, threshold, not_before))
        edges += READOUT_EDGES
        metadata.update(
            spll_hw_classes=json.dumps(list(saved.readout.class_names)),
            spll_hw_readout_bits=np.int64(saved.readout.bits or 0),
            spll_hw_levels=np.asarray(saved.levels, float),
            spll_hw_not_before=float(not_before),
            spll_hw_decision=DECISION_RULE,
        )
    return nir.NIRGraph(nodes=nodes, edges=edges, metadata=metadata)


def _readout_nodes(nir, readout: Readout, threshold: float, not_before: float) -> dict:
    k = readout.bias.size
    return {
        "readout": nir.Affine(
            weight=np.asarray(readout.weights, float), bias=np.asarray(readout.bias, float)
        ),
        "decision": nir.IF(
            r=np.ones(k),
            v_threshold=np.full(k, float(threshold)),
            v_reset=np.zeros(k),
            metadata={
                "spll_hw_op": "winner_take_all",
                "spll_hw_not_before": float(not_before),
                "description": DECISION_RULE,
            },
        ),
        "decision_output": nir.Output(output_type={"output": np.array([k])}),
    }


def from_nir_multichannel(graph) -> MultichannelGraph:
    """Read a graph written by :func:`to_nir_multichannel` back. ``ValueError`` naming the node,
    field or metadata key when it is not such a graph."""
    nir = nir_package()
    if not isinstance(graph, nir.NIRGraph):
        raise ValueError(f"from_nir_multichannel needs a nir.NIRGraph, got {type(graph).__name__}")
    meta = graph.metadata or {}
    fmt = exact._text(meta.get("spll_hw_format", ""))
    if fmt != FORMAT:
        raise ValueError(
            f"not an spll-hw multichannel NIR graph: metadata spll_hw_format is {fmt!r}, "
            f"expected {FORMAT!r}"
        )
    has_readout = "readout" in graph.nodes
    expected = set(exact.EDGES) | (set(READOUT_EDGES) if has_readout else set())
    if set(map(tuple, graph.edges)) != expected:
        raise ValueError(f"NIR graph edges {sorted(graph.edges)} differ from {sorted(expected)}")
    network = exact.from_nir(
        nir.NIRGraph(
            nodes={name: graph.nodes[name] for name in exact.NODES},
            edges=list(exact.EDGES),
            metadata={"spll_hw_format": exact.FORMAT, **{k: meta[k] for k in NETWORK_KEYS}},
        )
    )
    config = _config(meta)
    inputs = _inputs(graph.nodes["fanout"].weight, config, network.n_spll)
    if not has_readout:
        return MultichannelGraph(config, network, inputs)
    missing = [key for key in READOUT_KEYS if key not in meta]
    if missing:
        raise ValueError(f"NIR graph has a readout but no metadata {missing}")
    readout, threshold = _readout(graph, meta)
    saved = SavedReadout(readout, config.channels, np.asarray(meta["spll_hw_levels"], float))
    saved.check_network(config.channels, network.n_spll, "the NIR graph's network")
    return MultichannelGraph(
        config, network, inputs, saved, threshold, float(meta["spll_hw_not_before"])
    )


def _config(meta: dict) -> MultichannelConfig:
    """The configuration in ``meta["spll_hw_multichannel"]`` (its TOML)."""
    text = exact._text(meta.get("spll_hw_multichannel", ""))
    where = Path("NIR metadata spll_hw_multichannel")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where}: not a multichannel network file: {exc}") from None
    config = MultichannelConfig.from_document(doc, where)
    channels = tuple(_names(meta, "spll_hw_channels"))
    if channels != config.channels:
        raise ValueError(
            f"NIR metadata spll_hw_channels {channels} differ from {where}'s {config.channels}"
        )
    return config


def _names(meta: dict, key: str) -> list[str]:
    """The list of names in ``meta[key]`` (a JSON list: HDF5 keeps no string arrays)."""
    try:
        names = json.loads(exact._text(meta[key]))
    except (KeyError, json.JSONDecodeError):
        names = None
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise ValueError(f"NIR metadata {key} must be a JSON list of names")
    return names


def _inputs(weight, config: MultichannelConfig, n: int) -> np.ndarray:
    """The channel of each sPLL from the ``fanout`` weight ``(N, C)``, a channel one-hot whose
    counts per channel are ``config``'s."""
    weight = np.asarray(weight, float)
    c = len(config.channels)
    if (
        weight.shape != (n, c)
        or not np.all((weight == 0) | (weight == 1))
        or not np.all(weight.sum(axis=1) == 1)
    ):
        raise ValueError(
            f"NIR node 'fanout' must be a channel one-hot ({n}, {c}) of 0 and 1, one 1 a row; "
            f"got shape {weight.shape}"
        )
    inputs = np.argmax(weight, axis=1)
    _, expected = whole_network(config)
    if not np.array_equal(inputs, expected):
        raise ValueError(
            "NIR node 'fanout' gives the channels other sPLLs than metadata "
            "spll_hw_multichannel's networks"
        )
    return inputs


def _readout(graph, meta: dict) -> tuple[Readout, float]:
    """The readout and its threshold from the ``readout`` and ``decision`` nodes."""
    for name, kind in READOUT_NODES.items():
        node = graph.nodes.get(name)
        if node is None or type(node).__name__ != kind:
            raise ValueError(f"NIR node {name!r} must be a {kind} (the readout)")
    affine, decision = graph.nodes["readout"], graph.nodes["decision"]
    names = tuple(_names(meta, "spll_hw_classes"))
    weights, bias = np.asarray(affine.weight, float), np.asarray(affine.bias, float)
    k = len(names)
    if weights.shape[0] != k or bias.shape != (k,):
        raise ValueError(
            f"NIR node 'readout': weight {weights.shape} and bias {bias.shape} must have one row "
            f"per class of metadata spll_hw_classes ({k})"
        )
    theta = np.asarray(decision.v_threshold, float).reshape(-1)
    if theta.shape != (k,) or not np.all(theta == theta[0]) or not theta[0] > 0:
        raise ValueError("NIR node 'decision': v_threshold must be one threshold > 0 per class")
    if not np.all(np.asarray(decision.r) == 1):
        raise ValueError("NIR node 'decision': r must be 1 (the membrane is the score x time)")
    bits = int(meta["spll_hw_readout_bits"])
    return Readout(weights, bias, names, bits or None), float(theta[0])


def write_nir_multichannel(path: str | Path, *args, **kwargs) -> Path:
    """Write :func:`to_nir_multichannel`'s graph as a NIR HDF5 file; returns the path."""
    path = Path(path)
    return write_graph(path, to_nir_multichannel(*args, **kwargs))


def read_nir_multichannel(path: str | Path) -> MultichannelGraph:
    """Read a NIR HDF5 file written by :func:`write_nir_multichannel` back."""
    return from_nir_multichannel(read_graph(path))


def export_multichannel(
    config: MultichannelConfig,
    out: str | Path,
    saved: SavedReadout | None = None,
    threshold: float = float("inf"),
) -> list[Path]:
    """Write the export folder ``out``: ``network.nir`` (:func:`to_nir_multichannel`),
    ``multichannel.toml`` (the configuration, encoders included) and ``README.md`` (the graph
    and what a NIR consumer would see), once the written graph reads back to the same network
    and readout (:func:`check_read_back`; else nothing is written). Returns the files."""
    graph = to_nir_multichannel(config, saved, threshold)
    with ExportFolder(out) as folder:
        path = write_graph(folder.file(GRAPH_FILE), graph)
        check_read_back(path, config, saved, threshold)
        folder.text(CONFIG_FILE, config.to_toml())
        folder.text("README.md", readme(config, saved, threshold))
    return folder.files


def check_read_back(
    path: Path, config: MultichannelConfig, saved: SavedReadout | None, threshold: float
) -> None:
    """``ValueError`` naming ``path`` unless the NIR file reads back to ``config``'s whole
    network (every parameter equal, not close) and ``saved``'s readout at ``threshold``."""
    back = read_nir_multichannel(path)
    network, _ = whole_network(config)
    same = np.array_equal(back.network.matrix(), network.matrix())
    if saved is not None:
        r, b = saved.readout, back.readout.readout
        same &= np.array_equal(r.weights, b.weights) and np.array_equal(r.bias, b.bias)
        same &= r.class_names == b.class_names and r.bits == b.bits
        same &= back.threshold == threshold and np.array_equal(back.readout.levels, saved.levels)
    if not same:
        raise ValueError(f"{path} does not read back to the network and readout written")


def readme(config: MultichannelConfig, saved: SavedReadout | None, threshold: float) -> str:
    """The export folder's README: what the graph holds and what NIR cannot say."""
    network, _ = whole_network(config)
    lines = [
        "# Multichannel sPLL network" + (" with its spiking readout" if saved else ""),
        "",
        f"`{GRAPH_FILE}`: {network.n_spll} sPLLs of {len(config.channels)} channels "
        f"({', '.join(config.channels)}), written by spll-hw from `{config.source}`; "
        f"`{CONFIG_FILE}`: the channels' networks and encoders. Input `c` of the `input` node "
        "carries the encoded spikes of channel `c`; `fanout` (a channel one-hot) sends them to "
        "that channel's TDEs. The sPLL nodes are the exact mapping of one network (the TDE gate "
        "and refractory periods in node metadata: run it with spll-hw's "
        "`mappings.nir.multichannel.read_nir_multichannel`).",
    ]
    if saved is not None:
        r = saved.readout
        width = "float" if r.bits is None else f"{r.bits}-bit integer"
        lines += [
            "",
            f"Readout ({width} weights, {len(r.class_names)} classes: "
            f"{', '.join(r.class_names)}): `tde` → `readout` (Affine: weight `w`, bias `β`) → "
            f"`decision` (IF, `r = 1`, `v_threshold = θ = {threshold:g}` score·s) → "
            "`decision_output`. Exact in continuous time: a TDE spike adds `w_ji` to membrane "
            "`j`, the bias is its slope `β_j` [1/s].",
            "",
            "What NIR cannot say (metadata `spll_hw_decision`, node `decision`'s `description`):",
            "",
            "- **Winner-take-all**: the first spike of a decision neuron decides; the others do "
            "not matter. A consumer that counts spikes per time step sees several neurons "
            "spike within one step where the membranes (crossing times) break the tie.",
            f"- **Switch-on** at {START:g} s (`spll_hw_not_before`): no decision earlier.",
            "- **Fallback**: no spike within the run, the largest membrane at its end decides "
            "(a membrane, not a spike count).",
            "- **Encoding** (outside the graph): the readout was trained on each channel "
            "divided by its input level (metadata `spll_hw_levels`), its mean so far "
            "subtracted at every row (causal), then its encoder of `multichannel.toml` without "
            "centring (`center = false`).",
        ]
        if r.bits is not None:
            lines.append(
                f"- The {r.bits}-bit weights and bias are stored as floats: integers times a "
                "power-of-two scale per channel (weights) and one scale (bias)."
            )
    return "\n".join(lines) + "\n"
