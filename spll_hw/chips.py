"""Chip profiles, reached through a registry: the core never imports the package that
implements them.

A chip profile says what a chip does to a network: rounds its parameters to number formats,
mismatches them, limits its circuits. The package that knows profiles (``quantize``) registers a
provider in the ``spll_hw.profiles`` entry-point group; this module asks it to

* :func:`describe` a profile (name or TOML file) — its name, kind, description and what it can
  do (:class:`ProfileInfo`: clocked at ``dt``, mismatch draws, an energy table), failing with a
  clear error for an unknown or broken one before any work. The core asks these capabilities,
  never the kind: a provider may add kinds of its own;
* :func:`realise` a network on a profile — the network the chip implements, in SI units, and a
  Markdown report of what changed; a network that does not fit raises ``ValueError``;
* list the bundled profiles (:func:`names`);
* list a profile's chip figures — resources, timing, energy, each with its source
  (:func:`figures`);
* keep some parameters at their requested values in a realisation (:func:`keep_exact`), to see
  which of the chip's formats or mismatches costs a network its accuracy;
* say whether a network fits the chip, on how many cores, where each neuron goes
  (:func:`resources`), and what one simulated sample costs there: energy per category, step
  latency, real-time factor (:func:`cost`), each of an :class:`OnChip` (the network, the
  profile, the mismatch draw and, for a network of several inputs, which input drives each
  sPLL);
* place a spiking readout (one neuron per class, a synapse from every TDE) beside a network
  and cost its share of a sample (:func:`readout_resources`, :func:`readout_cost`), where the
  provider can (``readout_resources``/``readout_cost``: optional methods).
* place and cost a graph of standard neurons, the construction ``nir-standard`` and
  ``lava-standard`` write (:func:`spll_hw.neuron_graph.graph_resources`,
  :func:`~spll_hw.neuron_graph.graph_cost`), where the provider can
  (``graph_resources``/``graph_cost``: optional methods).

Every registered provider counts: their profile names must not collide (an error names both
providers). A provider is any object with ``names()``, ``describe(source)``,
``realise(network, source, seed)``, ``figures(source)``, ``resources(where)`` and
``cost(where, result)`` returning :class:`ProfileInfo`, :class:`Realisation`, a list of
:class:`ChipFigure`, :class:`ChipFit` and :class:`ChipCost` (``where``: a
:class:`OnChip`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache
from importlib.metadata import entry_points

import numpy as np

from . import backends
from .harness.metrics import rate_error
from .network import Network
from .params import PARAM_NAMES
from .result import SimulationResult
from .simulate import poisson_spikes

#: Entry-point group of profile providers.
GROUP = "spll_hw.profiles"


@dataclass(frozen=True)
class ProfileInfo:
    """What a profile is and what it can do.

    Attributes:
        name: the profile's name.
        kind: the provider's label for it (quantize: ``"fixed-point"``, ``"analog"``); a label
            for people: the core decides by the capabilities below, never by the kind.
        description: one line.
        dt: time step [s] of a clocked chip, whose integer arithmetic the
            ``golden-fixed-point`` backend runs; ``None`` for an unclocked (analog) one.
        mismatch: each chip is a draw: a realisation depends on a seed (``chip_seed``), so
            accuracy is averaged over draws.
        energy: the profile has an ``[energy]`` table (energy per sample can be costed).
        storage_bits: ``(parameter bits, state bits)`` one sPLL occupies at the chip's word
            widths (its footprint); ``None`` for a chip without word widths (an analog one).
        max_circuits: the most distinct sPLL circuits (time-scale groups) the chip holds, so a
            ``grouped:G`` layout with more groups never fits (``None``: no such budget).
    """

    name: str
    kind: str
    description: str
    dt: float | None = None
    mismatch: bool = False
    energy: bool = False
    storage_bits: tuple[int, int] | None = None
    max_circuits: int | None = None

    @property
    def clocked(self) -> bool:
        """The chip steps time by :attr:`dt` in integer arithmetic."""
        return self.dt is not None


@dataclass(frozen=True)
class Realisation:
    """A network as a chip implements it.

    Attributes:
        network: the realised network (SI units), simulated exactly by the golden model.
        profile: the profile it was realised on.
        report: Markdown: requested against realised value of every parameter, warnings.
        detail: the provider's own object (``quantize.QuantizedNetwork``), for backends of
            the same package (e.g. the integer parameters of a fixed-point profile).
    """

    network: Network
    profile: ProfileInfo
    report: str
    detail: object = None


@dataclass(frozen=True)
class ChipFigure:
    """One figure of a chip profile's ``[resources]``, ``[timing]`` or ``[energy]`` table.

    Attributes:
        table: ``"resources"``, ``"timing"`` or ``"energy"``.
        key: the figure's key (``"neurons_per_core"``, ``"synaptic_event"``, ...).
        value: a number in SI units (count, seconds, joules, watts), a flag or a list.
        meaning: what it is, with its unit.
        source: where it comes from.
        assumed: no public source gives it (every report marks it).
        unit: ``"s"``, ``"J"``, ``"W"`` or ``""`` (counts, flags, lists).
        low, high: the range the sources allow (``None``: the figure is one number).
        low_source, high_source: where each end comes from.
    """

    table: str
    key: str
    value: object
    meaning: str
    source: str
    assumed: bool
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_source: str = ""
    high_source: str = ""


@dataclass(frozen=True)
class ChipFit:
    """A network mapped onto a chip.

    Attributes:
        profile: the profile.
        fits: the network fits the chip's cores, configurations, axons and synapses.
        problems: why it does not fit ("needs 5 cores for 5 distinct ... configurations ...").
        cores, chips: cores and chips the placement uses (0 when nothing was placed).
        markdown: the report (totals, verdict, per-core use, assumed figures).
        data: the same as JSON-ready values.
        assumed: ``table.key`` of the assumed figures it rests on.
        detail: the provider's own object (``quantize.resources.ResourceReport``).
        cores_range: ``(fewest, most)`` cores over the ranges the profile's placement figures
            carry (neurons or configurations per core, ...); ``(cores, cores)`` when it carries
            none (``None``: the provider gives no range).
    """

    profile: ProfileInfo
    fits: bool
    problems: tuple[str, ...]
    cores: int
    chips: int
    markdown: str
    data: dict
    assumed: tuple[str, ...]
    detail: object = None
    cores_range: tuple[int, int] | None = None

    def cores_words(self) -> str:
        """``"13"``, or ``"13 [4, 13]"`` where the placement figures' ranges move the count."""
        low, high = self.cores_range or (self.cores, self.cores)
        return str(self.cores) if low == high else f"{self.cores} [{low}, {high}]"


