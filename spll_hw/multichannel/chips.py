"""A multichannel network on a chip: every channel's sPLLs placed as one network of several
inputs, and what one classification costs there.

:func:`whole_network` joins the channels' networks (in feature order) into one
:class:`~spll_hw.network.Network` and says which channel drives each sPLL; :func:`placement`
maps it onto a chip profile (:func:`spll_hw.chips.resources` with those ``inputs``: a channel's
spikes go only to the cores holding its TDEs) and says which channel's sPLLs went to which core.
:func:`classification_cost` encodes the first ``window`` seconds of every channel of a few
samples, runs each channel's sPLLs **as the chip realises the whole network**
(:func:`spll_hw.chips.realise`; the channels never interact, so each channel's slice of the
realised network runs on its own, exactly) in the golden model, and costs every sample on the
placement (:func:`spll_hw.chips.cost`): one classification is one window of every channel
through the chip. With ``classes``, the spiking readout (:mod:`.readout`: one neuron per class,
a synapse from every TDE) is placed on cores of its own beside the network and its share of
every classification costed apart (:func:`spll_hw.chips.readout_cost`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from tqdm.auto import tqdm

from .. import backends, chips
from ..datasets.multichannel import MultiChannelSet
from ..encoders import train_duration
from ..network import Network
from ..result import SimulationResult
from .clocks import clocked_profile, group_label
from .config import MultichannelConfig


def whole_network(config: MultichannelConfig) -> tuple[Network, np.ndarray]:
    """Every channel's copy of its group's network, joined in feature order, and the channel
    (index into ``config.channels``) of each sPLL, shape ``(config.n_spll,)`` int64."""
    parts = [g.network.build() for g in config.groups for _ in g.channels]
    network = Network(
        tuple(p for net in parts for p in net.spll),
        "custom",
        np.concatenate([net.scales for net in parts]),
    )
    inputs = np.repeat(np.arange(len(parts)), [net.n_spll for net in parts])
    return network, inputs


@dataclass(frozen=True)
class Placement:
    """The whole network on one chip profile.

    Attributes:
        fit: the provider's answer (:class:`spll_hw.chips.ChipFit`): fits or why not, cores,
            chips, per-core use.
        channels: channel names, in feature order (``inputs`` index them).
        inputs: the channel of each sPLL, shape ``(n_spll,)``.
        cores: per core used, channel → ``(TDEs, CCOs)`` of that channel on it.
    """

    fit: chips.ChipFit
    channels: tuple[str, ...]
    inputs: np.ndarray
    cores: tuple[dict[str, tuple[int, int]], ...]

    @property
    def split(self) -> int:
        """sPLLs whose TDE and CCO lie on different cores (their trigger and feedback
        messages cross cores)."""
        return int(self.fit.data.get("spll_crossing_cores", 0))

    def markdown(self) -> str:
        """Which channel's sPLLs lie on which core (``TDEs/CCOs``)."""
        if not self.cores:
            return "nothing placed: " + "; ".join(self.fit.problems)
        rows = ["| core | channels (TDEs/CCOs) |", "|---:|---|"]
        for core, held in enumerate(self.cores):
            cells = ", ".join(f"{c} {t}/{k}" for c, (t, k) in held.items())
            rows.append(f"| {core} | {cells} |")
        return "\n".join(rows)


def placement(config: MultichannelConfig, profile: str, seed: int | None = None) -> Placement:
    """``config``'s whole network (:func:`whole_network`) on chip ``profile``: fit, cores and
    where every channel's sPLLs went; ``ValueError`` when the profile has no ``[resources]``
    table."""
    network, inputs = whole_network(config)
    fit = chips.resources(chips.OnChip(network, profile, seed, inputs))
    names = config.channels
    cores = []
    for use in fit.data.get("placement", []):
        held: dict[str, list[int]] = {}
        for kind, column in (("tde", 0), ("cco", 1)):
            for i in use[kind]:
                held.setdefault(names[inputs[i]], [0, 0])[column] += 1
        order = sorted(held, key=names.index)
        cores.append({c: (held[c][0], held[c][1]) for c in order})
    return Placement(fit, names, inputs, tuple(cores))


def readout_placement(
    config: MultichannelConfig, profile: str, classes: int, seed: int | None = None
) -> chips.ChipFit:
    """A readout of ``classes`` neurons driven by every TDE of ``config``'s whole network, on
    cores of its own beside :func:`placement`'s (:func:`spll_hw.chips.readout_resources`)."""
    network, inputs = whole_network(config)
    return chips.readout_resources(chips.OnChip(network, profile, seed, inputs), classes)


