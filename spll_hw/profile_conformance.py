"""The conformance suite of chip profiles: what every profile, bundled or registered, must do,
as :mod:`spll_hw.backends.conformance` is for backends and :mod:`spll_hw.exporters.conformance`
for exporters. It asks the public profile API (:mod:`spll_hw.chips`) alone, so a profile of
any provider is judged by what it does.

Each check takes a profile source (a bundled name or a TOML file) and raises
``AssertionError`` naming the broken rule:

* :func:`check_loads`: it describes itself through the registry (:func:`spll_hw.chips.describe`)
  with a name (a bundled profile's own), a description and capabilities that agree with its
  figures (a clocked profile has a time step > 0; an ``[energy]`` table where it says it costs
  energy);
* :func:`check_realises`: it realises every reference network (:data:`REFERENCE_PRESETS`: the
  default network and a tuned BioTac one, in their layouts) or refuses one with a
  ``ValueError`` that says why; a realised network has the same size, finite parameters and a
  report; a mismatch profile draws differently per seed and the same per seed, any other
  realises the same whatever the seed;
* :func:`check_resources`: where it has a ``[resources]`` table, the resource report of every
  reference network is consistent: every sPLL's TDE and CCO placed on a listed core, each core's
  lists matching the placement, the totals the sums of the cores, cores and chips within what
  the profile offers when it fits, and a reason for every misfit.

``python -m spll_hw.profile_conformance [SOURCE ...]`` runs every check on each profile (default:
every bundled one) and prints one line per check.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator

import numpy as np

from . import chips
from .config import NetworkConfig
from .network import Network

#: Networks every profile is checked on: the default network (vary-offset), the same in
#: time-scale groups, and a tuned BioTac network.
REFERENCE_PRESETS: tuple[tuple[str, str | None], ...] = (
    ("vibtac-vary-offset-lif", None),
    ("vibtac-time-scaled-lif", "grouped:4"),
    ("biotac-tuned-vary-offset-lif", None),
)


def reference_networks() -> Iterator[tuple[str, Network]]:
    """``(label, network)`` of :data:`REFERENCE_PRESETS`."""
    for preset, layout in REFERENCE_PRESETS:
        config = NetworkConfig.preset(preset)
        if layout is not None:
            config = config.with_layout(layout)
        yield f"{preset} ({config.layout})", config.build()


def check_loads(source: str) -> None:
    """Describes itself (a bundled profile by its own name); its capabilities agree with its
    figures."""
    info = chips.describe(source)
    assert isinstance(info.name, str) and info.name, f"{source}: no name ({info.name!r})"
    if source in chips.names():
        assert info.name == source, f"{source}: describe() names {info.name!r}"
    assert info.description, f"{source}: no description"
    if info.clocked:
        assert info.dt > 0 and np.isfinite(info.dt), f"{source}: time step {info.dt!r}"
    has_energy = any(f.table == "energy" for f in chips.figures(source))
    assert info.energy == has_energy, f"{source}: energy {info.energy}, [energy] table {has_energy}"


def check_realises(source: str) -> None:
    """Realises every reference network (or refuses it with a reason); a mismatch profile's
    draws differ between seeds and repeat for one seed."""
    info = chips.describe(source)
    for label, network in reference_networks():
        try:
            realised = chips.realise(network, source, seed=1 if info.mismatch else None)
        except ValueError as exc:
            assert str(exc), f"{source} on {label}: refused without a reason"
            continue
        net = realised.network
        assert net.n_spll == network.n_spll, f"{source} on {label}: {net.n_spll} sPLLs"
        assert np.all(np.isfinite(net.matrix())), f"{source} on {label}: non-finite parameters"
        assert realised.report.strip(), f"{source} on {label}: empty report"
        again = chips.realise(network, source, seed=1).network.matrix()
        other = chips.realise(network, source, seed=2).network.matrix()
        if info.mismatch:
            assert np.array_equal(again, net.matrix()), f"{source} on {label}: seed 1 twice differs"
            assert not np.array_equal(other, net.matrix()), (
                f"{source} on {label}: seeds 1 and 2 equal (it says each chip is a draw)"
            )
        else:
            assert np.array_equal(other, net.matrix()), (
                f"{source} on {label}: seeds 1 and 2 differ, but it draws no mismatch"
            )


def check_resources(source: str) -> None:
    """The resource report of every reference network is consistent (module docstring)."""
    if not any(f.table == "resources" for f in chips.figures(source)):
        return
    for label, network in reference_networks():
        try:
            fit = chips.resources(chips.OnChip(network, source))
        except ValueError as exc:
            assert str(exc), f"{source} on {label}: refused without a reason"
            continue
        r, what = fit.detail, f"{source} on {label}"
        assert fit.fits == (not fit.problems), f"{what}: fits {fit.fits} with {fit.problems}"
        if not r.cores:
            assert fit.problems, f"{what}: nothing placed and no reason given"
            continue
        listed = {c.core for c in r.cores}
        for kind, where in (("TDE", r.tde_core), ("CCO", r.cco_core)):
            assert where.shape == (network.n_spll,), f"{what}: {kind} placement {where.shape}"
            assert set(where.tolist()) <= listed, f"{what}: a {kind} on a core not listed"
        for c in r.cores:
            assert list(c.tdes) == np.flatnonzero(r.tde_core == c.core).tolist(), (
                f"{what}: core {c.core}'s TDEs disagree with the placement"
            )
            assert list(c.ccos) == np.flatnonzero(r.cco_core == c.core).tolist(), (
                f"{what}: core {c.core}'s CCOs disagree with the placement"
            )
        assert sum(c.compartments for c in r.cores) == r.compartments, (
            f"{what}: cores hold {sum(c.compartments for c in r.cores)} compartments of "
            f"{r.compartments}"
        )
        assert fit.cores == len(r.cores) and fit.chips == r.n_chips, f"{what}: totals"
        if fit.fits:
            assert fit.cores <= r.cores_available * r.chips_available, (
                f"{what}: fits on {fit.cores} cores, the profile offers "
                f"{r.cores_available * r.chips_available}"
            )


CHECKS: tuple[tuple[str, Callable[[str], None]], ...] = (
    ("loads", check_loads),
    ("realises", check_realises),
    ("resources", check_resources),
)


def check_profile(source: str) -> dict[str, str]:
    """Every check on ``source``: ``{check: "ok" or the failure}``."""
    out = {}
    for name, check in CHECKS:
        try:
            check(source)
        except (AssertionError, ValueError) as exc:  # a broken profile fails to load
            out[name] = f"FAIL: {exc}"
        else:
            out[name] = "ok"
    return out


def main(argv: list[str] | None = None) -> int:
    sources = (sys.argv[1:] if argv is None else argv) or chips.names()
    failed = False
    for source in sources:
        for name, verdict in check_profile(source).items():
            print(f"{source:14s} {name:10s} {verdict}")
            failed |= verdict != "ok"
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
