"""Whether an sPLL network fits a chip, where each neuron goes, and what one sample costs
(the placement itself: :mod:`quantize.placement`).

A profile's ``[resources]``, ``[timing]`` and ``[energy]`` tables (:mod:`quantize.profiles`)
describe the chip; this module maps a network onto it and counts. It does not simulate: the
event counts of a sample come from a :class:`~spll_hw.result.SimulationResult` of any backend.

**How an sPLL maps.** Per sPLL ``i``: the TDE takes ``tde_compartments`` compartments (1: one
programmable neuron with three state words, as :mod:`mappings.lava` builds it for Loihi 2; 2: a
facilitatory compartment joined to the soma, for chips without programmable neurons); the CCO
is one compartment. Three synapses: facilitatory (input → TDE_i), trigger (CCO_i → TDE_i) and
feedback (TDE_i → CCO_i). The input is one axon per core that holds TDEs.

**Configurations.** Neurons on one core share a limited number of configurations: the realised
values of the parameter groups in ``config_shares`` (``decay``, ``refractory``, ``threshold``,
``offset``, ``gain``). On a fixed-point chip they are compared as the integers the chip holds
(:data:`quantize.fixed_point.FIXED_PARAM_NAMES`); on an analog chip as the programmed values
(the requested parameters with the realised, shared offset levels; mismatch is the device, not
a configuration). A TDE of ``k`` compartments uses ``k`` configurations. ``thresholds_per_core``
counts distinct thresholds separately (Loihi's threshold profiles).

**Placement.** sPLLs sorted by their (TDE, CCO) configurations, the TDE then the CCO of each
placed first-fit on the lowest-numbered core where it fits (compartments, configurations,
thresholds, synapses); a full core opens the next.

**Several inputs** (``inputs``: the input of each sPLL, e.g. the sensor channel of a
multichannel network whose channels each drive their own sPLLs): every input is one axon on each
core holding a TDE it drives, and its spikes go to those cores only. The placement is tried
sorted by configuration then input and by input then configuration (a channel's sPLLs kept
together); the one with fewer cores wins, then the one with fewer input axons (fewer input
messages). With one input both orders are the first. Cores lie on chips of ``cores_per_chip``, in
tiles of ``cores_per_tile`` behind one router on a mesh of ``mesh_columns`` tiles per row;
messages take X-then-Y routes between tiles (``hop``) and chips lie on a chain (``chip_hop``).
The input enters at core 0 (the host interface is assumed at the mesh origin).

**Messages.** On a unicast chip (Loihi) a spike is one message per destination core, its own
included; on a ``multicast`` chip (SpiNNaker, DYNAP-SE2) one packet per spike that routers copy
along a tree (hops: the edges of the union of the routes). An input spike goes to the cores
holding the TDEs of its own input.

**Cost of a sample** (:func:`sample_cost`) from the counts of one run: input deliveries
``n_in × n_spll`` (``Σ_k n_in[k] × sPLLs of input k`` with several inputs), trigger deliveries
``Σ cco_counts``, feedback deliveries ``Σ tde_counts``
(each one synaptic event), spikes ``Σ tde + Σ cco``, messages and hops from the placement,
neuron updates ``compartments × steps`` on a clocked chip (``steps = round(duration / dt)``) or
one per synaptic event on an event-driven one. Energy = counts × the ``[energy]`` figures, plus
``static_power × chips + core_power × cores`` times the window (:mod:`quantize.pricing`). Step
latency = the busiest core's mean work per step (updates, synaptic events, spikes, messages) +
the longest route's hops + the barrier; real-time factor = step latency / dt (≤ 1 keeps up with
real time).
A timer-paced chip spends the sample's duration on chip (longer when it cannot keep up); a
free-running one ``steps × step latency``; an analog chip runs in physical time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spll_hw.model.grid import n_steps
from spll_hw.network import Network

from .analog import CircuitBudgetError
from .chip_tables import CHIP_KEYS, DEFAULT_CONFIG_SHARES, ChipSpec
from .core import QuantizedNetwork, quantize
from .placement import (
    SYNAPSES_ONTO,
    CoreLoad,
    Fitting,
    Mesh,
    axon_problems,
    config_keys,
    input_routes,
    placement,
    too_big_for_a_core,
    why_cores,
)
from .pricing import ENERGY_CATEGORIES as ENERGY_CATEGORIES  # re-exported: its old home
from .pricing import POWER_KEYS as POWER_KEYS
from .pricing import EventCounts, SampleCost, priced
from .profiles import FixedPointProfile, Profile, load_profile

#: Event types of a sample, in report order.
EVENTS = ("input", "trigger", "feedback")


class ChipError(ValueError):
    """A profile without the tables a question needs (e.g. no ``[resources]``)."""


@dataclass(frozen=True)
class CoreUse(CoreLoad):
    """What one core of an sPLL network holds: :class:`~quantize.placement.CoreLoad` (a TDE
    config counts ``tde_compartments``; input axons: one per input driving a TDE here, one per
    CCO whose TDE is here, one per TDE whose CCO is here), and

    Attributes:
        tdes, ccos: sPLL indices of the TDEs and CCOs on it.
        compartments: compartments used.
    """

    tdes: tuple[int, ...]
    ccos: tuple[int, ...]
    compartments: int


@dataclass(frozen=True)
class ResourceReport(Fitting):
    """An sPLL network on a chip: what it needs, where it goes, whether it fits.

    Attributes:
        profile: profile name.
        n_spll: sPLLs.
        tde_compartments: compartments per TDE.
        neurons: ``2 n_spll`` (TDE + CCO per sPLL).
        compartments: ``n_spll (tde_compartments + 1)``.
        synapses: ``3 n_spll``.
        tde_configs, cco_configs: distinct configurations of the TDEs and CCOs.
        thresholds: distinct thresholds (``None`` when the chip does not count them apart).
        tde_core, cco_core: core of each sPLL's TDE and CCO, shape ``(n_spll,)`` int64.
        cores: per-core use (:class:`CoreUse`).
        cores_available, chips_available: what the profile offers.
        input_messages: messages per input spike (destination cores, or 1 when multicast),
            summed over the inputs (one spike on every input).
        input_hops, input_chip_hops: router and chip hops per input spike, summed likewise.
        trigger_hops, feedback_hops: hops of each sPLL's trigger (CCO → TDE) and feedback
            (TDE → CCO) message, shape ``(n_spll,)``; ``*_chip_hops`` likewise between chips.
        longest_route: most hops of any message [hops].
        problems: why it does not fit (empty when it fits).
        assumed: ``table.key`` of the assumed figures the report uses.
        quantized: the realised network (``None`` when the profile refused it).
        inputs: the input of each sPLL, shape ``(n_spll,)`` int64 (all 0: one input).
        input_routes: per input ``k``, ``(messages, hops, chip hops)`` per spike of input
            ``k``, shape ``(n_inputs, 3)`` int64 (empty when nothing was placed).
    """

    profile: str
    n_spll: int
    tde_compartments: int
    neurons: int
    compartments: int
    synapses: int
    tde_configs: int
    cco_configs: int
    thresholds: int | None
    tde_core: np.ndarray
    cco_core: np.ndarray
    cores: tuple[CoreUse, ...]
    cores_per_chip: int
    cores_available: int
    chips_available: int
    input_messages: int
    input_hops: int
    input_chip_hops: int
    trigger_hops: np.ndarray
    feedback_hops: np.ndarray
    trigger_chip_hops: np.ndarray
    feedback_chip_hops: np.ndarray
    longest_route: int
    problems: tuple[str, ...]
    assumed: tuple[str, ...]
    quantized: QuantizedNetwork | None = field(default=None, repr=False)
    inputs: np.ndarray | None = field(default=None, repr=False)
    input_routes: np.ndarray | None = field(default=None, repr=False)

    @property
    def input_of(self) -> np.ndarray:
        """The input of each sPLL, shape ``(n_spll,)`` int64."""
        return np.zeros(self.n_spll, np.int64) if self.inputs is None else self.inputs

    @property
    def n_inputs(self) -> int:
        """Input spike trains the network has (1 unless ``inputs`` says more)."""
        return int(self.input_of.max()) + 1

    @property
    def n_cores(self) -> int:
        """Cores used."""
        return len(self.cores)

    @property
    def n_chips(self) -> int:
        """Chips used."""
        return max(1, -(-self.n_cores // self.cores_per_chip)) if self.cores else 0

    @property
    def crossing(self) -> dict[str, int]:
        """sPLLs whose trigger / feedback messages cross cores."""
        apart = int(np.sum(self.tde_core != self.cco_core))
        return {"trigger": apart, "feedback": apart}

    def to_dict(self) -> dict:
        return self.verdict() | {
            "n_spll": self.n_spll,
            "neurons": self.neurons,
            "compartments": self.compartments,
            "tde_compartments": self.tde_compartments,
            "synapses": self.synapses,
            "tde_configs": self.tde_configs,
            "cco_configs": self.cco_configs,
            "thresholds": self.thresholds,
            "cores": self.n_cores,
            "chips": self.n_chips,
            "cores_available": self.cores_available,
            "chips_available": self.chips_available,
            "input_messages_per_spike": self.input_messages,
            "input_hops_per_spike": self.input_hops,
            "spll_crossing_cores": self.crossing["trigger"],
            "inputs": self.n_inputs,
            "longest_route_hops": self.longest_route,
            "placement": [
                {
                    "core": c.core,
                    "tde": list(c.tdes),
                    "cco": list(c.ccos),
                    "compartments": c.compartments,
                    "configs": c.configs,
                    "thresholds": c.thresholds,
                    "fan_in": c.fan_in,
                    "fan_out": c.fan_out,
                    "synapses": c.synapses,
                }
                for c in self.cores
            ],  # fmt: skip
            "assumed": list(self.assumed),
        }

    def markdown(self) -> str:
        """The report as Markdown: totals, the fit verdict, per-core use."""
        thr = "-" if self.thresholds is None else str(self.thresholds)
        lines = [
            f"**{self.profile}**: {self.n_spll} sPLLs = {self.neurons} neurons, "
            f"{self.compartments} compartments (TDE: {self.tde_compartments}), "
            f"{self.synapses} synapses; configurations: {self.tde_configs} TDE + "
            f"{self.cco_configs} CCO, thresholds {thr}; {self.n_cores} core(s) on "
            f"{self.n_chips} chip(s) of {self.cores_available} core(s) on "
            f"{self.chips_available} chip(s).",
            "",
            "fits" if self.fits else "does not fit: " + "; ".join(self.problems),
            "",
            f"Messages: {self.input_messages} per input spike ({self.input_hops} hops)"
            + (f", summed over {self.n_inputs} inputs; " if self.n_inputs > 1 else "; ")
            + f"{self.crossing['trigger']} sPLL(s) have TDE and CCO on different cores "
            f"(their trigger and feedback messages cross cores); longest route "
            f"{self.longest_route} hop(s).",
        ]
        if self.cores:
            lines += [
                "",
                "| core | TDEs | CCOs | compartments | configs | thresholds | fan-in | fan-out "
                "| synapses |",
                "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
            ]
            lines += [
                f"| {c.core} | {len(c.tdes)} | {len(c.ccos)} | {c.compartments} | "
                + c.cells(self.thresholds is not None)
                for c in self.cores
            ]
        if self.assumed:
            lines += ["", "Assumed figures: " + ", ".join(self.assumed)]
        return "\n".join(lines)


def chip_of(profile: Profile) -> ChipSpec:
    """The profile's chip tables; :class:`ChipError` when it has no ``[resources]``."""
    chip = profile.chip
    if chip is None or not chip.resources.figures:
        raise ChipError(
            f"profile {profile.name!r} has no [resources] table: it says how the chip rounds a "
            "network, not what the chip holds (see quantize/profiles/loihi1.toml)"
        )
    return chip