@dataclass(frozen=True)
class ClassificationCost:
    """What one classification (one window of every channel) costs on a chip, over samples.

    Attributes:
        window: seconds of every channel per classification [s].
        costs: the cost of each sample (:class:`spll_hw.chips.ChipCost`).
        input_spikes: mean input spikes per classification, all channels.
        readout: the spiking readout's share of each sample (empty: not costed).
    """

    window: float
    costs: tuple[chips.ChipCost, ...]
    input_spikes: float
    readout: tuple[chips.ChipCost, ...] = ()

    @property
    def readout_energy(self) -> float | None:
        """Mean dynamic energy of the readout per classification [J] (``None``: not
        costed)."""
        if not self.readout:
            return None
        return float(np.mean([c.dynamic_energy for c in self.readout]))

    @property
    def dynamic_energy(self) -> float:
        """Mean dynamic energy per classification [J] (event counts × per-event costs)."""
        return float(np.mean([c.dynamic_energy for c in self.costs]))

    @property
    def dynamic_range(self) -> chips.EnergyRange:
        """:attr:`dynamic_energy` with every figure at its low and its high end [J]."""
        return chips.EnergyRange.mean([c.dynamic_range for c in self.costs])

    @property
    def samples(self) -> int:
        """Classifications costed."""
        return len(self.costs)

    @property
    def assumed(self) -> tuple[str, ...]:
        """``table.key`` of the assumed figures the costs rest on."""
        return tuple(dict.fromkeys(k for c in self.costs for k in c.assumed))

    @property
    def figure_counts(self) -> dict[str, float]:
        """Mean times per classification each ``[energy]`` figure is paid
        (:attr:`spll_hw.chips.ChipCost.figure_counts`)."""
        keys = dict.fromkeys(k for c in self.costs for k in c.figure_counts)
        return {k: float(np.mean([c.figure_counts.get(k, 0) for c in self.costs])) for k in keys}

    @property
    def assumed_dynamic_energy(self) -> float:
        """The part of :attr:`dynamic_energy` on assumed figures [J]."""
        return float(np.mean([c.assumed_dynamic_energy for c in self.costs]))

    @property
    def static_energy(self) -> float | None:
        """Mean static and core power × time on chip [J] (``None``: not modelled)."""
        static = [c.static_energy for c in self.costs]
        return None if None in static else float(np.mean(static))

    @property
    def real_time_factor(self) -> float | None:
        """The worst sample's step latency / time step (``None``: not modelled)."""
        factors = [c.real_time_factor for c in self.costs]
        return None if None in factors else float(max(factors))

    @property
    def crossing(self) -> float:
        """Mean messages per classification that leave their core (inputs from the host
        included)."""
        return float(np.mean([sum(c.data["counts"]["crossing"].values()) for c in self.costs]))

    @property
    def latency(self) -> float | None:
        """Time from the start of the slide to the decision [s]: the window, or longer on a
        chip slower than real time (``window × real-time factor``); ``None`` when not
        modelled."""
        rtf = self.real_time_factor
        return None if rtf is None else self.window * max(1.0, rtf)


def classification_cost(
    config: MultichannelConfig,
    profile: str,
    samples: MultiChannelSet,
    levels: dict[str, float],
    window: float,
    seed: int | None = None,
    threads: int | None = 1,
    classes: int = 0,
    progress: bool = False,
) -> ClassificationCost:
    """Cost of classifying every sample of ``samples`` from its first ``window`` s on chip
    ``profile`` (module docstring).

    Args:
        config: the multichannel network.
        profile: a chip profile with ``[resources]`` (and ``[energy]`` for energies).
        samples: every channel of ``config``, at least ``window`` s long.
        levels: what each channel is divided by before encoding (:func:`.features.input_levels`).
        window: seconds into the slide [s].
        seed: the mismatch draw of an analog profile.
        threads: engine threads.
        classes: readout neurons to cost beside the network (0: none).
        progress: progress bars (stderr) over the channels, then over the samples costed.

    Raises:
        ValueError: the profile cannot realise or place the network or the readout (naming
            why).
    """
    network, inputs = whole_network(config)
    realised = chips.realise(network, profile, seed).network
    part = samples.first(window)
    golden = backends.get("golden")
    tde = np.zeros((len(part), network.n_spll), np.int64)
    cco = np.zeros_like(tde)
    spikes = np.zeros((len(part), inputs.max() + 1), np.int64)
    channels = [(c, g) for g in config.groups for c in g.channels]
    duration = window

    bar = tqdm(channels, desc=f"{profile}: encoding + sPLLs", unit="channel",
               disable=not progress, leave=False)  # fmt: skip
    for k, (channel, group) in enumerate(bar):
        encoder = group.make_encoder()
        signals = part.channel(channel).normalized(levels[channel], "the channel's input level")
        trains = encoder.encode(signals.signals, signals.fs)
        duration = train_duration(encoder, signals.duration)
        mine = np.flatnonzero(inputs == k)
        sub = Network(tuple(realised.spll[i] for i in mine), "custom")
        results = golden.simulate_batch(sub, trains, duration, threads=threads)
        for s, r in enumerate(results):
            tde[s, mine], cco[s, mine] = r.tde_counts, r.cco_counts
            spikes[s, k] = r.info["n_input_spikes"]
    runs = [
        SimulationResult(tde[s], cco[s], duration, info={"n_input_spikes": spikes[s]})
        for s in range(len(part))
    ]
    # every sample is placed anew and priced (its realisation is quantize()'s kept one)
    bar = tqdm(total=len(runs) * (2 if classes else 1), unit="sample", leave=False,
               desc=f"{profile}: placing and costing", disable=not progress)  # fmt: skip
    costs, readout = [], []
    on_chip = chips.OnChip(network, profile, seed, inputs)
    with bar:
        for r in runs:
            costs.append(chips.cost(on_chip, r))
            bar.update()
        for r in runs if classes else []:
            readout.append(chips.readout_cost(on_chip, classes, r))
            bar.update()
    return ClassificationCost(
        window, tuple(costs), float(spikes.sum(axis=1).mean()), tuple(readout)
    )


