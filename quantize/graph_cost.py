"""Whether a graph of standard neurons fits a chip, where each neuron goes, and what a run of it
costs: the sPLL as ``nir-standard`` and ``lava-standard`` write it (a construction of standard
neurons at their own step, :class:`spll_hw.neuron_graph.NeuronGraph`), costed as
:mod:`quantize.resources` costs the two-compartment sPLL.

**Configurations.** A standard neuron is one compartment. Neurons on one core share a limited
number of configurations (``configs_per_core``): a neuron's configuration is its values of the
profile's ``config_shares`` that a standard neuron has, its decays (``decay``) and its threshold
(``threshold``; Loihi's compartment profiles hold the decays only). The bias is each neuron's
own and the weights are the synapses'; the construction holds refractory periods with neurons,
so no neuron has one. ``thresholds_per_core`` counts distinct thresholds apart.

**Placement.** Each sPLL's construction (its neurons) is one unit, and the neurons shared by all
sPLLs (NIR's start pulse) another, placed first; the sPLLs are sorted by the configurations
their neurons use, then placed first-fit on the lowest-numbered core where the whole unit fits
(neurons ``neurons_per_core``, configurations, thresholds, synapses onto its neurons
``synapses_per_core``), a full core opening the next. A unit too big for an empty core is placed
neuron by neuron. A core runs one clock: a graph of several clocks (``lava-standard`` with a
clock per sPLL) puts each clock's neurons on cores of their own. Cores lie on chips and meshes
as in :mod:`quantize.resources`; the input enters at core 0.

**Counts of a run** (:func:`graph_counts`) from the spike count ``s_j`` of every neuron ``j``,
the input spikes ``n_in`` and the duration ``T``: input deliveries ``n_in x`` (synapses from
the input), deliveries between neurons ``Σ_j s_j x fan-out_j`` (each a synaptic event), spikes
``Σ_j s_j``, messages ``Σ_j s_j x`` (cores holding a target of ``j``; 1 on a ``multicast`` chip)
plus ``n_in x`` (cores holding a target of the input), their hops along X-then-Y routes (on a
multicast chip the edges of the union of the routes), neuron updates ``Σ_clocks neurons x
steps`` with ``steps = round(T / dt)`` on a clocked (fixed-point) profile, one per synaptic event
on an analog one, and each clock's steps (the per-step energy ``step``). Energy: the counts x
the ``[energy]`` figures, static and core power over the window (:func:`quantize.pricing.priced`,
the two-compartment sPLL's rule). Step latency of a clock: its busiest core's mean work per step
(updates, synaptic events, spikes, messages) + the longest route's hops + the barrier; the
real-time factor is the largest over the clocks of step latency / dt. Messages to the host (a
Lava sink, NIR's output node) are not counted.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.sparse import csr_matrix

from spll_hw.model.grid import n_steps
from spll_hw.neuron_graph import NeuronGraph

from .chip_tables import DEFAULT_CONFIG_SHARES
from .placement import CoreLoad, Fitting, Mesh, axon_problems
from .pricing import ENERGY_CATEGORIES, Counts, SampleCost, priced
from .profiles import FixedPointProfile, Profile, load_profile
from .resources import chip_of

#: Energy categories of a run of a graph, in report order: (name, ``[energy]`` key, the
#: :class:`GraphCounts` field counted): the two-compartment sPLL's (input deliveries, spikes,
#: messages, hops, chip hops, neuron updates, steps), its trigger and feedback deliveries
#: replaced by the deliveries of every neuron's spikes.
GRAPH_CATEGORIES = (
    ENERGY_CATEGORIES[0],
    ("deliveries between neurons", "synaptic_event", "deliveries"),
    *ENERGY_CATEGORIES[3:],
)
#: What the messages, hops and crossings of a run are counted apart for.
SOURCES = ("input", "neurons")
#: What a spike's route is counted in, in :attr:`GraphFit.routes`' order.
ROUTES = ("messages", "crossing", "hops", "chip_hops")


@dataclass(frozen=True)
class GraphCore(CoreLoad):
    """What one core of a graph holds: :class:`~quantize.placement.CoreLoad` (input axons:
    presynaptic neurons and the input with a synapse onto its neurons), its ``clock`` (index
    into the graph's steps), ``splls`` (the sPLLs of its neurons; -1: shared ones) and
    ``neurons``."""

    clock: int
    splls: tuple[int, ...]
    neurons: int


@dataclass(frozen=True)
class GraphFit(Fitting):
    """A graph on a chip (module docstring).

    Attributes:
        profile: profile name.
        graph: the graph.
        core_of: core of each neuron, shape ``(n,)`` int64.
        cores: per-core use.
        cores_per_chip, cores_available, chips_available: what the profile offers.
        configs: distinct configurations of the graph (:func:`config_keys`).
        thresholds: distinct thresholds (``None`` where the chip does not count them apart).
        routes: per spike of each neuron, its :data:`ROUTES` (messages, those that leave its
            core, router hops, chip hops), shape ``(n, 4)`` int64.
        input_routes: :data:`ROUTES` of a spike of each of the graph's ``K`` inputs, shape
            ``(K, 4)`` int64.
        longest_route: most hops of any message.
        problems: why it does not fit (empty: it fits).
        assumed: ``table.key`` of the assumed figures the placement rests on.
    """

    profile: str
    graph: NeuronGraph = field(repr=False)
    core_of: np.ndarray = field(repr=False)
    cores: tuple[GraphCore, ...]
    cores_per_chip: int
    cores_available: int
    chips_available: int
    configs: int
    thresholds: int | None
    routes: np.ndarray = field(repr=False)
    input_routes: np.ndarray
    longest_route: int
    problems: tuple[str, ...]
    assumed: tuple[str, ...]

    @property
    def n_cores(self) -> int:
        return len(self.cores)

    @property
    def n_chips(self) -> int:
        return -(-self.n_cores // self.cores_per_chip) if self.cores else 0

    @property
    def input_route(self) -> np.ndarray:
        """:data:`ROUTES` of an input spike, shape ``(4,)``: the mean over the inputs (integers
        where every input's are the same)."""
        mean = self.input_routes.mean(axis=0)
        return mean.astype(np.int64) if (mean == np.round(mean)).all() else mean

    def to_dict(self) -> dict:
        g = self.graph
        return self.verdict() | {
            "costed": f"{g.target}: {g.description}", "n_spll": g.n_spll, "dt_s": list(g.dts),
            "neurons": g.neurons, "populations": g.population_sizes(),
            "synapses": g.n_synapses, "input_synapses": int(g.input_synapses.sum()),
            "configs": self.configs, "thresholds": self.thresholds, "cores": self.n_cores,
            "chips": self.n_chips, "cores_available": self.cores_available,
            "chips_available": self.chips_available,
            "input_messages_per_spike": self.input_route[0].item(),
            "input_hops_per_spike": self.input_route[2].item(),
            "longest_route_hops": self.longest_route,
            "placement": [asdict(c) | {"splls": list(c.splls)} for c in self.cores],
            "assumed": list(self.assumed),
        }  # fmt: skip

    def markdown(self) -> str:
        """Totals, the fit verdict and the per-core use as Markdown."""
        g = self.graph
        sizes: dict[str, int] = {}  # a population of every clock counted once by its name
        for name, size in g.population_sizes().items():
            sizes[name.split("@")[0]] = sizes.get(name.split("@")[0], 0) + size
        pops = ", ".join(f"{k} {v}" for k, v in sizes.items())
        thr = "-" if self.thresholds is None else str(self.thresholds)
        lines = [
            f"**{self.profile}**: the {g.target} construction ({g.description}) of {g.n_spll} "
            f"sPLLs at {g.step_words()}: {g.neurons} neurons ({pops}), {g.n_synapses} synapses "
            f"({int(g.input_synapses.sum())} from the input); configurations {self.configs}, "
            f"thresholds {thr}; {self.n_cores} core(s) on {self.n_chips} chip(s) of "
            f"{self.cores_available} core(s) on {self.chips_available} chip(s).",
            "",
            "fits" if self.fits else "does not fit: " + "; ".join(self.problems),
            "",
            f"Messages: {self.input_route[0]:g} per input spike ({self.input_route[2]:g} hops); "
            f"longest route {self.longest_route} hop(s).",
        ]
        if self.cores:
            lines += [
                "",
                "| core | clock | sPLLs | neurons | configs | thresholds | fan-in | "
                "fan-out | synapses |",
                "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
            ]
            lines += [f"| {c.core} | {g.step_words() if len(g.dts) == 1 else c.clock} | "
                      f"{sum(i >= 0 for i in c.splls)} | {c.neurons} | "
                      + c.cells(self.thresholds is not None) for c in self.cores]  # fmt: skip
        if self.assumed:
            lines += ["", "Assumed figures: " + ", ".join(self.assumed)]
        return "\n".join(lines)


@dataclass(frozen=True, kw_only=True)
class GraphCounts(Counts):
    """What one run of a graph makes a chip do (module docstring): :class:`Counts` with the
    synaptic events of the neurons' spikes (``deliveries``), messages, crossings and hops per
    source (:data:`SOURCES`; every input message crosses into a core), neuron updates of every
    neuron every step of its clock (one per synaptic event on an analog chip), ``steps`` summed
    over the clocks and ``clock_steps`` of each (empty on an analog chip)."""

    deliveries: int
    clock_steps: tuple[int, ...] = ()

    @property
    def synaptic_events(self) -> int:
        return self.input_deliveries + self.deliveries

    def as_dict(self) -> dict:
        return {k: (dict(v) if isinstance(v, dict) else v) for k, v in self.__dict__.items()
                if k != "clock_steps"} | {"clock_steps": list(self.clock_steps)}  # fmt: skip


def config_keys(graph: NeuronGraph, shares) -> tuple[np.ndarray, np.ndarray]:
    """Per neuron, its configuration id under ``shares`` (the groups a configuration fixes;
    those a standard neuron has: ``decay``, ``threshold``) and its threshold id, ``(n,)``
    int64 each."""
    parts = [getattr(graph, g) for g in ("decay", "threshold") if g in shares]
    if not parts:
        return np.zeros(graph.neurons, np.int64), graph.threshold
    _, keys = np.unique(np.stack(parts, axis=1), axis=0, return_inverse=True)
    return keys.reshape(-1).astype(np.int64), graph.threshold


class _Core:
    def __init__(self, index: int, clock: int) -> None:
        self.index, self.clock = index, clock
        self.neurons: list[int] = []
        self.configs: set[int] = set()
        self.thresholds: set[int] = set()
        self.synapses = 0


def _fits(core: _Core, idx: np.ndarray, keys, thr, onto, limits: dict) -> bool:
    if len(core.neurons) + idx.size > limits["neurons_per_core"]:
        return False
    cap = limits.get("configs_per_core")
    if cap is not None and len(core.configs | set(keys[idx].tolist())) > cap:
        return False
    cap = limits.get("thresholds_per_core")
    if cap is not None and len(core.thresholds | set(thr[idx].tolist())) > cap:
        return False
    cap = limits.get("synapses_per_core")
    return cap is None or core.synapses + int(onto[idx].sum()) <= cap


def _units(graph: NeuronGraph, keys: np.ndarray) -> list[np.ndarray]:
    """Neurons of each unit in placement order (module docstring): the shared ones of each
    clock, then the sPLLs' by clock and configurations."""
    units = []
    for clock in range(len(graph.dts)):
        mine = graph.clock == clock
        shared = np.flatnonzero(mine & (graph.spll < 0))
        if shared.size:
            units.append((clock, (), -1, shared))
        for i in np.unique(graph.spll[mine & (graph.spll >= 0)]):
            idx = np.flatnonzero(mine & (graph.spll == i))
            units.append((clock, tuple(sorted(set(keys[idx].tolist()))), int(i), idx))
    units.sort(key=lambda u: (u[0], u[2] >= 0, u[1], u[2]))
    return [u[3] for u in units]


def _place(graph: NeuronGraph, keys, thr, onto, limits: dict) -> list[_Core]:
    cores: list[_Core] = []
    for unit in _units(graph, keys):
        clock = int(graph.clock[unit[0]])
        empty = _Core(-1, clock)
        items = (
            [unit]
            if _fits(empty, unit, keys, thr, onto, limits)
            else [unit[[j]] for j in range(unit.size)]
        )
        for idx in items:
            core = next((c for c in cores if c.clock == clock
                         and _fits(c, idx, keys, thr, onto, limits)), None)  # fmt: skip
            if core is None:
                core = _Core(len(cores), clock)
                cores.append(core)
            core.neurons += idx.tolist()
            core.configs |= set(keys[idx].tolist())
            core.thresholds |= set(thr[idx].tolist())
            core.synapses += int(onto[idx].sum())
    return cores


def graph_fit(graph: NeuronGraph, profile: Profile | str) -> GraphFit:
    """Place ``graph`` on ``profile``'s cores (module docstring) and say whether it fits;
    :class:`~quantize.resources.ChipError` when the profile has no ``[resources]``."""
    profile = load_profile(profile)
    chip = chip_of(profile)
    res = chip.resources
    used = [f"resources.{k}" for k in ("chips", "cores_per_chip", "neurons_per_core")]
    limits = {"neurons_per_core": res.value("neurons_per_core")}
    for key in ("configs_per_core", "thresholds_per_core", "synapses_per_core",
                "synapses_per_neuron", "fan_in_per_core", "fan_out_per_core",
                "cores_per_tile", "mesh_columns", "multicast"):  # fmt: skip
        if key in res:
            limits[key] = res.value(key)
            used.append(f"resources.{key}")
    keys, thr = config_keys(graph, res.value("config_shares", DEFAULT_CONFIG_SHARES))
    onto = np.asarray(graph.synapses.sum(axis=1)).reshape(-1) + graph.input_synapses
    cores = _place(graph, keys, thr, onto, limits)
    n, n_cores = graph.neurons, len(cores)
    core_of = np.zeros(n, np.int64)
    for c in cores:
        core_of[c.neurons] = c.index
    # dest[c, j]: neuron j has a synapse onto a neuron of core c.
    targets = csr_matrix((graph.synapses > 0).astype(np.int64))
    member = csr_matrix((np.ones(n, np.int64), (core_of, np.arange(n))), shape=(n_cores, n))
    dest = (member @ targets).tocsc()
    from_input = graph.input_fan.tocsc()  # (n, K)
    mesh, multicast = Mesh(res), bool(res.value("multicast", False))
    route = {}  # (src, dst) core -> (router edges, chip edges)
    routes = np.zeros((n, len(ROUTES)), np.int64)
    fan_out = np.zeros(n_cores, np.int64)

    def routed(src: int, dsts) -> tuple[int, int, int, int]:
        """Messages, crossing, hops and chip hops of one spike from ``src`` to ``dsts``."""
        edges, chip_edges, hops, chip_hops = set(), set(), 0, 0
        for d in dsts:
            r = route.setdefault((src, int(d)), mesh.route(src, int(d)))
            edges |= r[0]
            chip_edges |= r[1]
            hops, chip_hops = hops + len(r[0]), chip_hops + len(r[1])
        if multicast:
            return int(len(dsts) > 0), int(any(d != src for d in dsts)), len(edges), len(chip_edges)
        return len(dsts), sum(int(d != src) for d in dsts), hops, chip_hops

    for j in range(n):
        dsts = dest.indices[dest.indptr[j] : dest.indptr[j + 1]]
        routes[j] = routed(int(core_of[j]), dsts)
        fan_out[core_of[j]] += dsts.size
    reached = [from_input.indices[from_input.indptr[k] : from_input.indptr[k + 1]]
               for k in range(from_input.shape[1])]  # each input's neurons  # fmt: skip
    input_routes = np.array([routed(0, np.unique(core_of[r])) for r in reached], np.int64)
    input_routes = input_routes.reshape(-1, len(ROUTES))
    longest = max((len(r[0]) for r in route.values()), default=0)
    uses = []
    for c in cores:
        idx = np.asarray(c.neurons, np.int64)
        pre = np.unique(targets[idx].indices)
        fan_in = pre.size + int(graph.input_synapses[idx].any())
        splls = tuple(sorted(set(graph.spll[idx].tolist())))
        uses.append(GraphCore(c.index, len(c.configs), len(c.thresholds), fan_in,
                              int(fan_out[c.index]), c.synapses, clock=c.clock, splls=splls,
                              neurons=idx.size))  # fmt: skip
    problems = _problems(graph, uses, onto, res, limits)
    counted = "thresholds_per_core" in res
    return GraphFit(
        profile.name, graph, core_of, tuple(uses), res.value("cores_per_chip"),
        res.value("chips") * res.value("cores_per_chip"), res.value("chips"),
        int(np.unique(keys).size), int(np.unique(thr).size) if counted else None,
        routes, input_routes, longest,
        tuple(problems), chip.assumed_among(used),
    )  # fmt: skip


def _problems(graph: NeuronGraph, uses: list[GraphCore], onto, res, limits: dict) -> list[str]:
    """Why the placement ``uses`` does not fit the chip (empty: it does)."""
    out = []
    most = int(onto.max(initial=0))
    for key, where in (("synapses_per_neuron", "the chip gives a neuron"),
                       ("synapses_per_core", "one core holds")):  # fmt: skip
        if key in limits and most > limits[key]:
            out.append(f"a neuron needs {most} synapses onto it, {where} {limits[key]} ({key})")
    out += axon_problems(uses, limits)
    available = res.value("chips") * res.value("cores_per_chip")
    if len(uses) > available:
        configs = limits.get("configs_per_core")
        out.append(
            f"needs {len(uses)} cores for {graph.neurons} neurons "
            f"({limits['neurons_per_core']} per core"
            + (f", {configs} configurations per core" if configs is not None else "")
            + f", each sPLL's construction on one core), the profile allows {available} "
            f"({res.value('chips')} chip(s) x {res.value('cores_per_chip')} cores)"
        )
    return out


def graph_counts(fit: GraphFit, spikes, n_input_spikes, duration: float,
                 clocked: bool) -> GraphCounts:  # fmt: skip
    """Counts of a run (module docstring): ``spikes`` of every neuron, shape ``(n,)``, and
    ``n_input_spikes`` in ``duration`` [s] (one count, or one per input of a graph of several:
    each input's spikes reach its own synapses); neuron updates per step on a ``clocked``
    chip."""
    g = fit.graph
    s = np.asarray(spikes, dtype=np.int64)
    if s.shape != (g.neurons,):
        raise ValueError(f"spike counts must have shape ({g.neurons},), got {s.shape}")
    n_k = _input_spikes(g, n_input_spikes)
    n_in = int(n_k.sum())
    inputs = int(n_k @ g.input_fan_out)
    deliveries = int(s @ g.fan_out)
    steps = tuple(n_steps(duration, dt) for dt in g.dts) if clocked else ()
    if clocked:
        updates = sum(int(np.sum(g.clock == k)) * st for k, st in enumerate(steps))
    else:
        updates = inputs + deliveries
    # Per kind of route (ROUTES), the input's and the neurons'; the input comes from off the
    # chip, so every input message crosses into a core.
    of_input = n_k @ fit.input_routes[:, [0, 0, 2, 3]]
    per = [{"input": int(a), "neurons": int(b)} for a, b in zip(of_input, s @ fit.routes,
                                                                   strict=True)]  # fmt: skip
    return GraphCounts(
        n_in, inputs, int(s.sum()), *per, int(updates), sum(steps) if clocked else None,
        deliveries=deliveries, clock_steps=steps,
    )  # fmt: skip


def _input_spikes(graph: NeuronGraph, n_input_spikes) -> np.ndarray:
    """Spikes of each of the graph's ``K`` inputs, shape ``(K,)`` int64, from a count per input
    or, for a graph of one input, one count."""
    n = np.atleast_1d(np.asarray(n_input_spikes, dtype=np.int64))
    k = graph.input_fan.shape[1]
    if n.shape != (k,):
        raise ValueError(f"the graph has {k} input(s), got {n.size} input-spike count(s)")
    return n


def _clock_latency(fit: GraphFit, counts: GraphCounts, spikes: np.ndarray, input_spikes,
                   timing):  # fmt: skip
    """Per clock, its step latency [s] (module docstring)."""
    g = fit.graph
    t = {k: timing.value(k, 0.0) for k in ("neuron_update", "synaptic_event", "spike",
                                          "message", "hop", "barrier")}  # fmt: skip
    into = g.synapses @ spikes + g.input_fan @ input_spikes  # events per neuron
    out = []
    for k, steps in enumerate(counts.clock_steps):
        work = [
            c.neurons * t["neuron_update"]
            + (into[fit.core_of == c.core].sum() * t["synaptic_event"]
               + spikes[fit.core_of == c.core].sum() * (t["spike"] + t["message"])) / steps
            for c in fit.cores if c.clock == k
        ]  # fmt: skip
        out.append(max(work, default=0.0) + fit.longest_route * t["hop"] + t["barrier"])
    return out


def graph_cost(fit: GraphFit, profile: Profile | str, spikes, n_input_spikes: int,
               duration: float) -> SampleCost:  # fmt: skip
    """Energy per category (:data:`GRAPH_CATEGORIES`), step latency and real-time factor of a
    run of ``fit``'s graph on ``profile`` (module docstring): ``spikes`` of every neuron, shape
    ``(n,)``, ``n_input_spikes`` input spikes in ``duration`` [s]. Clocked at the graph's own
    steps on a fixed-point profile (not the profile's ``dt``), event-driven on an analog one."""
    profile = load_profile(profile)
    chip = chip_of(profile)
    if not fit.cores:
        raise ValueError(f"no placement on {fit.profile!r}: {'; '.join(fit.problems)}")
    clocked = isinstance(profile, FixedPointProfile)
    s = np.asarray(spikes, dtype=np.int64)
    n_k = _input_spikes(fit.graph, n_input_spikes)
    counts = graph_counts(fit, s, n_k, duration, clocked)
    clock = None if not clocked else (None, None, None)
    if clocked and any(k in chip.timing for k in ("neuron_update", "synaptic_event")):
        latency = _clock_latency(fit, counts, s, n_k, chip.timing)
        factors = [x / dt for x, dt in zip(latency, fit.graph.dts, strict=True)]
        slowest = int(np.argmax(factors))
        busy = max(x * st for x, st in zip(latency, counts.clock_steps, strict=True))
        clock = (latency[slowest], factors[slowest], busy)
    return priced(profile.name, chip, counts, duration, (fit.n_chips, fit.n_cores),
                  fit.assumed, clock, GRAPH_CATEGORIES)  # fmt: skip