def _checked_inputs(inputs, n: int) -> np.ndarray:
    """``inputs`` as an ``(n,)`` int64 array of input indices (``None``: all 0);
    ``ValueError`` for another shape, a negative index or an input that drives nothing."""
    if inputs is None:
        return np.zeros(n, np.int64)
    out = np.asarray(inputs)
    if out.shape != (n,) or not np.issubdtype(out.dtype, np.integer) or (out < 0).any():
        raise ValueError(
            f"inputs must give each of the {n} sPLLs its input as an integer >= 0, shape "
            f"({n},); got shape {out.shape} of {out.dtype}"
        )
    out = out.astype(np.int64)
    idle = sorted(set(range(int(out.max()) + 1)) - set(out.tolist()))
    if idle:
        raise ValueError(f"inputs {idle} drive no sPLL: number the inputs 0 to K-1")
    return out


def resource_report(
    network: Network,
    profile: Profile | str | Path,
    seed: int | None = None,
    inputs: Sequence[int] | np.ndarray | None = None,
) -> ResourceReport:
    """Map ``network`` onto chip ``profile`` (module docstring) and say whether it fits.

    Args:
        network: the requested network.
        profile: a profile with a ``[resources]`` table (name, path or loaded).
        seed: an analog profile's mismatch draw (default: the profile's own).
        inputs: the input spike train of each sPLL, indices ``0 … K-1``, shape ``(n_spll,)``
            (default: one input drives them all).

    Returns:
        A :class:`ResourceReport`; a network the profile cannot realise at all (e.g. more
        sPLL circuits than an analog chip's groups) gives a report with that problem, no
        placement and ``quantized = None``.

    Raises:
        ChipError: the profile has no ``[resources]`` table.
    """
    profile = load_profile(profile)
    chip = chip_of(profile)
    res = chip.resources
    n = network.n_spll
    inputs = _checked_inputs(inputs, n)
    tde_comp = res.value("tde_compartments")
    used = ["resources." + k for k in ("chips", "cores_per_chip", "neurons_per_core",
                                      "tde_compartments")]  # fmt: skip
    limits = _core_limits(res, used)
    shares = res.value("config_shares", DEFAULT_CONFIG_SHARES)
    available = res.value("chips") * res.value("cores_per_chip")
    problems: list[str] = []
    try:
        q = quantize(network, profile, seed=seed if profile.draws_mismatch else None)
    except CircuitBudgetError as exc:  # its fix depends on whether the sPLLs share one input
        problems.append(exc.for_channels() if inputs.max() > 0 else str(exc))
        q = None
    except ValueError as exc:
        problems.append(str(exc))
        q = None
    empty = np.zeros(n, dtype=np.int64)
    if q is None:
        return ResourceReport(
            profile.name, n, tde_comp, 2 * n, n * (tde_comp + 1), 3 * n, 0, 0, None, empty,
            empty, (), res.value("cores_per_chip"), available, res.value("chips"), 0, 0, 0,
            empty, empty, empty, empty, 0, tuple(problems), chip.assumed_among(used), None,
            inputs, np.zeros((0, 3), np.int64),
        )  # fmt: skip
    keys = {kind: config_keys(q, shares, kind) for kind in ("tde", "cco")}
    counted = "thresholds_per_core" in res
    thr = {kind: config_keys(q, ("threshold",), kind) if counted else [None] * n
           for kind in ("tde", "cco")}  # fmt: skip
    if "synapses_per_neuron" in res:
        used.append("resources.synapses_per_neuron")
        need = max(SYNAPSES_ONTO.values())
        if need > res.value("synapses_per_neuron"):
            problems.append(
                f"a TDE needs {need} synapses, the chip gives a neuron "
                f"{res.value('synapses_per_neuron')}"
            )
    too_big = too_big_for_a_core(tde_comp, limits)
    if too_big:
        problems.append(too_big)
        cores = []
    else:
        cores = placement(keys, thr, tde_comp, limits, inputs)
    tde_core = np.zeros(n, dtype=np.int64)
    cco_core = np.zeros(n, dtype=np.int64)
    for c in cores:
        tde_core[c.tdes] = c.index
        cco_core[c.ccos] = c.index
    n_tde_cfg, n_cco_cfg = len(set(keys["tde"])), len(set(keys["cco"]))
    n_thr = len(set(thr["tde"]) | set(thr["cco"])) if counted else None
    if cores and len(cores) > available:
        problems.append(
            why_cores(len(cores), available, res, n, tde_comp, n_tde_cfg, n_cco_cfg, n_thr)
        )
    uses = [_core_use(c, inputs) for c in cores]
    axons = {key: res.value(key) for key in ("fan_in_per_core", "fan_out_per_core") if key in res}
    used += [f"resources.{key}" for key in axons]
    problems += axon_problems(uses, axons)
    mesh = Mesh(res)
    multicast = bool(res.value("multicast", False))
    used += [f"resources.{k}" for k in ("cores_per_tile", "mesh_columns", "multicast") if k in res]
    routes, longest = input_routes(cores, inputs, mesh, multicast)
    hops, chip_hops, spll_longest = _spll_routes(mesh, tde_core, cco_core)
    longest = max(longest, spll_longest)
    return ResourceReport(
        profile.name, n, tde_comp, 2 * n, n * (tde_comp + 1), 3 * n, n_tde_cfg, n_cco_cfg,
        n_thr, tde_core, cco_core, tuple(uses), res.value("cores_per_chip"), available,
        res.value("chips"), *(int(v) for v in routes.sum(axis=0)),
        hops["trigger"], hops["feedback"], chip_hops["trigger"], chip_hops["feedback"], longest,
        tuple(problems), chip.assumed_among(used), q, inputs, routes,
    )  # fmt: skip


