"""What a sample costs on a chip from its counts: energy categories, the per-sample record
(:class:`SampleCost`) and the one pricing rule (:func:`priced`) every model of what runs on a
chip shares: the two-compartment sPLL (:func:`quantize.resources.sample_cost`) and a graph of
standard neurons (:func:`quantize.graph_cost.graph_cost`).

**Energy** = each count x its ``[energy]`` figure [J], plus static power x chips and core power
x cores over the *window*: the chip is powered for the whole sample in real-time use (its
duration), longer only where it cannot keep up (a time on chip longer than the duration). On
a clocked chip the time on chip is the sample's duration on a timer-paced chip (longer when a
step takes longer than ``dt``), ``steps x step latency`` on a free-running one; an analog chip
runs in physical time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from spll_hw.chips import format_joules

from .chip_tables import ChipSpec

#: Energy categories of the traffic on a chip, the same for the sPLLs and the readout (the
#: readout's :data:`~quantize.readout.READOUT_CATEGORIES`): (name, [energy] key, what is counted).
TRAFFIC_CATEGORIES = (
    ("messages", "message", "messages"),
    ("hops", "hop", "hops"),
    ("chip hops", "chip_hop", "chip_hops"),
    ("neuron updates", "neuron_update", "neuron_updates"),
)
#: Energy categories of a sample, in report order: (name, [energy] key, what is counted).
ENERGY_CATEGORIES = (
    ("input deliveries", "synaptic_event", "input_deliveries"),
    ("trigger deliveries", "synaptic_event", "trigger_deliveries"),
    ("feedback deliveries", "synaptic_event", "feedback_deliveries"),
    ("spikes", "spike", "spikes"),
    *TRAFFIC_CATEGORIES,
    ("steps", "step", "steps"),
)


#: ``[energy]`` figures that are a power [W], charged over the window, not per event.
POWER_KEYS = ("static_power", "core_power")


@dataclass(frozen=True)
class Counts:
    """What one sample makes a chip do, in the terms every model of what runs counts (the
    fields :func:`priced` reads through :meth:`total`; each model adds its own).

    Attributes:
        input_spikes: input spikes of the sample (every input's).
        input_deliveries: synaptic events of the input spikes.
        spikes: spikes of the neurons.
        messages: per source (an event type, the input, ...).
        crossing: messages that leave their core, per source.
        hops, chip_hops: router and chip hops, per source.
        neuron_updates: neuron (compartment) updates.
        steps: time steps (``None`` on an analog chip).
    """

    input_spikes: int
    input_deliveries: int
    spikes: int
    messages: dict[str, int]
    crossing: dict[str, int]
    hops: dict[str, int]
    chip_hops: dict[str, int]
    neuron_updates: int
    steps: int | None

    def total(self, name: str) -> int:
        """A count by its name in the categories (:data:`ENERGY_CATEGORIES`; per-source counts
        summed; no steps on an analog chip: 0)."""
        value = getattr(self, name)
        return int(sum(value.values())) if isinstance(value, dict) else int(value or 0)


@dataclass(frozen=True, kw_only=True)
class EventCounts(Counts):
    """What one sample makes the two-compartment sPLL network do on a chip
    (:mod:`quantize.resources` docstring for each count): :class:`Counts` with the input's,
    the triggers' (CCO -> TDE) and the feedback's (TDE -> CCO) deliveries, spikes of the TDEs
    and CCOs, messages and hops per event type (``"input"``, ``"trigger"``, ``"feedback"``),
    and ``per_input``, the input spikes of each input (:attr:`ResourceReport.inputs`)."""

    trigger_deliveries: int
    feedback_deliveries: int
    per_input: tuple[int, ...] = ()

    @property
    def synaptic_events(self) -> int:
        return self.input_deliveries + self.trigger_deliveries + self.feedback_deliveries

    def as_dict(self) -> dict:
        """The counts as JSON-ready values."""
        return {"input_spikes": self.input_spikes, "input_spikes_per_input": list(self.per_input),
                "input_deliveries": self.input_deliveries,
                "trigger_deliveries": self.trigger_deliveries,
                "feedback_deliveries": self.feedback_deliveries, "spikes": self.spikes,
                "messages": self.messages, "crossing": self.crossing, "hops": self.hops,
                "chip_hops": self.chip_hops, "neuron_updates": self.neuron_updates,
                "steps": self.steps}  # fmt: skip


@dataclass(frozen=True)
class SampleCost:
    """Energy and time of one sample on a chip.

    Attributes:
        profile: profile name.
        duration: simulated time [s].
        counts: the :class:`EventCounts` (or, for a graph of standard neurons, a
            :class:`quantize.graph_cost.GraphCounts`: anything with ``total`` and ``as_dict``).
        energy: J per category of ``categories`` plus ``"static"`` and ``"cores"``; ``None``
            where the profile gives no figure (not modelled).
        step_latency: time one step takes on the chip [s] (``None``: analog, or no
            ``[timing]``).
        real_time_factor: ``step_latency / dt`` (≤ 1 keeps up with real time; 1 on an
            analog chip).
        time_on_chip: how long the chip works on the sample [s] (``None`` when unknown).
        assumed: ``table.key`` of the assumed figures used.
        assumed_categories: the categories of ``energy`` that rest on an assumed figure: its
            ``[energy]`` cost or power, or (static and core power) a time on chip computed
            from assumed ``[timing]`` figures.
        window: how long the chip is powered for the sample [s]: the sample's duration, or
            the time on chip where that is longer (static and core power are charged over it).
        categories: the energy categories, ``(name, [energy] key, count)`` in report order
            (:data:`ENERGY_CATEGORIES` for the two-compartment sPLL).
    """

    profile: str
    duration: float
    counts: EventCounts
    energy: dict[str, float | None]
    step_latency: float | None
    real_time_factor: float | None
    time_on_chip: float | None
    assumed: tuple[str, ...]
    assumed_categories: tuple[str, ...] = ()
    window: float | None = None
    categories: tuple[tuple[str, str, str], ...] = ENERGY_CATEGORIES

    @property
    def figure_counts(self) -> dict[str, int]:
        """Per ``[energy]`` key of a per-event figure the profile gives, how many times the
        sample pays it (categories of one key summed): dynamic energy is the sum of these
        counts × the figures."""
        out: dict[str, int] = {}
        for name, key, attr in self.categories:
            if self.energy[name] is not None:
                out[key] = out.get(key, 0) + self.counts.total(attr)
        return out

    @property
    def total_energy(self) -> float:
        """Sum of the modelled categories [J]."""
        return float(sum(v for v in self.energy.values() if v is not None))

    @property
    def keeps_up(self) -> bool | None:
        return None if self.real_time_factor is None else self.real_time_factor <= 1.0

    def to_dict(self) -> dict:
        return {
            "profile": self.profile,
            "duration_s": self.duration,
            "counts": self.counts.as_dict(),
            "energy_j": self.energy,
            "total_energy_j": self.total_energy,
            "step_latency_s": self.step_latency,
            "real_time_factor": self.real_time_factor,
            "keeps_up": self.keeps_up,
            "time_on_chip_s": self.time_on_chip,
            "window_s": self.window,
            "assumed": list(self.assumed),
            "assumed_categories": list(self.assumed_categories),
        }

    def markdown(self) -> str:
        """Counts and energy per category as a Markdown table: the dynamic (per-event)
        categories and their sum first, static and core power apart; ``*`` marks a category
        that rests on an assumed figure."""
        c = self.counts

        def cell(name: str) -> str:
            star = " *" if name in self.assumed_categories else ""
            return f"{joules(self.energy[name])}{star}"

        rows = ["| category | count | energy |", "|---|---:|---:|"]
        for name, _, attr in self.categories:
            rows.append(f"| {name} | {c.total(attr)} | {cell(name)} |")
        dynamic = sum(self.energy[n] or 0.0 for n, _, _ in self.categories)
        rows.append(f"| **dynamic** | | **{joules(dynamic)}** |")
        rows.append(f"| static, apart | - | {cell('static')} |")
        rows.append(f"| cores, apart | - | {cell('cores')} |")
        rows.append(f"| total | | {joules(self.total_energy)} |")
        latency = "-" if self.step_latency is None else f"{self.step_latency * 1e6:.3g} µs"
        rtf = "-" if self.real_time_factor is None else f"{self.real_time_factor:.3g}"
        rows += [
            "",
            f"step latency {latency}, real-time factor {rtf}; messages crossing cores: "
            + ", ".join(f"{e} {n}" for e, n in c.crossing.items()),
        ]
        if self.assumed:
            rows.append("Assumed figures: " + ", ".join(self.assumed))
        return "\n".join(rows)


def joules(x: float | None) -> str:
    """An energy [J] as every table of spll-hw prints one (:func:`spll_hw.chips.format_joules`);
    ``"not modelled"`` for ``None``."""
    return "not modelled" if x is None else format_joules(x)


def priced(
    name: str,
    chip: ChipSpec,
    counts,
    duration: float,
    units: tuple[int, int],
    used: Sequence[str],
    clock: tuple[float | None, float | None, float | None] | None,
    categories: tuple[tuple[str, str, str], ...] = ENERGY_CATEGORIES,
) -> SampleCost:
    """The :class:`SampleCost` of ``counts`` (``counts.total(attr)`` of every category of
    ``categories``) of a sample of ``duration`` [s] on ``chip``, profile ``name``: each count x
    its ``[energy]`` figure [J]; static power x ``units[0]`` chips and core power x
    ``units[1]`` cores over the window (module docstring). ``clock``: ``(step latency [s],
    real-time factor, busy time [s])`` of a clocked chip, each ``None`` where the profile's
    ``[timing]`` cannot give it; ``None`` for an event-driven (analog) chip, which works for
    the whole ``duration``. ``used``: the assumed figures the placement rests on."""
    energy_table, timing = chip.energy, chip.timing
    assumed = set(chip.assumed())
    used = list(used)
    energy: dict[str, float | None] = {}
    assumed_categories = []
    for category, key, attr in categories:
        per = energy_table.value(key)
        energy[category] = None if per is None else per * counts.total(attr)
        if per is not None:
            used.append(f"energy.{key}")
            if f"energy.{key}" in assumed:
                assumed_categories.append(category)
    step, rtf, busy = (None, 1.0, None) if clock is None else clock
    if clock is None:
        time_on_chip = duration
    else:
        if step is not None:
            used += [f"timing.{k}" for k, _ in timing.figures]
        paced = bool(timing.value("realtime_paced", False))
        if busy is None:
            time_on_chip = duration if paced else None
        else:
            time_on_chip = max(duration, busy) if paced else busy
    # One rule for every chip: in real-time use it is powered for the whole window, longer
    # only where it cannot keep up; that rests on assumed [timing] figures only then.
    window = duration if time_on_chip is None else max(duration, time_on_chip)
    timed_on_assumed = window != duration and any(
        f"timing.{k}" in assumed for k, _ in timing.figures
    )
    for category, key, n in (("static", "static_power", units[0]),
                             ("cores", "core_power", units[1])):  # fmt: skip
        power = energy_table.value(key)
        if power is None:
            energy[category] = None
        else:
            used.append(f"energy.{key}")
            energy[category] = power * n * window
            if f"energy.{key}" in assumed or timed_on_assumed:
                assumed_categories.append(category)
    return SampleCost(
        name, float(duration), counts, energy, step, rtf, time_on_chip,
        chip.assumed_among(used), tuple(assumed_categories), window,
        categories,
    )  # fmt: skip
