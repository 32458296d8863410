"""quantize's chip profiles as the core sees them: the provider registered in the
``spll_hw.profiles`` entry-point group (:mod:`spll_hw.chips`)."""

from __future__ import annotations

from spll_hw.chips import ChipCost, ChipFigure, ChipFit, ProfileInfo, Realisation
from spll_hw.network import Network
from spll_hw.result import SimulationResult

from .core import quantize
from .footprint import storage_bits
from .profiles import FixedPointProfile, Profile, available_profiles, load_profile
from .resources import chip_figures, resource_report, sample_cost


def _info(profile: Profile) -> ProfileInfo:
    """The profile's capabilities as the core asks them (a new kind sets the same ones)."""
    dt = profile.dt if isinstance(profile, FixedPointProfile) else None  # analog: unclocked
    energy = profile.chip is not None and bool(profile.chip.energy.figures)
    return ProfileInfo(
        profile.name, profile.kind, profile.description, dt, profile.draws_mismatch, energy,
        storage_bits(profile),
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

    def resources(
        self, network: Network, source: str, seed: int | None = None, inputs=None
    ) -> ChipFit:
        profile = load_profile(source)
        report = resource_report(network, profile, seed, inputs)
        return ChipFit(
            _info(profile), report.fits, report.problems, report.n_cores, report.n_chips,
            report.markdown(), report.to_dict(), report.assumed, report,
        )  # fmt: skip

    def cost(
        self,
        network: Network,
        source: str,
        result: SimulationResult,
        seed: int | None = None,
        inputs=None,
    ) -> ChipCost:
        profile = load_profile(source)
        if "n_input_spikes" not in result.info:
            raise ValueError(
                f"the {result.backend!r} result has no info['n_input_spikes']: the cost of a "
                "sample needs its input-spike count"
            )
        report = resource_report(network, profile, seed, inputs)
        c = sample_cost(
            report, profile, result.tde_counts, result.cco_counts,
            result.info["n_input_spikes"], result.duration,
        )  # fmt: skip
        return ChipCost(
            _info(profile), c.energy, c.total_energy, c.step_latency, c.real_time_factor,
            c.markdown(), c.to_dict(), c.assumed, c, c.assumed_categories, c.time_on_chip,
        )  # fmt: skip


#: The registered provider.
PROFILES = Profiles()