def _core_limits(res, used: list[str]) -> dict:
    """The per-core limits of a placement that ``res`` (a ``[resources]`` table) gives; appends
    the keys read to ``used``."""
    limits = {"neurons_per_core": res.value("neurons_per_core")}
    for key in ("configs_per_core", "thresholds_per_core", "synapses_per_core"):
        if key in res:
            limits[key] = res.value(key)
            used.append(f"resources.{key}")
    return limits


def _core_use(core, inputs: np.ndarray) -> CoreUse:
    """The :class:`CoreUse` of a placed core: an input axon per input driving a TDE there, then
    one per source neuron (each TDE's CCO, each CCO's TDE); an output axon per neuron."""
    fan_in = len(set(inputs[core.tdes].tolist())) + len(core.tdes) + len(core.ccos)
    return CoreUse(
        core.index, sum(core.configs.values()), len(core.thresholds), fan_in,
        len(core.tdes) + len(core.ccos), core.synapses, tdes=tuple(sorted(core.tdes)),
        ccos=tuple(sorted(core.ccos)), compartments=core.compartments,
    )  # fmt: skip


def _spll_routes(mesh: Mesh, tde_core: np.ndarray, cco_core: np.ndarray):
    """Per event (``"trigger"``: CCO -> TDE, ``"feedback"``: TDE -> CCO), the router and chip
    hops of each sPLL's message, shape ``(n_spll,)`` int64 each, and the longest route
    [hops]."""
    n = tde_core.size
    hops = {e: np.zeros(n, np.int64) for e in ("trigger", "feedback")}
    chip_hops = {e: np.zeros(n, np.int64) for e in ("trigger", "feedback")}
    longest = 0
    for i in range(n):
        for event, (src, dst) in (("trigger", (cco_core[i], tde_core[i])),
                                  ("feedback", (tde_core[i], cco_core[i]))):  # fmt: skip
            edges, chips = mesh.route(int(src), int(dst))
            hops[event][i], chip_hops[event][i] = len(edges), len(chips)
            longest = max(longest, len(edges))
    return hops, chip_hops, longest