@dataclass(frozen=True)
class ChipCost:
    """What one simulated sample costs on a chip.

    Attributes:
        profile: the profile.
        energy: J per category (input/trigger/feedback deliveries, spikes, messages, hops,
            neuron updates, static, cores); ``None`` for a category the profile does not model.
        total_energy: sum of the modelled categories [J], static power included.
        step_latency: time of one step on the chip [s] (``None``: analog or not modelled).
        real_time_factor: step latency / time step (≤ 1 keeps up with real time).
        markdown: counts and energy per category as Markdown.
        data: the same as JSON-ready values.
        assumed: ``table.key`` of the assumed figures it rests on.
        detail: the provider's own object (``quantize.pricing.SampleCost``).
        assumed_categories: the categories of ``energy`` whose value rests on an assumed
            figure (its per-event cost or power, or for static power the time on chip).
        time_on_chip: how long the chip works on the sample [s] (``None``: unknown).
        energy_low, energy_high: ``energy`` with every figure at the low and the high end of
            its range (the same as ``energy`` for a figure of one number); empty: the
            provider gives no range.
        figure_counts: per ``[energy]`` key of a per-event figure (``"neuron_update"``,
            ``"synaptic_event"``, ``"step"``, ...), how many times the sample pays it:
            dynamic energy is their sum × the figures.
        figure_ranges: ``(low, high)`` of each of those figures [J].
        figure_values: each of those figures at its single value [J] (empty: the provider
            gives none): ``figure_counts × figure_values`` summed is :attr:`dynamic_energy`.
    """

    profile: ProfileInfo
    energy: dict[str, float | None]
    total_energy: float
    step_latency: float | None
    real_time_factor: float | None
    markdown: str
    data: dict
    assumed: tuple[str, ...]
    detail: object = None
    assumed_categories: tuple[str, ...] = ()
    time_on_chip: float | None = None
    energy_low: dict[str, float | None] = field(default_factory=dict)
    energy_high: dict[str, float | None] = field(default_factory=dict)
    figure_counts: dict[str, float] = field(default_factory=dict)
    figure_ranges: dict[str, tuple[float, float]] = field(default_factory=dict)
    figure_values: dict[str, float] = field(default_factory=dict)

    @property
    def dynamic_energy(self) -> float:
        """Energy of the sample's events [J]: event counts × per-event costs, no static or
        core power (:data:`STATIC_CATEGORIES`)."""
        return _sum(self.energy, lambda k: k not in STATIC_CATEGORIES)

    @property
    def dynamic_range(self) -> EnergyRange:
        """:attr:`dynamic_energy` with every figure at its low and its high end [J]."""
        low, high = (self.energy_low or self.energy), (self.energy_high or self.energy)
        keep = lambda k: k not in STATIC_CATEGORIES  # noqa: E731
        return EnergyRange(_sum(low, keep), _sum(high, keep))

    @property
    def static_range(self) -> EnergyRange | None:
        """:attr:`static_energy` at the low and the high end of the power figures [J]."""
        if self.static_energy is None:
            return None
        low, high = (self.energy_low or self.energy), (self.energy_high or self.energy)
        keep = lambda k: k in STATIC_CATEGORIES  # noqa: E731
        return EnergyRange(_sum(low, keep), _sum(high, keep))

    @property
    def static_energy(self) -> float | None:
        """Static and core power × the window [J] (``quantize.pricing.SampleCost.window``:
        the sample's duration, or the time on chip where the chip cannot keep up); ``None``
        when the profile models neither (or the time on chip is unknown)."""
        if all(self.energy.get(k) is None for k in STATIC_CATEGORIES):
            return None
        return _sum(self.energy, lambda k: k in STATIC_CATEGORIES)

    @property
    def assumed_dynamic_energy(self) -> float:
        """The part of :attr:`dynamic_energy` that rests on assumed figures [J]."""
        return _sum(
            self.energy, lambda k: k not in STATIC_CATEGORIES and k in self.assumed_categories
        )

    @property
    def assumed_static_energy(self) -> float:
        """The part of :attr:`static_energy` that rests on assumed figures [J]."""
        return _sum(self.energy, lambda k: k in STATIC_CATEGORIES and k in self.assumed_categories)


