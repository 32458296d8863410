"""quantize's chip profiles as the core sees them: the provider registered in the
``spll_hw.profiles`` entry-point group (:mod:`spll_hw.chips`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from spll_hw.chips import ChipCost, ChipFigure, ChipFit, OnChip, ProfileInfo, Realisation
from spll_hw.network import Network
from spll_hw.neuron_graph import NeuronGraph
from spll_hw.result import SimulationResult

from .chip_tables import ENDS
from .core import quantize
from .footprint import storage_bits
from .graph_cost import GraphFit, graph_cost, graph_fit
from .pricing import POWER_KEYS, SampleCost
from .profiles import FixedPointProfile, Profile, available_profiles, load_profile
from .readout import readout_cost, readout_fit
from .resources import ResourceReport, chip_figures, resource_report, sample_cost


def _info(profile: Profile) -> ProfileInfo:
    """The profile's capabilities as the core asks them (a new kind sets the same ones)."""
    dt = profile.dt if isinstance(profile, FixedPointProfile) else None  # analog: unclocked
    energy = profile.chip is not None and bool(profile.chip.energy.figures)
    circuits = getattr(profile, "max_groups", None)  # an analog chip's circuit budget
    return ProfileInfo(
        profile.name, profile.kind, profile.description, dt, profile.draws_mismatch, energy,
        storage_bits(profile), circuits,
    )  # fmt: skip