def _per_input(report: ResourceReport, n_input_spikes) -> np.ndarray:
    """The input spikes of each of the report's inputs, shape ``(n_inputs,)`` int64."""
    n_in = np.atleast_1d(np.asarray(n_input_spikes))
    if n_in.shape != (report.n_inputs,) or not np.issubdtype(n_in.dtype, np.integer):
        raise ValueError(
            f"the network has {report.n_inputs} input(s): give the input spikes of each as "
            f"integers, shape ({report.n_inputs},); got {np.asarray(n_input_spikes)!r}"
        )
    return n_in.astype(np.int64)


def event_counts(
    report: ResourceReport,
    tde_counts: np.ndarray,
    cco_counts: np.ndarray,
    n_input_spikes: int | Sequence[int] | np.ndarray,
    duration: float,
    dt: float | None,
) -> EventCounts:
    """Counts of one sample on the placement of ``report`` (module docstring).

    Args:
        report: a fitting :class:`ResourceReport` of the simulated network.
        tde_counts, cco_counts: spikes per sPLL, shape ``(n_spll,)``.
        n_input_spikes: input spikes of the sample; per input, shape ``(n_inputs,)``, for a
            report of several inputs.
        duration: simulated time [s].
        dt: time step [s] of a clocked chip; ``None`` for an event-driven (analog) one.
    """
    tde = np.asarray(tde_counts, dtype=np.int64)
    cco = np.asarray(cco_counts, dtype=np.int64)
    if tde.shape != (report.n_spll,) or cco.shape != (report.n_spll,):
        raise ValueError(
            f"spike counts must have shape ({report.n_spll},), got {tde.shape} and {cco.shape}"
        )
    if not report.cores:
        raise ValueError(f"no placement on {report.profile!r}: {'; '.join(report.problems)}")
    per_input = _per_input(report, n_input_spikes)
    n_in = int(per_input.sum())
    routes = report.input_routes
    apart = report.tde_core != report.cco_core
    inputs = int(per_input[report.input_of].sum())  # each sPLL gets its own input's spikes
    trigger, feedback = int(cco.sum()), int(tde.sum())
    input_messages = int(per_input @ routes[:, 0])
    steps = None if dt is None else n_steps(duration, dt)
    updates = report.compartments * steps if steps is not None else inputs + trigger + feedback
    return EventCounts(
        input_spikes=n_in,
        input_deliveries=inputs,
        trigger_deliveries=trigger,
        feedback_deliveries=feedback,
        spikes=trigger + feedback,
        messages={"input": input_messages, "trigger": trigger, "feedback": feedback},
        crossing={
            # The input comes from off the chip: every input message crosses into a core.
            "input": input_messages,
            "trigger": int(cco[apart].sum()),
            "feedback": int(tde[apart].sum()),
        },
        hops={
            "input": int(per_input @ routes[:, 1]),
            "trigger": int(cco @ report.trigger_hops),
            "feedback": int(tde @ report.feedback_hops),
        },  # fmt: skip
        chip_hops={
            "input": int(per_input @ routes[:, 2]),
            "trigger": int(cco @ report.trigger_chip_hops),
            "feedback": int(tde @ report.feedback_chip_hops),
        },  # fmt: skip
        neuron_updates=int(updates),
        steps=steps,
        per_input=tuple(int(k) for k in per_input),
    )