#: Energy categories that are power × time, not per event: never part of a headline energy,
#: a Pareto front or a tuning objective, shown apart.
STATIC_CATEGORIES = ("static", "cores")


@dataclass(frozen=True)
class EnergyRange:
    """An energy [J] as the range its figures allow: ``low`` with every figure at its low end,
    ``high`` at its high end."""

    low: float
    high: float

    def __str__(self) -> str:
        return f"[{format_joules(self.low)}, {format_joules(self.high)}]"

    @classmethod
    def mean(cls, ranges: Sequence[EnergyRange]) -> EnergyRange:
        return cls(
            sum(r.low for r in ranges) / len(ranges), sum(r.high for r in ranges) / len(ranges)
        )


def format_joules(x: float) -> str:
    """An energy in the unit that keeps it readable: ``"12.3 µJ"``, ``"4.56 mJ"``."""
    for unit, scale in (("J", 1.0), ("mJ", 1e-3), ("µJ", 1e-6), ("nJ", 1e-9)):
        if abs(x) >= scale:
            return f"{x / scale:.3g} {unit}"
    return "0 J" if x == 0 else f"{x / 1e-12:.3g} pJ"


def cheaper(
    a: dict[str, float], b: dict[str, float], ranges: dict[str, tuple[float, float]]
) -> bool | None:
    """Whether counts ``a`` cost less dynamic energy than counts ``b`` (each: ``[energy]`` key
    → times paid, :attr:`ChipCost.figure_counts`) wherever the figures lie within their
    ``ranges`` (key → ``(low, high)`` [J]): ``True`` when ``a`` is cheaper throughout, ``False``
    when ``b`` is, ``None`` when neither is (the ranking flips inside the ranges, or they cost
    the same).

    The difference ``Σ_k f_k (a_k - b_k)`` is linear in the figures ``f_k``, so its largest
    value takes each ``f_k`` at the end its count difference favours; ``a`` is cheaper
    throughout exactly when that largest value is below 0."""

    def largest(x: dict[str, float], y: dict[str, float]) -> float:
        diff = {k: x.get(k, 0.0) - y.get(k, 0.0) for k in set(x) | set(y)}
        return sum(d * ranges[k][1 if d > 0 else 0] for k, d in diff.items() if d)

    if largest(a, b) < 0:
        return True
    if largest(b, a) < 0:
        return False
    return None


#: Length [s] of the Poisson train :func:`arithmetic_error` runs.
ARITHMETIC_CHECK_S = 1.0


