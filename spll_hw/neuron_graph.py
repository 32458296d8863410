"""A network of standard neurons as a target writes it, and what a chip makes of it.

The exports ``nir-standard`` and ``lava-standard`` (and the backends that run them,
``nir-numpy`` and ``standard-fixed-point``) realise each sPLL as a *construction* of standard
neurons at their own time step (:mod:`spll_hw.construction.gate`): a CCO, a TDE, K level
and K AND neurons for the gate, relays and refractory units. :class:`NeuronGraph` states that
graph in the terms a chip costs (its neurons, which sPLL each belongs to, which share a
configuration, its synapses, its step), with no reference to the target's own types: the target
builds it (:mod:`mappings.lava.neuron_graph`, :mod:`mappings.nir.neuron_graph`), the chip
profile provider places and prices it (:func:`graph_resources`, :func:`graph_cost`; quantize's
:mod:`quantize.graph_cost`), the way :func:`spll_hw.chips.resources` and
:func:`spll_hw.chips.cost` place and price the two-compartment sPLL.

A run of the graph gives the spike count of every neuron: a backend that runs a construction
puts them in its results' ``info["neuron_counts"]`` (shape ``(n,)``, int64, in the graph's
neuron order; :func:`neuron_counts`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix

from . import backends, chips
from .backends.base import Backend
from .result import SimulationResult

#: Where a backend that runs a construction puts the spike count of every neuron of a run.
COUNTS_KEY = "neuron_counts"


@dataclass(frozen=True)
class NeuronGraph:
    """A graph of ``n`` standard neurons, in the order the target numbers them.

    Attributes:
        target: who writes it (``"lava-standard"``, ``"nir-standard"``).
        description: one line on what it is (levels, refractory realisation, step).
        n_spll: sPLLs the graph realises.
        dts: time step of each clock [s] (one for a graph on one clock).
        clock: the clock of each neuron (index into ``dts``), shape ``(n,)`` int64.
        spll: the sPLL each neuron belongs to, shape ``(n,)`` int64 (``-1``: shared by all,
            e.g. NIR's start pulse).
        decay: neurons of one id share their decays (a chip's ``decay`` configuration group),
            shape ``(n,)`` int64.
        threshold: neurons of one id share their threshold, shape ``(n,)`` int64.
        population: the population (node, process) of each neuron, index into
            ``populations``, shape ``(n,)`` int64.
        populations: population names.
        synapses: synapses between neurons, ``synapses[post, pre]`` = how many (a weight
            written in two ``Dense`` of different exponents is two), shape ``(n, n)``, a sparse
            int64 matrix. A presynaptic neuron's fan-out is its column's sum.
        input_synapses: synapses from the input onto each neuron, shape ``(n,)`` int64 (of a
            graph of several inputs: from all of them).
        input_fan: the synapses from each of the graph's ``K`` inputs onto each neuron (a
            readout fed by ``K`` TDEs), shape ``(n, K)``, a sparse int64 matrix whose row sums
            are ``input_synapses``; ``None`` (given): one input, ``input_synapses`` its
            column.
    """

    target: str
    description: str
    n_spll: int
    dts: tuple[float, ...]
    clock: np.ndarray
    spll: np.ndarray
    decay: np.ndarray
    threshold: np.ndarray
    population: np.ndarray
    populations: tuple[str, ...]
    synapses: csr_matrix
    input_synapses: np.ndarray
    input_fan: csr_matrix | None = None

    def __post_init__(self) -> None:
        n = int(np.asarray(self.spll).shape[0])
        for name in ("clock", "spll", "decay", "threshold", "population", "input_synapses"):
            value = np.asarray(getattr(self, name))
            if value.shape != (n,) or not np.issubdtype(value.dtype, np.integer):
                raise ValueError(
                    f"NeuronGraph of {self.target}: {name} must be integers of shape ({n},), "
                    f"got {value.dtype} of shape {value.shape}"
                )
            object.__setattr__(self, name, value.astype(np.int64))
        synapses = csr_matrix(self.synapses, dtype=np.int64)
        if synapses.shape != (n, n) or (synapses.data < 0).any():
            raise ValueError(
                f"NeuronGraph of {self.target}: synapses must be counts >= 0 of shape ({n}, {n}), "
                f"got shape {synapses.shape}"
            )
        object.__setattr__(self, "synapses", synapses)
        one = self.input_synapses.reshape(-1, 1)
        fan = csr_matrix(one if self.input_fan is None else self.input_fan, dtype=np.int64)
        rows = np.asarray(fan.sum(axis=1)).reshape(-1)
        if fan.shape[0] != n or (fan.data < 0).any() or not np.array_equal(rows, one[:, 0]):
            raise ValueError(
                f"NeuronGraph of {self.target}: input_fan must be counts >= 0 of shape "
                f"({n}, K) whose rows sum to input_synapses, got shape {fan.shape}"
            )
        object.__setattr__(self, "input_fan", fan)
        dts = tuple(float(x) for x in self.dts)
        if not dts or any(not (np.isfinite(x) and x > 0) for x in dts):
            raise ValueError(f"NeuronGraph of {self.target}: every step must be > 0 s, got {dts}")
        object.__setattr__(self, "dts", dts)
        if n and (self.clock.min() < 0 or self.clock.max() >= len(dts)):
            raise ValueError(f"NeuronGraph of {self.target}: a neuron's clock is not one of {dts}")
        if n and (self.spll.min() < -1 or self.spll.max() >= self.n_spll):
            raise ValueError(
                f"NeuronGraph of {self.target}: a neuron's sPLL is outside -1..{self.n_spll - 1}"
            )
        if n and (self.population.min() < 0 or self.population.max() >= len(self.populations)):
            raise ValueError(f"NeuronGraph of {self.target}: a neuron's population is unnamed")

    @property
    def neurons(self) -> int:
        return int(self.spll.shape[0])

    @property
    def n_synapses(self) -> int:
        """Synapses between neurons and from the input."""
        return int(self.synapses.sum()) + int(self.input_synapses.sum())

    @property
    def input_fan_out(self) -> np.ndarray:
        """Synapses from each input, shape ``(K,)`` int64."""
        return np.asarray(self.input_fan.sum(axis=0)).reshape(-1).astype(np.int64)

    @property
    def fan_out(self) -> np.ndarray:
        """Synapses from each neuron, shape ``(n,)`` int64."""
        return np.asarray(self.synapses.sum(axis=0)).reshape(-1).astype(np.int64)

    def population_sizes(self) -> dict[str, int]:
        """Neurons per population, in :attr:`populations` order."""
        sizes = np.bincount(self.population, minlength=len(self.populations))
        return {name: int(k) for name, k in zip(self.populations, sizes, strict=True)}

    def step_words(self) -> str:
        """``"dt = 50 µs"``, or the steps of several clocks."""
        return step_words(self.dts)


def step_words(dts: Sequence[float]) -> str:
    """``"dt = 50 µs"``, or the steps of several clocks."""
    shown = [f"{dt * 1e6:.4g} µs" for dt in dts]
    if len(shown) == 1:
        return f"dt = {shown[0]}"
    return f"{len(shown)} clocks (dt = {', '.join(shown)})"


def ids(values: Sequence) -> np.ndarray:
    """Per item, the index of its value among the distinct ones (equal values share an id),
    shape ``(len(values),)`` int64; the values are rows (tuples) or scalars."""
    keys = [tuple(np.atleast_1d(v).tolist()) for v in values]
    table: dict[tuple, int] = {}
    return np.array([table.setdefault(k, len(table)) for k in keys], dtype=np.int64)


def synapse_counts(rows: list, cols: list, in_rows: list, n: int, in_cols: list | None = None,
                   inputs: int = 1) -> tuple:  # fmt: skip
    """A target's synapses as :class:`NeuronGraph` holds them: the ``(n, n)`` matrix (one
    synapse per ``rows[i][j]``, ``cols[i][j]`` pair: post, pre), the synapses from the input
    onto each neuron (one per entry of ``in_rows``) and those from each of ``inputs`` inputs
    (``(n, inputs)``: the entries of ``in_rows`` from input ``in_cols``; none given: one input)."""
    none = [np.zeros(0, np.int64)]

    def counted(post: list, pre: list, shape: tuple[int, int]) -> csr_matrix:
        post, pre = np.concatenate(post or none), np.concatenate(pre or none)
        return coo_matrix((np.ones(post.size, np.int64), (post, pre)), shape=shape).tocsr()

    in_cols = in_cols if in_cols is not None else [np.zeros(len(r), np.int64) for r in in_rows]
    fan = counted(in_rows, in_cols, (n, inputs))
    return counted(rows, cols, (n, n)), np.asarray(fan.sum(axis=1)).reshape(-1), fan


def neuron_counts(result: SimulationResult, graph: NeuronGraph) -> np.ndarray:
    """The spike count of every neuron of ``graph`` in ``result``, shape ``(n,)`` int64;
    ``ValueError`` naming the backend when it did not count them."""
    counts = result.info.get(COUNTS_KEY)
    if counts is None:
        raise ValueError(
            f"the {result.backend!r} result has no info[{COUNTS_KEY!r}]: costing the "
            f"{graph.target} construction needs the spike count of every neuron, which "
            "nir-numpy and standard-fixed-point give (nir-snntorch and nir-norse compute the same "
            "spikes but report the outputs only)"
        )
    counts = np.asarray(counts)
    if counts.shape != (graph.neurons,):
        raise ValueError(
            f"the {result.backend!r} result counts {counts.shape} neurons, the {graph.target} "
            f"graph has ({graph.neurons},)"
        )
    return counts.astype(np.int64)


def _provider(source: str):
    provider = chips.provider(source)
    if not hasattr(provider, "graph_cost"):
        raise ValueError(f"the provider of chip profile {source!r} does not cost graphs of neurons")
    return provider


def graph_resources(graph: NeuronGraph, source: str) -> chips.ChipFit:
    """Whether ``graph`` fits chip profile ``source``, on how many cores, where each neuron
    goes (each sPLL's construction kept together); ``ValueError`` when the profile has no
    ``[resources]`` table or its provider costs no graphs."""
    return _provider(source).graph_resources(graph, source)


def graph_cost(graph: NeuronGraph, source: str, result: SimulationResult) -> chips.ChipCost:
    """What the run ``result`` of ``graph`` (its :func:`neuron_counts`,
    ``info["n_input_spikes"]``: one count, or one per input of a graph of several, and
    ``duration``) costs on chip profile ``source``: energy per
    category at the figures' values and at each end of their ranges, step latency, real-time
    factor, as :func:`spll_hw.chips.cost` gives the two-compartment sPLL's."""
    counts = neuron_counts(result, graph)
    if "n_input_spikes" not in result.info:
        raise ValueError(
            f"the {result.backend!r} result has no info['n_input_spikes']: the cost of a "
            "sample needs its input-spike count"
        )
    return _provider(source).graph_cost(
        graph, source, counts, result.info["n_input_spikes"], float(result.duration)
    )


def runs_construction(backend) -> bool:
    """Whether ``backend`` runs a construction of standard neurons (it overrides
    :meth:`~spll_hw.backends.base.Backend.neuron_graph`: ``nir-numpy``,
    ``standard-fixed-point``), not the two-compartment sPLL; known without a network."""
    return type(backend).neuron_graph is not Backend.neuron_graph


def at_step(backend, profile: str):
    """The construction ``backend`` built at the step of a stepped chip profile ``NAME@STEP``
    where it takes a ``dt`` (as a chip of that clock would run it); ``backend`` itself
    otherwise (at its own step)."""
    if "@" in profile and "dt" in backend.OPTIONS:
        return backends.get(backend, dt=chips.describe(profile).dt)
    return backend


@dataclass(frozen=True)
class GraphSize:
    """What a construction is, in a few numbers: who writes it, ``description``, its
    ``neurons``, its ``synapses`` (between neurons and from the input) and the step of each
    of its clocks ``dts`` [s]."""

    target: str
    description: str
    neurons: int
    synapses: int
    dts: tuple[float, ...]

    @classmethod
    def of(cls, graph: NeuronGraph) -> GraphSize:
        return cls(graph.target, graph.description, graph.neurons, graph.n_synapses, graph.dts)

    def step_words(self) -> str:
        """``"dt = 50 µs"``, or the steps of several clocks."""
        return step_words(self.dts)

    def to_dict(self) -> dict:
        return {"target": self.target, "description": self.description,
                "neurons": self.neurons, "synapses": self.synapses,
                "dt_s": list(self.dts)}  # fmt: skip


def run_by(spec: str | None, network, profile: str):
    """How chip profile ``profile`` costs ``network`` run by backend ``spec`` (``spll-hw chips
    --backend``, ``fit --backend``): ``(backend, graph)``, ``graph`` the construction of
    standard neurons a construction backend runs (its
    :meth:`~spll_hw.backends.base.Backend.neuron_graph`, built at the step of a stepped
    ``NAME@STEP`` where the backend takes a ``dt``, :func:`at_step`), ``None`` where the
    backend runs the two-compartment sPLL (default: ``golden:profile=NAME``, the network as
    the chip realises it). ``ValueError`` where the profile's step cannot hold the network."""
    backend = backends.get(spec or f"golden:profile={profile}")
    if spec is not None and backend.neuron_graph(network) is not None:
        backend = at_step(backend, profile)
        return backend, backend.neuron_graph(network)
    if "@" in profile:  # a step of a ladder: refused where the chip cannot write the network
        chips.realise(network, profile)
    return backend, None