def _step_latency(report: ResourceReport, counts: EventCounts, tde, cco, timing) -> float:
    """Mean time of one step [s] (module docstring)."""
    t = {k: timing.value(k, 0.0) for k in ("neuron_update", "synaptic_event", "spike",
                                          "message", "hop", "barrier")}  # fmt: skip
    steps = counts.steps
    per_input = np.asarray(counts.per_input, dtype=np.int64)
    work = []
    for c in report.cores:
        tdes, ccos = list(c.tdes), list(c.ccos)
        inputs = int(per_input[report.input_of[tdes]].sum())
        events = inputs + int(cco[tdes].sum()) + int(tde[ccos].sum())
        spikes = int(tde[tdes].sum()) + int(cco[ccos].sum())
        work.append(
            c.compartments * t["neuron_update"]
            + (events * t["synaptic_event"] + spikes * (t["spike"] + t["message"])) / steps
        )
    return max(work) + report.longest_route * t["hop"] + t["barrier"]


def sample_cost(
    report: ResourceReport,
    profile: Profile | str | Path,
    tde_counts: np.ndarray,
    cco_counts: np.ndarray,
    n_input_spikes: int | Sequence[int] | np.ndarray,
    duration: float,
) -> SampleCost:
    """Energy per category, step latency and real-time factor of one sample (module
    docstring) on the placement of ``report``; clocked on a fixed-point profile (its ``dt``),
    event-driven on an analog one. Arrays have shape ``(n_spll,)``."""
    profile = load_profile(profile)
    chip = chip_of(profile)
    dt = profile.dt if isinstance(profile, FixedPointProfile) else None
    counts = event_counts(report, tde_counts, cco_counts, n_input_spikes, duration, dt)
    clock = None if dt is None else (None, None, None)
    if dt is not None and any(k in chip.timing for k in ("neuron_update", "synaptic_event")):
        tde = np.asarray(tde_counts, dtype=np.int64)
        cco = np.asarray(cco_counts, dtype=np.int64)
        step = _step_latency(report, counts, tde, cco, chip.timing)
        clock = (step, step / dt, counts.steps * step)
    return priced(profile.name, chip, counts, duration, (report.n_chips, report.n_cores),
                  report.assumed, clock)  # fmt: skip


_SI_UNITS = {"seconds": "s", "joules": "J", "watts": "W"}


def chip_figures(profile: Profile | str | Path) -> list[dict]:
    """Every figure of the profile's chip tables: ``table``, ``key``, ``value``, ``meaning``
    (with its unit), ``source``, ``assumed``, ``unit`` (``"s"``, ``"J"``, ``"W"`` or ``""``)
    and the range's ``low``, ``high`` (``None``: one number), ``low_source``, ``high_source``;
    empty for a profile without them."""
    profile = load_profile(profile)
    if profile.chip is None:
        return []
    out = []
    for table in profile.chip.tables():
        for key, fig in table.figures:
            value = list(fig.value) if isinstance(fig.value, tuple) else fig.value
            spec = CHIP_KEYS[table.table][key]
            out.append({"table": table.table, "key": key, "value": value, "meaning": spec.doc,
                        "source": fig.source, "assumed": fig.assumed,
                        "unit": _SI_UNITS.get(spec.kind, ""), "low": fig.low, "high": fig.high,
                        "low_source": fig.low_source, "high_source": fig.high_source})  # fmt: skip
    return out