def arithmetic_error(network: Network, source: str) -> tuple[float, float, str] | None:
    """How far ``network`` in chip ``source``'s own integer arithmetic
    (``golden-fixed-point:profile=SOURCE``) is from golden, on a Poisson train at the
    network's median free-running frequency (:data:`ARITHMETIC_CHECK_S` s): ``(error, rate
    [Hz], backend spec)``, the error the TDE rates' ``sum|r - r_golden| / sum r_golden`` (NaN
    where golden's TDEs are silent); ``None`` for a profile that is not clocked."""
    if not describe(source).clocked:
        return None
    rate = float(np.median(network.free_frequencies()))
    train = poisson_spikes(rate, ARITHMETIC_CHECK_S, seed=0)
    golden = backends.get("golden").simulate(network, train, ARITHMETIC_CHECK_S)
    spec = f"golden-fixed-point:profile={source}"
    mine = backends.get(spec).simulate(network, train, ARITHMETIC_CHECK_S)
    return rate_error(mine, golden), rate, spec


def percent_off(error: float) -> str:
    """An :func:`arithmetic_error` as ``"x.y %"`` (``"no TDE spike in golden"`` for NaN)."""
    return "no TDE spike in golden" if error != error else f"{100 * error:.1f} %"


def arithmetic_line(network: Network, source: str) -> str:
    """One sentence on :func:`arithmetic_error`; empty for a profile that is not clocked."""
    found = arithmetic_error(network, source)
    if found is None:
        return ""
    error, rate, spec = found
    return (
        f"In {source}'s own integer arithmetic (`{spec}`), on a {ARITHMETIC_CHECK_S:g}-s "
        f"Poisson train at {rate:.0f} Hz, the TDE rates are {percent_off(error)} off golden "
        "(sum |r - golden's| / sum golden's; `spll-hw export --to lava` judges this against "
        "its limit)."
    )


def _sum(energy: dict[str, float | None], keep) -> float:
    return float(sum(v for k, v in energy.items() if v is not None and keep(k)))


@cache
def providers() -> dict[str, object]:
    """Every registered profile provider by entry-point name; ``ValueError`` when none is
    installed or two providers bundle a profile of the same name."""
    found = {ep.name: ep.load() for ep in entry_points(group=GROUP)}
    if not found:
        raise ValueError(
            f"no chip profiles are installed (nothing registers the {GROUP!r} entry-point "
            "group; reinstall spll-hw: pip install -e .)"
        )
    owner: dict[str, str] = {}
    for name, p in found.items():
        for profile in p.names():
            if profile in owner:
                raise ValueError(
                    f"chip profile {profile!r} is bundled by two providers of {GROUP!r}, "
                    f"{owner[profile]!r} and {name!r}: uninstall or rename one"
                )
            owner[profile] = name
    return found


def provider(source: str | None = None):
    """The provider of profile ``source``: the one that bundles that name; for a TOML file
    (or any other source) the first provider whose ``describe`` accepts it, else the first
    provider's error."""
    found = providers()
    for p in found.values():
        if source in p.names():
            return p
    if len(found) == 1 or source is None:
        return next(iter(found.values()))
    first_error = None
    for p in found.values():
        try:
            p.describe(source)
        except ValueError as exc:
            first_error = first_error or exc
            continue
        return p
    raise first_error


def names() -> list[str]:
    """Bundled profile names of every provider."""
    return [name for p in providers().values() for name in p.names()]


def describe(source: str) -> ProfileInfo:
    """The profile ``source`` (a bundled name or a TOML path); ``ValueError`` naming what is
    wrong when it is unknown or broken."""
    return provider(source).describe(source)


def realise(network: Network, source: str, seed: int | None = None) -> Realisation:
    """``network`` as chip profile ``source`` implements it; ``seed`` picks the mismatch draw
    of a profile with :attr:`ProfileInfo.mismatch` (default: the profile's own). ``ValueError``
    when it does not fit."""
    return provider(source).realise(network, source, seed)


#: Parameters that set a CCO's free-running frequency (eq. 6) besides its offset current.
_FREQUENCY_PARAMS = ("tau_cco", "c_cco", "v_cco_thr", "t_cco_refr")


def exact_names(text: str) -> tuple[str, ...]:
    """``"tau_tde_fac+tau_tde"`` -> ``("tau_tde_fac", "tau_tde")``: sPLL parameter names
    joined by ``+``; ``ValueError`` for an empty list or an unknown name."""
    names = tuple(dict.fromkeys(n.strip() for n in str(text).split("+") if n.strip()))
    unknown = [n for n in names if n not in PARAM_NAMES]
    if not names or unknown:
        raise ValueError(
            f"{unknown or 'no name'}: give sPLL parameter names joined by '+', e.g. "
            f"tau_tde_fac+tau_tde; known: {', '.join(PARAM_NAMES)}"
        )
    return names