class Profiles:
    """Bundled profiles and TOML files, realised with :func:`quantize.quantize`."""

    def names(self) -> list[str]:
        return available_profiles()

    def describe(self, source: str) -> ProfileInfo:
        return _info(load_profile(source))

    def realise(self, network: Network, source: str, seed: int | None = None) -> Realisation:
        profile = load_profile(source)
        q = quantize(network, profile, seed=seed if profile.draws_mismatch else None)
        return Realisation(q.network, _info(profile), q.report_markdown(), q)

    def figures(self, source: str) -> list[ChipFigure]:
        return [ChipFigure(**f) for f in chip_figures(source)]

    def resources(self, where: OnChip) -> ChipFit:
        return _chip_fit(_placed(where))

    def cost(self, where: OnChip, result: SimulationResult) -> ChipCost:
        return _chip_cost(_placed(where), lambda p, r: _sample_cost(r, p, result))

    def graph_resources(self, graph: NeuronGraph, source: str) -> ChipFit:
        """:func:`spll_hw.neuron_graph.graph_resources` (:func:`quantize.graph_cost.graph_fit`)."""
        return _chip_fit(_graph_placed(graph, source))

    def graph_cost(
        self, graph: NeuronGraph, source: str, spikes, n_input_spikes, duration: float
    ) -> ChipCost:
        """:func:`spll_hw.neuron_graph.graph_cost` (:func:`quantize.graph_cost.graph_cost` at
        the figures' values; each end of the range is the extreme, over the placements at the
        ends of the placement figures' ranges, of the cost at that end of the prices)."""
        return _chip_cost(
            _graph_placed(graph, source),
            lambda p, f: graph_cost(f, p, spikes, n_input_spikes, duration),
        )

    def readout_resources(self, where: OnChip, classes: int) -> ChipFit:
        profile, report = _placed(where)[0]
        fit = readout_fit(report, profile, classes)
        chips = -(-(fit.cores[-1] + 1) // report.cores_per_chip) if fit.cores else 0
        return ChipFit(
            _info(profile), fit.fits, fit.problems, len(fit.cores), chips, fit.markdown(),
            fit.to_dict(), fit.assumed, fit,
        )  # fmt: skip

    def readout_cost(self, where: OnChip, classes: int, result: SimulationResult) -> ChipCost:
        profile, report = _placed(where)[0]
        fit = readout_fit(report, profile, classes)
        ends = [at_end(profile, end) for end in ("value", "low", "high")]
        networks = [_sample_cost(report, p, result) for p in ends]
        c, low, high = (
            readout_cost(fit, report, p, result.tde_counts, result.duration, n.window)
            for p, n in zip(ends, networks, strict=True)
        )  # fmt: skip
        total = sum(v for v in c.energy.values() if v is not None)
        data = c.to_dict() | {"energy_low_j": low.energy, "energy_high_j": high.energy}
        spent = networks[0].time_on_chip
        return ChipCost(
            _info(profile), c.energy, total, None, None, c.markdown(), data, fit.assumed, c,
            c.assumed_categories, spent, low.energy, high.energy, c.figure_counts,
            *_figure_ends(profile),
        )  # fmt: skip


def at_end(profile: Profile, end: str) -> Profile:
    """``profile`` with every ranged price at its ``"low"`` or ``"high"`` end (``"value"``: as
    it is); its placement figures as they are."""
    if end == "value" or profile.chip is None:
        return profile
    return replace(profile, chip=profile.chip.at(end))


def _figure_ends(profile: Profile) -> tuple[dict, dict]:
    """``(low, high)`` and the single value [J] of every per-event ``[energy]`` figure of
    ``profile``, by key (:attr:`ChipCost.figure_ranges`, :attr:`ChipCost.figure_values`)."""
    figures = [] if profile.chip is None else profile.chip.energy.figures
    per_event = [(k, f) for k, f in figures if k not in POWER_KEYS]
    return ({k: (f.at("low"), f.at("high")) for k, f in per_event},
            {k: f.at("value") for k, f in per_event})  # fmt: skip


def _chip_cost(
    placed: list[tuple], cost: Callable[[Profile, ResourceReport | GraphFit], SampleCost]
) -> ChipCost:
    """The :class:`ChipCost` of a sample whose cost on placement ``fit`` at ``profile``'s prices
    is ``cost(profile, fit)``: at the figures' values on the first of ``placed``
    (:func:`_placed`, :func:`_graph_placed`), and at the low and the high end of the prices
    the extreme over every placement (:func:`_extreme`)."""
    profile, fit = placed[0]
    c = cost(profile, fit)
    low, high = (_extreme(end, [cost(at_end(p, end), f) for p, f in placed]) for end in ENDS)
    data = c.to_dict() | {"energy_low_j": low.energy, "energy_high_j": high.energy}
    return ChipCost(
        _info(profile), c.energy, c.total_energy, c.step_latency, c.real_time_factor,
        c.markdown(), data, c.assumed, c, c.assumed_categories, c.time_on_chip, low.energy,
        high.energy, c.figure_counts, *_figure_ends(profile),
    )  # fmt: skip


def _placements(source: str) -> list[Profile]:
    """The profile ``source`` as it is, then (where its placement figures carry ranges) with
    them at their low and at their high end (:meth:`quantize.chip_tables.ChipSpec.placements`)."""
    profile = load_profile(source)
    if profile.chip is None:
        return [profile]
    return [replace(profile, chip=chip) for chip in profile.chip.placements()]


def _placed(where: OnChip) -> list[tuple]:
    """``(profile, resource_report)`` of ``where``'s network on each of
    :func:`_placements` of its profile; the first is the profile as it is."""
    network, seed, inputs = where.network, where.seed, where.inputs
    return [(p, resource_report(network, p, seed, inputs)) for p in _placements(where.source)]


def _graph_placed(graph: NeuronGraph, source: str) -> list[tuple]:
    """``(profile, graph_fit)`` of ``graph`` on each of :func:`_placements`."""
    return [(p, graph_fit(graph, p)) for p in _placements(source)]


def _extreme(end: str, costs: list[SampleCost]) -> SampleCost:
    """The least (``end == "low"``) or the most costly of ``costs`` (total energy)."""
    pick = min if end == "low" else max
    return pick(costs, key=lambda c: c.total_energy)


def _chip_fit(placed: list[tuple]) -> ChipFit:
    """The :class:`ChipFit` of ``placed`` (:func:`_placed` or :func:`_graph_placed`: the fit
    at the placement figures' values first, then at the ends of their ranges), with the cores
    ``(fewest, most)`` over every placement."""
    (profile, fit), *ends = placed
    cores = min(f.n_cores for _, f in placed), max(f.n_cores for _, f in placed)
    words = _cores_words(cores, profile, [f.problems for _, f in ends])
    return ChipFit(
        _info(profile), fit.fits, fit.problems, fit.n_cores, fit.n_chips, fit.markdown() + words,
        fit.to_dict() | {"cores_range": list(cores)}, fit.assumed, fit, cores,
    )  # fmt: skip


def _cores_words(cores: tuple[int, int], profile: Profile, problems: list[tuple[str, ...]]) -> str:
    """The line a fit's report adds where the placement figures' ranges move the core count;
    ``problems``: those of the placements at the low and the high end (where there are any)."""
    if cores[0] == cores[1] and not any(problems):
        return ""
    ranged = profile.chip.ranged_placement()
    words = (
        f"\n\nCores at the ends of the placement figures' ranges ({', '.join(ranged)}; "
        f"the table above is the placement at their values): {cores[0]} to {cores[1]}."
    )
    for end, why in zip(ENDS, problems, strict=True):
        if why:
            words += f" At the {end} end it does not fit: {'; '.join(why)}."
    return words


def _sample_cost(report, profile: Profile, result: SimulationResult):
    """:func:`sample_cost` of ``result`` on ``report``'s placement; ``ValueError`` when the
    result lacks its input-spike count."""
    if "n_input_spikes" not in result.info:
        raise ValueError(
            f"the {result.backend!r} result has no info['n_input_spikes']: the cost of a "
            "sample needs its input-spike count"
        )
    return sample_cost(
        report, profile, result.tde_counts, result.cco_counts, result.info["n_input_spikes"],
        result.duration,
    )  # fmt: skip


#: The registered provider.
PROFILES = Profiles()
