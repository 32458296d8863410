"""A spiking readout on a chip: where its neurons go and what it adds to a classification.

The readout (:mod:`spll_hw.multichannel.readout`) is one non-leaky integrate-and-fire neuron per
class, with a synapse from every TDE of the network (its weight per spike) and a constant bias
current. On a chip it is ``classes`` neurons of one compartment and one configuration (the same
decay, refractory period and threshold; the bias is per neuron) and ``classes x features``
synapses, placed on **cores of its own after the network's** (:func:`readout_fit`): as many
neurons per core as its compartments and synapse memory hold (``min(neurons_per_core,
synapses_per_core // features)``). Every readout core takes one input axon per TDE
(``features``), and every TDE one more output axon per readout core.

**Messages.** On a unicast chip every TDE spike sends one more message per readout core, routed
X-then-Y from its core (hops, chip hops); on a multicast chip its one packet (already counted as
the feedback message) is copied further: no more messages, and the hops are the edges the
readout's routes add to the tree of its feedback route.

**Cost of a classification** (:func:`readout_cost`) from the TDE counts of one run: deliveries
``sum(tde) x classes`` (synaptic events), messages and hops from the placement, neuron updates
``classes x steps`` on a clocked chip or one per delivery on an event-driven one, and one spike
(the winner's: the decision). Energy = counts x the ``[energy]`` figures; apart, ``core_power``
of the readout's cores and ``static_power`` of chips it adds, over the network's window
(powered for the whole sample, longer where the chip cannot keep up).
The readout's work per step (updates, deliveries, the decision spike) is reported; it is not
folded into the network's step latency.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spll_hw.model.grid import n_steps

from .placement import Fitting, Mesh
from .pricing import TRAFFIC_CATEGORIES, joules
from .profiles import FixedPointProfile, Profile, load_profile
from .resources import ResourceReport, chip_of

#: Energy categories of the readout: (name, ``[energy]`` key, :class:`ReadoutCounts` field).
READOUT_CATEGORIES = (
    ("deliveries", "synaptic_event", "deliveries"),
    *TRAFFIC_CATEGORIES,
    ("spikes", "spike", "spikes"),
)


@dataclass(frozen=True)
class ReadoutFit(Fitting):
    """The readout on a chip, beside the network of ``report``.

    Attributes:
        profile: profile name.
        classes: readout neurons (one per class).
        features: TDEs driving each of them (the network's sPLLs).
        cores: core index of each readout core (after the network's).
        neurons: readout neurons on each of those cores.
        weight_bits: bits of one synapse's weight (a fixed-point chip's weight mantissa;
            ``None`` on an analog chip).
        messages, hops, chip_hops: what one spike of each TDE adds, shape ``(features,)``.
        problems: why it does not fit (empty when it fits).
        assumed: ``table.key`` of the assumed figures the placement uses.
    """

    profile: str
    classes: int
    features: int
    cores: tuple[int, ...]
    neurons: tuple[int, ...]
    weight_bits: int | None
    messages: np.ndarray
    hops: np.ndarray
    chip_hops: np.ndarray
    problems: tuple[str, ...]
    assumed: tuple[str, ...]

    @property
    def synapses(self) -> int:
        """Synapses of the readout, ``classes x features``."""
        return self.classes * self.features

    @property
    def synapse_bits(self) -> int | None:
        """Weight memory of the readout [bits] (``None`` on an analog chip)."""
        return None if self.weight_bits is None else self.synapses * self.weight_bits

    def to_dict(self) -> dict:
        return self.verdict() | {
            "classes": self.classes,
            "features": self.features,
            "cores": list(self.cores),
            "neurons_per_core": list(self.neurons),
            "synapses": self.synapses,
            "synapse_bits": self.synapse_bits,
            "messages_per_tde_spike": float(self.messages.mean()) if self.features else 0.0,
            "assumed": list(self.assumed),
        }

    def markdown(self) -> str:
        """One paragraph: neurons, cores, synapses, messages per TDE spike, verdict."""
        memory = "" if self.synapse_bits is None else f" ({self.synapse_bits / 8e3:.4g} kB)"
        where = ", ".join(f"core {c}: {k}" for c, k in zip(self.cores, self.neurons, strict=True))
        verdict = "fits" if self.fits else "does not fit: " + "; ".join(self.problems)
        return (
            f"**readout on {self.profile}**: {self.classes} neurons x {self.features} TDE "
            f"synapses = {self.synapses} synapses{memory}; {len(self.cores)} core(s) of its own "
            f"({where or 'none'}); {self.messages.mean() if self.features else 0:.3g} more "
            f"messages per TDE spike; {verdict}."
        )


def _problems(report: ResourceReport, res, classes: int, d: int) -> list[str]:
    """What keeps a readout of ``classes`` neurons of ``d`` synapses off the chip."""
    out = []
    if not report.cores:
        out.append("the network is not placed (its report says why)")
    for key, what in (("synapses_per_neuron", "synapses"), ("fan_in_per_core", "input axons"),
                      ("synapses_per_core", "synapses")):  # fmt: skip
        if key in res and d > res.value(key):
            out.append(f"a readout neuron needs {d} {what} (one per TDE), the profile "
                       f"allows {res.value(key)} ({key})")  # fmt: skip
    if "configs_per_core" in res and res.value("configs_per_core") < 1:
        out.append("the profile allows no configuration per core")
    return out


def readout_fit(report: ResourceReport, profile: Profile | str | Path, classes: int) -> ReadoutFit:
    """Place a readout of ``classes`` neurons driven by every TDE of ``report``'s network
    (module docstring); ``ValueError`` for fewer than 1 class."""
    if classes < 1:
        raise ValueError(f"a readout needs >= 1 class (one neuron each), got {classes}")
    profile = load_profile(profile)
    chip = chip_of(profile)
    res = chip.resources
    d = report.n_spll
    problems = _problems(report, res, classes, d)
    per_core = res.value("neurons_per_core")
    if "synapses_per_core" in res and d:
        per_core = min(per_core, res.value("synapses_per_core") // d)
    first = report.n_cores
    neurons: list[int] = []
    if not problems:
        left = classes
        while left:
            neurons.append(min(per_core, left))
            left -= neurons[-1]
    cores = tuple(range(first, first + len(neurons)))
    if cores and cores[-1] >= report.cores_available:
        problems.append(
            f"the network's {first} core(s) and the readout's {len(cores)} need "
            f"{cores[-1] + 1}, the profile allows {report.cores_available}"
        )
    if "fan_out_per_core" in res and cores:
        worst = max(c.fan_out + len(c.tdes) * len(cores) for c in report.cores)
        if worst > res.value("fan_out_per_core"):
            problems.append(
                f"with the readout a core needs {worst} output axons, the profile allows "
                f"{res.value('fan_out_per_core')} (fan_out_per_core)"
            )
    messages, hops, chip_hops = _routes(report, res, cores)
    used = [f"resources.{k}" for k in ("neurons_per_core", "synapses_per_core",
                                       "synapses_per_neuron", "fan_in_per_core",
                                       "fan_out_per_core", "multicast") if k in res]  # fmt: skip
    assumed = set(chip.assumed())
    bits = profile.weight_mantissa_bits if isinstance(profile, FixedPointProfile) else None
    return ReadoutFit(
        profile.name, classes, d, cores, tuple(neurons), bits, messages, hops, chip_hops,
        tuple(problems), tuple(k for k in used if k in assumed),
    )  # fmt: skip


def _routes(report: ResourceReport, res, cores: tuple[int, ...]):
    """Messages, hops and chip hops one spike of each TDE adds to reach the readout ``cores``,
    each shape ``(n_spll,)`` int64 (module docstring)."""
    n = report.n_spll
    messages, hops, chip_hops = (np.zeros(n, np.int64) for _ in range(3))
    if not cores:
        return messages, hops, chip_hops
    mesh = Mesh(res)
    multicast = bool(res.value("multicast", False))
    for i in range(n):
        src = int(report.tde_core[i])
        feedback, feedback_chips = mesh.route(src, int(report.cco_core[i]))
        edges, chips = set(), set()
        for core in cores:
            e, c = mesh.route(src, core)
            if multicast:
                edges |= e
                chips |= c
            else:
                hops[i] += len(e)
                chip_hops[i] += len(c)
        if multicast:  # the feedback packet is copied: only the edges it did not take yet
            hops[i] = len(edges - feedback)
            chip_hops[i] = len(chips - feedback_chips)
        else:
            messages[i] = len(cores)
    return messages, hops, chip_hops


@dataclass(frozen=True)
class ReadoutCounts:
    """What the readout makes a chip do in one classification (module docstring)."""

    deliveries: int
    messages: int
    hops: int
    chip_hops: int
    neuron_updates: int
    spikes: int
    steps: int | None


@dataclass(frozen=True)
class ReadoutCost:
    """The readout's share of one classification.

    Attributes:
        fit: the :class:`ReadoutFit` it was counted on.
        counts: the :class:`ReadoutCounts`.
        energy: J per category of :data:`READOUT_CATEGORIES` plus ``"static"`` (chips the
            readout adds) and ``"cores"`` (its cores); ``None`` where the profile has no figure.
        step_work: the readout cores' mean work per step [s] (``None``: no ``[timing]`` or an
            analog chip).
        assumed_categories: categories of ``energy`` on an assumed figure.
    """

    fit: ReadoutFit
    counts: ReadoutCounts
    energy: dict[str, float | None]
    step_work: float | None
    assumed_categories: tuple[str, ...]

    @property
    def dynamic_energy(self) -> float:
        """Energy of the readout's events [J] (no static or core power)."""
        return float(sum(self.energy[n] or 0.0 for n, _, _ in READOUT_CATEGORIES))

    @property
    def figure_counts(self) -> dict[str, int]:
        """Per ``[energy]`` key of a per-event figure the profile gives, how many times the
        readout pays it (:attr:`quantize.pricing.SampleCost.figure_counts`)."""
        out: dict[str, int] = {}
        for name, key, attr in READOUT_CATEGORIES:
            if self.energy[name] is not None:
                out[key] = out.get(key, 0) + getattr(self.counts, attr)
        return out

    def to_dict(self) -> dict:
        return {
            "fit": self.fit.to_dict(),
            "counts": vars(self.counts).copy(),
            "energy_j": self.energy,
            "dynamic_energy_j": self.dynamic_energy,
            "step_work_s": self.step_work,
            "assumed_categories": list(self.assumed_categories),
        }

    def markdown(self) -> str:
        """Counts and energy per category as a Markdown table (``*``: assumed figure)."""
        rows = ["| readout | count | energy |", "|---|---:|---:|"]
        for name, _, attr in READOUT_CATEGORIES:
            star = " *" if name in self.assumed_categories else ""
            rows.append(
                f"| {name} | {getattr(self.counts, attr)} | {joules(self.energy[name])}{star} |"
            )
        rows.append(f"| **dynamic** | | **{joules(self.dynamic_energy)}** |")
        return "\n".join(rows)


