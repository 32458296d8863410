"""quantize's chip profiles as the core sees them: the provider registered in the
``spll_hw.profiles`` entry-point group (:mod:`spll_hw.chips`)."""

from __future__ import annotations

from spll_hw.chips import ProfileInfo, Realisation
from spll_hw.network import Network

from .core import quantize
from .profiles import Profile, available_profiles, load_profile


def _info(profile: Profile) -> ProfileInfo:
    return ProfileInfo(profile.name, profile.kind, profile.description)


class Profiles:
    """Bundled profiles and TOML files, realised with :func:`quantize.quantize`."""

    def names(self) -> list[str]:
        return available_profiles()

    def describe(self, source: str) -> ProfileInfo:
        return _info(load_profile(source))

    def realise(self, network: Network, source: str, seed: int | None = None) -> Realisation:
        profile = load_profile(source)
        q = quantize(network, profile, seed=seed if profile.kind == "analog" else None)
        return Realisation(q.network, _info(profile), q.report_markdown(), q)


#: The registered provider.
PROFILES = Profiles()
