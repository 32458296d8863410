"""Where each neuron of an sPLL network goes on a chip (the placement rules of
:mod:`quantize.resources`' docstring): the configuration of each neuron, first-fit onto cores
within a profile's per-core limits, the mesh of routers a message crosses, and why a placement
needs more cores than the chip has."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from spll_hw.params import PARAM_NAMES

from .chip_tables import DEFAULT_CONFIG_SHARES
from .core import QuantizedNetwork
from .fixed_point import FIXED_PARAM_NAMES
from .profiles import FixedPointProfile


class Fitting:
    """The verdict of a placement on a chip (:class:`~quantize.resources.ResourceReport`,
    :class:`~quantize.graph_cost.GraphFit`, :class:`~quantize.readout.ReadoutFit`): it fits
    when ``problems``, why it does not, is empty."""

    profile: str
    problems: tuple[str, ...]

    @property
    def fits(self) -> bool:
        return not self.problems

    def verdict(self) -> dict:
        """What every ``to_dict`` of a placement starts with: ``profile`` (its name), ``fits``
        and ``problems``."""
        return {"profile": self.profile, "fits": self.fits, "problems": list(self.problems)}


#: Parameters of each configuration group, per neuron, as realised SI values (analog chips).
SI_GROUPS = {
    "tde": {
        "decay": ("tau_tde_fac", "tau_tde_trg", "tau_tde"),
        "threshold": ("v_tde_thr", "c_tde"),
        "refractory": ("t_tde_refr",),
        "offset": (),
        "gain": ("g_tde_fac", "g_tde_trg"),
    },
    "cco": {
        "decay": ("tau_cco_syn", "tau_cco"),
        "threshold": ("v_cco_thr", "c_cco"),
        "refractory": ("t_cco_refr",),
        "offset": ("i_cco_offset",),
        "gain": ("g_cco",),
    },
}
#: The same groups as the integer columns of a fixed-point chip.
FIXED_GROUPS = {
    "tde": {
        "decay": ("fac_decay", "trg_decay", "tde_decay"),
        "threshold": ("tde_threshold",),
        "refractory": ("tde_refr",),
        "offset": (),
        "gain": ("fac_weight", "trg_mantissa", "trg_shift", "tde_current_shift"),
    },
    "cco": {
        "decay": ("cco_syn_decay", "cco_decay"),
        "threshold": ("cco_threshold",),
        "refractory": ("cco_refr",),
        "offset": ("cco_bias",),
        "gain": ("cco_weight", "cco_current_shift"),
    },
}
#: Synapses onto each neuron: the TDE's facilitatory and trigger synapse, the CCO's feedback.
SYNAPSES_ONTO = {"tde": 2, "cco": 1}


def config_keys(q: QuantizedNetwork, shares: Sequence[str], kind: str) -> list[tuple]:
    """Per sPLL, the configuration of its ``kind`` neuron (``"tde"``/``"cco"``): a tuple of
    the realised values of the groups in ``shares``."""
    if isinstance(q.profile, FixedPointProfile):
        columns = [c for g in shares for c in FIXED_GROUPS[kind][g]]
        idx = [FIXED_PARAM_NAMES.index(c) for c in columns]
        return [tuple(int(v) for v in row) for row in q.fixed.matrix[:, idx]]
    names = [c for g in shares for c in SI_GROUPS[kind][g]]
    programmed = q.requested.matrix()
    offset = PARAM_NAMES.index("i_cco_offset")
    programmed[:, offset] = q.network.matrix()[:, offset]
    idx = [PARAM_NAMES.index(c) for c in names]
    return [tuple(float(v) for v in row) for row in programmed[:, idx]]


class Core:
    """A core being filled."""

    def __init__(self, index: int) -> None:
        self.index = index
        self.tdes: list[int] = []
        self.ccos: list[int] = []
        self.compartments = 0
        self.configs: dict[tuple, int] = {}
        self.thresholds: set = set()
        self.synapses = 0


@dataclass(frozen=True)
class Item:
    kind: str
    spll: int
    config: tuple
    threshold: object
    compartments: int
    config_weight: int


def fits(core: Core, item: Item, limits: dict) -> bool:
    if core.compartments + item.compartments > limits["neurons_per_core"]:
        return False
    cap = limits.get("configs_per_core")
    key = (item.kind, item.config)
    if cap is not None and key not in core.configs:
        if sum(core.configs.values()) + item.config_weight > cap:
            return False
    cap = limits.get("thresholds_per_core")
    if cap is not None and item.threshold not in core.thresholds:
        if len(core.thresholds) + 1 > cap:
            return False
    cap = limits.get("synapses_per_core")
    return cap is None or core.synapses + SYNAPSES_ONTO[item.kind] <= cap


def too_big_for_a_core(tde_comp: int, limits: dict) -> str:
    """Why a TDE of ``tde_comp`` compartments does not fit even an empty core (``""``: it
    does; a CCO, one compartment, configuration and synapse, always does)."""
    needs = (
        ("neurons_per_core", tde_comp, "compartments"),
        ("configs_per_core", tde_comp, "configurations"),
        ("synapses_per_core", SYNAPSES_ONTO["tde"], "synapses"),
    )
    over = [(key, need, what) for key, need, what in needs if need > limits.get(key, need)]
    if not over:
        return ""
    return f"a TDE of {tde_comp} compartment(s) does not fit one core: " + ", ".join(
        f"it needs {need} {what}, the profile allows {limits[key]} ({key})"
        for key, need, what in over
    )


@dataclass(frozen=True)
class CoreLoad:
    """What a placement puts on one core, counted alike for an sPLL network
    (:class:`~quantize.resources.CoreUse`) and a graph of neurons
    (:class:`~quantize.graph_cost.GraphCore`).

    Attributes:
        core: core index (chip ``core // cores_per_chip``).
        configs: distinct configurations used.
        thresholds: distinct thresholds.
        fan_in: input axons (one per input and per presynaptic neuron with a synapse here).
        fan_out: output axons (one per neuron and destination core).
        synapses: synapses onto its neurons.
    """

    core: int
    configs: int
    thresholds: int
    fan_in: int
    fan_out: int
    synapses: int

    def cells(self, thresholds_counted: bool) -> str:
        """The placement table's last cells, ``configs | thresholds | fan-in | fan-out |
        synapses |`` (thresholds ``-`` where the chip does not count them)."""
        thr = self.thresholds if thresholds_counted else "-"
        return f"{self.configs} | {thr} | {self.fan_in} | {self.fan_out} | {self.synapses} |"


def axon_problems(uses: Sequence, limits: dict) -> list[str]:
    """Why the placed cores ``uses`` (each with its ``fan_in`` and ``fan_out`` axons) exceed
    the axons per core of ``limits`` (``fan_in_per_core``, ``fan_out_per_core``; absent: no
    limit); empty where they do not."""
    out = []
    for key, attr in (("fan_in_per_core", "fan_in"), ("fan_out_per_core", "fan_out")):
        worst = max((getattr(u, attr) for u in uses), default=0)
        if key in limits and worst > limits[key]:
            out.append(f"a core needs {worst} {attr.replace('_', '-')} axons, the profile allows "
                       f"{limits[key]} ({key})")  # fmt: skip
    return out


def place(items: list[Item], limits: dict) -> list[Core]:
    """First-fit of ``items`` (in order) onto as many cores as needed."""
    cores: list[Core] = []
    for item in items:
        core = next((c for c in cores if fits(c, item, limits)), None)
        if core is None:
            core = Core(len(cores))
            cores.append(core)
        (core.tdes if item.kind == "tde" else core.ccos).append(item.spll)
        core.compartments += item.compartments
        core.configs[(item.kind, item.config)] = item.config_weight
        core.thresholds.add(item.threshold)
        core.synapses += SYNAPSES_ONTO[item.kind]
    return cores


class Mesh:
    """Router positions of cores: chip, tile column and row."""

    def __init__(self, res) -> None:
        self.per_chip = res.value("cores_per_chip")
        self.per_tile = res.value("cores_per_tile", 1)
        tiles = -(-self.per_chip // self.per_tile)
        self.columns = res.value("mesh_columns", tiles)

    def where(self, core: int) -> tuple[int, int, int]:
        chip, local = divmod(core, self.per_chip)
        tile = local // self.per_tile
        return chip, tile % self.columns, tile // self.columns

    def route(self, src: int, dst: int) -> tuple[set, set]:
        """Router edges and chip edges of the X-then-Y route from core ``src`` to ``dst``
        (between chips: to the same position on the next chip of the chain)."""
        (c0, x0, y0), (c1, x1, y1) = self.where(src), self.where(dst)
        chip_edges = {
            (min(c, c + 1), max(c, c + 1)) for c in range(min(c0, c1), max(c0, c1))
        }  # fmt: skip
        edges = set()
        x, y = x0, y0
        while x != x1:
            step = 1 if x1 > x else -1
            edges.add((c1, (x, y), (x + step, y)))
            x += step
        while y != y1:
            step = 1 if y1 > y else -1
            edges.add((c1, (x, y), (x, y + step)))
            y += step
        return edges, chip_edges


def placement(
    keys: dict[str, list], thr: dict[str, list], tde_comp: int, limits: dict, inputs: np.ndarray
) -> list[Core]:
    """Cores of the placement (module docstring): sPLLs by configuration (then input) and, with
    several inputs, by input then configuration; the one with fewer cores, then fewer input
    axons."""
    n = inputs.size
    orders = [sorted(range(n), key=lambda i: (keys["tde"][i], keys["cco"][i], inputs[i]))]
    if inputs.max() > 0:
        orders.append(sorted(range(n), key=lambda i: (inputs[i], keys["tde"][i], keys["cco"][i])))
    placements = []
    for order in orders:
        items = []
        for i in order:
            items.append(Item("tde", i, keys["tde"][i], thr["tde"][i], tde_comp, tde_comp))
            items.append(Item("cco", i, keys["cco"][i], thr["cco"][i], 1, 1))
        placements.append(place(items, limits))
    return min(placements, key=lambda cores: (len(cores), input_axons(cores, inputs)))


def input_axons(cores: list[Core], inputs: np.ndarray) -> int:
    """Input axons of a placement: one per input and core holding a TDE it drives."""
    return sum(len(set(inputs[c.tdes].tolist())) for c in cores)


def input_routes(
    cores: list[Core], inputs: np.ndarray, mesh: Mesh, multicast: bool
) -> tuple[np.ndarray, int]:
    """Per input, ``(messages, hops, chip hops)`` of one of its spikes from core 0 to the cores
    holding its TDEs, shape ``(n_inputs, 3)``, and the longest of those routes [hops]."""
    routes = np.zeros((int(inputs.max()) + 1, 3), np.int64)
    longest = 0
    for k in range(routes.shape[0]):
        dest = sorted({c.index for c in cores if any(inputs[i] == k for i in c.tdes)})
        in_edges, in_chip = set(), set()
        for d in dest:
            edges, chips = mesh.route(0, d)
            in_edges |= edges
            in_chip |= chips
            routes[k, 1:] += (len(edges), len(chips))
            longest = max(longest, len(edges))
        routes[k, 0] = len(dest)
        if multicast:
            routes[k] = (1, len(in_edges), len(in_chip))
    return routes, longest


def why_cores(
    needed: int, available: int, res, n: int, tde_comp: int, tde_cfg: int, cco_cfg: int, thr
) -> str:
    """``"needs 5 cores for 5 distinct neuron configurations (1 per core), the profile allows
    4 (1 chip x 4 cores)"``: the binding limit named."""
    reasons = [
        (
            -(-n * (tde_comp + 1) // res.value("neurons_per_core")),
            f"{n * (tde_comp + 1)} compartments ({res.value('neurons_per_core')} per core)",
        )
    ]
    if "configs_per_core" in res:
        shares = "/".join(res.value("config_shares", DEFAULT_CONFIG_SHARES))
        weight = tde_cfg * tde_comp + cco_cfg
        per = res.value("configs_per_core")
        reasons.append(
            (
                -(-weight // per),
                f"{weight} distinct {shares} configurations "
                f"({tde_cfg} TDE x {tde_comp} compartment(s) + {cco_cfg} CCO; "
                f"{per} per core)",
            )
        )
    if thr is not None:
        per = res.value("thresholds_per_core")
        reasons.append((-(-thr // per), f"{thr} distinct thresholds ({per} per core)"))
    bound, why = max(reasons, key=lambda r: r[0])
    if bound < needed:
        why += " and the packing of the rest"
    return (
        f"needs {needed} cores for {why}, the profile allows {available} "
        f"({res.value('chips')} chip(s) x {res.value('cores_per_chip')} cores)"
    )  # fmt: skip