@dataclass(frozen=True)
class ClockedCost:
    """What one classification costs on separate clocks: the sum of its clocks' costs (each on
    chips of its own, with its own per-step energy and static power), decided when the slowest
    clock has finished. The same properties as :class:`ClassificationCost`."""

    parts: tuple[ClassificationCost, ...]

    @property
    def window(self) -> float:
        return self.parts[0].window

    @property
    def samples(self) -> int:
        return self.parts[0].samples

    @property
    def assumed(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(k for p in self.parts for k in p.assumed))

    @property
    def dynamic_energy(self) -> float:
        return sum(p.dynamic_energy for p in self.parts)

    @property
    def dynamic_range(self) -> chips.EnergyRange:
        ranges = [p.dynamic_range for p in self.parts]
        return chips.EnergyRange(sum(r.low for r in ranges), sum(r.high for r in ranges))

    @property
    def assumed_dynamic_energy(self) -> float:
        return sum(p.assumed_dynamic_energy for p in self.parts)

    @property
    def static_energy(self) -> float | None:
        static = [p.static_energy for p in self.parts]
        return None if None in static else sum(static)

    @property
    def real_time_factor(self) -> float | None:
        factors = [p.real_time_factor for p in self.parts]
        return None if None in factors else max(factors)

    @property
    def latency(self) -> float | None:
        latencies = [p.latency for p in self.parts]
        return None if None in latencies else max(latencies)

    @property
    def crossing(self) -> float:
        return sum(p.crossing for p in self.parts)

    @property
    def input_spikes(self) -> float:
        return sum(p.input_spikes for p in self.parts)


@dataclass(frozen=True)
class Clock:
    """One clock of a multichannel network on separate clocks (:mod:`.clocks`): some of its
    groups on chips of their own, stepped together.

    Attributes:
        label: the groups it holds, as a reader names them (``pac``; ``ele1…tdc (22
            channels)``; several joined by `` + ``).
        profile: the chip profile at its step (``loihi2@80us``), or as named for the groups
            without a step of their own.
        config: the network of those groups alone.
    """

    label: str
    profile: str
    config: MultichannelConfig


def clocks(config: MultichannelConfig, profile: str, steps: dict[int, float]) -> list[Clock]:
    """``config`` on chip ``profile`` with each group of ``steps`` (group index → step [s],
    :func:`.clocks.parse_group_steps`) on a clock of its own, the other groups together on
    ``profile`` as named; ``ValueError`` where the chip cannot write a group at its step."""
    out = [
        Clock(
            group_label(g), clocked_profile(profile, g, steps[k]), config.only(g.channels)
        )  # fmt: skip
        for k, g in enumerate(config.groups)
        if k in steps
    ]
    rest = [g for k, g in enumerate(config.groups) if k not in steps]
    if rest:
        label = " + ".join(group_label(g) for g in rest)
        out.append(Clock(label, profile, config.only(config.channels_of(rest))))
    return out


def describe_fit(places: Sequence[Placement]) -> str:
    """One Markdown row per profile: fits, cores, chips, split sPLLs, input axons, why not."""
    rows = [
        "| profile | fits | cores | chips | sPLLs split over 2 cores | why not |",
        "|---|---|---:|---:|---:|---|",
    ]
    for p in places:
        why = "; ".join(p.fit.problems) or "-"
        rows.append(
            f"| {p.fit.profile.name} | {'yes' if p.fit.fits else 'no'} | {p.fit.cores_words()} "
            f"| {p.fit.chips} | {p.split} | {why} |"
        )
    return "\n".join(rows)