def keep_exact(realised: Network, requested: Network, names: tuple[str, ...]) -> Network:
    """``realised`` with parameters ``names`` (:data:`spll_hw.params.PARAM_NAMES`) set back
    to their values in ``requested``, sPLL by sPLL: the chip with those formats (or
    mismatches) made exact, everything else as it realises it.

    A chip re-solves each CCO's offset current for its free-running frequency, so the offset
    follows what is kept exact: with any of ``tau_cco``, ``c_cco``, ``v_cco_thr``,
    ``t_cco_refr`` exact the offset is re-solved to keep the realised frequency; with
    ``i_cco_offset`` exact it is re-solved for the requested frequency (the requested offset
    itself when nothing else about the CCO differs). ``ValueError`` when the two networks
    differ in size or a frequency cannot be held.
    """
    if realised.n_spll != requested.n_spll:
        raise ValueError(
            f"the realised network has {realised.n_spll} sPLLs, the requested one "
            f"{requested.n_spll}"
        )
    names = tuple(names)
    retune = "i_cco_offset" in names or any(n in names for n in _FREQUENCY_PARAMS)
    kept = []
    for i, (chip, asked) in enumerate(zip(realised.spll, requested.spll, strict=True)):
        p = replace(chip, **{n: getattr(asked, n) for n in names})
        if retune:
            target = (asked if "i_cco_offset" in names else chip).free_frequency()
            if target > 0 and p.free_frequency() != target:
                try:
                    p = p.with_free_frequency(target)
                except ValueError as exc:
                    raise ValueError(f"sPLL {i}: with {'+'.join(names)} exact: {exc}") from None
        kept.append(p)
    return replace(realised, spll=tuple(kept))


def figures(source: str) -> list[ChipFigure]:
    """Every figure of profile ``source``'s chip tables, with its source (empty when it has
    none)."""
    return list(provider(source).figures(source))


@dataclass(frozen=True, eq=False)
class OnChip:
    """A network on a chip profile: what :func:`resources`, :func:`cost`,
    :func:`readout_resources` and :func:`readout_cost` place, and what a provider's methods of
    the same names are given.

    Attributes:
        network: the network (SI units).
        source: the chip profile, a bundled name or a TOML path.
        seed: the mismatch draw of a profile with :attr:`ProfileInfo.mismatch` (``None``: the
            profile's own; a profile without mismatch ignores it).
        inputs: which of ``K`` input spike trains drives each sPLL, indices ``0 … K-1``, shape
            ``(n_spll,)`` (``None``: one input drives them all; e.g. one sPLL network per
            sensor channel, :mod:`spll_hw.multichannel.chips`).
    """

    network: Network
    source: str
    seed: int | None = None
    inputs: Sequence[int] | np.ndarray | None = None


def resources(where: OnChip) -> ChipFit:
    """Whether ``where``'s network fits its chip profile, on how many cores, where each
    neuron goes. ``ValueError`` when the profile has no ``[resources]`` table."""
    return provider(where.source).resources(where)


def cost(where: OnChip, result: SimulationResult) -> ChipCost:
    """Energy, step latency and real-time factor of the sample ``result`` (a run of
    ``where``'s network: its ``tde_counts``, ``cco_counts``, ``info["n_input_spikes"]``
    and ``duration``) on ``where``'s chip profile; with ``where.inputs``
    ``info["n_input_spikes"]`` gives each input's spikes, shape ``(K,)``. ``ValueError`` when
    the network cannot be placed or the result lacks its input-spike count."""
    return provider(where.source).cost(where, result)


def _readout_provider(source: str):
    """The provider of ``source``, which must place readouts; ``ValueError`` otherwise."""
    p = provider(source)
    if not hasattr(p, "readout_cost"):
        raise ValueError(f"the provider of chip profile {source!r} does not place a readout")
    return p


def readout_resources(where: OnChip, classes: int) -> ChipFit:
    """Where a readout of ``classes`` neurons, each with a synapse from every TDE of
    ``where``'s network, goes on its chip profile beside the network (:func:`resources`'s
    placement): its cores (``cores``; ``chips``: the chips up to its last core), synapses,
    messages per TDE spike. ``ValueError`` when the provider places no readout or the profile
    has no ``[resources]`` table."""
    return _readout_provider(where.source).readout_resources(where, classes)


def readout_cost(where: OnChip, classes: int, result: SimulationResult) -> ChipCost:
    """The readout's share of the sample ``result`` (a run of ``where``'s network, as
    :func:`cost`): its deliveries, messages, hops, updates and decision spike and their energy;
    static and core power of what it adds over the network's time on chip (``time_on_chip``);
    ``step_latency`` and ``real_time_factor`` are ``None`` (its work per step is in
    ``data``). ``ValueError`` as :func:`readout_resources` or when it does not fit."""
    return _readout_provider(where.source).readout_cost(where, classes, result)