def readout_cost(
    fit: ReadoutFit,
    report: ResourceReport,
    profile: Profile | str | Path,
    tde_counts: np.ndarray,
    duration: float,
    window: float | None,
) -> ReadoutCost:
    """The readout's counts and energy in one classification (module docstring): TDE spikes
    ``tde_counts`` ``(n_spll,)`` of a run of ``duration`` [s] on ``report``'s placement, which
    keeps the chip powered ``window`` [s] (:attr:`quantize.pricing.SampleCost.window`;
    ``None``: unknown, no static energy)."""
    profile = load_profile(profile)
    chip = chip_of(profile)
    tde = np.asarray(tde_counts, dtype=np.int64)
    if tde.shape != (fit.features,):
        raise ValueError(f"TDE counts must have shape ({fit.features},), got {tde.shape}")
    if not fit.cores:
        raise ValueError(f"no readout placement on {fit.profile!r}: {'; '.join(fit.problems)}")
    dt = profile.dt if isinstance(profile, FixedPointProfile) else None
    steps = None if dt is None else n_steps(duration, dt)
    deliveries = int(tde.sum()) * fit.classes
    counts = ReadoutCounts(
        deliveries, int(tde @ fit.messages), int(tde @ fit.hops), int(tde @ fit.chip_hops),
        fit.classes * steps if steps is not None else deliveries, 1, steps,
    )  # fmt: skip
    table, assumed = chip.energy, set(chip.assumed())
    energy: dict[str, float | None] = {}
    starred = []
    for name, key, attr in READOUT_CATEGORIES:
        per = table.value(key)
        energy[name] = None if per is None else per * getattr(counts, attr)
        if per is not None and f"energy.{key}" in assumed:
            starred.append(name)
    chips_with_readout = -(-(fit.cores[-1] + 1) // report.cores_per_chip)
    added_chips = max(0, chips_with_readout - report.n_chips)
    for name, key, units in (("static", "static_power", added_chips),
                             ("cores", "core_power", len(fit.cores))):  # fmt: skip
        power = table.value(key)
        energy[name] = None if power is None or window is None else power * units * window
        if power is not None and f"energy.{key}" in assumed:
            starred.append(name)
    return ReadoutCost(fit, counts, energy, _step_work(fit, counts, chip.timing), tuple(starred))


def _step_work(fit: ReadoutFit, counts: ReadoutCounts, timing) -> float | None:
    """Mean work of the busiest readout core per step [s]: its neurons' updates, its share of
    the deliveries and the decision spike."""
    if counts.steps is None or not any(k in timing for k in ("neuron_update", "synaptic_event")):
        return None
    t = {k: timing.value(k, 0.0) for k in ("neuron_update", "synaptic_event", "spike", "message")}
    busiest = max(fit.neurons)
    events = counts.deliveries * busiest / fit.classes
    return (
        busiest * t["neuron_update"]
        + (events * t["synaptic_event"] + t["spike"] + t["message"]) / counts.steps
    )
