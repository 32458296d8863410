"""Tuning for a chip: the study's objectives, the chip draws a trial is scored on, whether a
network fits, what a sample costs, and the Pareto front of a multi-objective study.

A study tunes for chip profile ``P`` when its backend simulates the network as ``P`` realises it
(``golden:profile=P``: the exact model of the quantized or mismatched network;
``golden-fixed-point:profile=P``: the chip's integer arithmetic). Then

* a trial's network is first checked against the chip (:func:`check_fit`: it must be realisable,
  and fit the chip's cores when the profile has a ``[resources]`` table); one that does not fit
  is pruned unsimulated, the reason in its ``error`` and ``fit`` user attributes;
* on an analog profile the trial is scored on ``K`` mismatch draws (:func:`draw_specs`:
  ``chip_seed`` 0..K-1) and its accuracy is their mean, so the winner is robust to the chip it
  lands on;
* the objectives (:data:`OBJECTIVES`) may add the chip's cost to the accuracy: ``energy``, the
  mean dynamic energy per sample [J] (:func:`sample_energy`: event counts of simulated samples
  × the chip's per-event costs, ``spll_hw.chips.cost``; static power never enters it), or
  ``cores``, the cores the network occupies; the study is then multi-objective and
  its result a Pareto front (:func:`pareto_front`, :func:`chosen_points`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import backends, chips
from ..config import NetworkConfig
from ..network import Network
from ..params import PARAM_NAMES
from ..pareto import front
from ..timestep import at_step
from .space import PROBE_SPLL

#: Objective name -> (Optuna direction, what it is, with its unit).
OBJECTIVES = {
    "accuracy": ("maximize", "mean CV accuracy (fraction)"),
    "energy": ("minimize", "mean dynamic energy per sample on the chip [J] (no static power)"),
    "cores": ("minimize", "cores the network occupies on the chip"),
}
#: The chip table each cost objective needs in the profile.
NEEDS_TABLE = {"energy": "energy", "cores": "resources"}


def parse_objectives(text: str | Sequence[str]) -> tuple[str, ...]:
    """``"accuracy,energy"`` -> ``("accuracy", "energy")``; ``ValueError`` for an unknown or
    repeated name, or a list that does not start with ``accuracy`` (what every study
    maximises; costs are traded against it)."""
    names = [n.strip() for n in text.split(",")] if isinstance(text, str) else list(text)
    names = [n for n in names if n]
    unknown = [n for n in names if n not in OBJECTIVES]
    if unknown:
        raise ValueError(
            f"unknown objective(s) {unknown}; choose from {', '.join(OBJECTIVES)} "
            "(e.g. --objectives accuracy,energy)"
        )
    if len(set(names)) != len(names):
        raise ValueError(f"objectives {names} name one objective twice")
    if not names or names[0] != "accuracy":
        raise ValueError(
            f"objectives {names}: the first must be accuracy (a cost is traded against it), "
            "e.g. accuracy,energy or accuracy,cores"
        )
    return tuple(names)


def directions(objectives: Sequence[str]) -> list[str]:
    """Optuna's direction (``"maximize"``/``"minimize"``) of every objective."""
    return [OBJECTIVES[n][0] for n in objectives]


def backend_profile(spec: str) -> str | None:
    """The chip profile (name or file) that backend ``spec`` simulates, ``None`` for the
    network as given (a fixed-point backend's profile is its arithmetic)."""
    backend = backends.get(spec)
    profile = backend.options.get("profile")
    return None if profile is None else str(getattr(profile, "name", profile))


def study_backend(backend: str, profile: str | None) -> str:
    """The backend spec of a study tuned for chip ``profile`` (``--profiles``): ``backend``
    with ``profile=P`` added when it names none (``golden`` -> ``golden:profile=P``).

    ``ValueError`` for an unknown profile, a backend that cannot simulate a chip profile, or a
    backend spec that names another profile than ``profile``.
    """
    if profile is None:
        return backends.get(backend).spec
    chips.describe(profile)  # an unknown or broken profile fails here, naming it
    name, options = backends.parse_spec(backend)
    if "profile" not in backends.backend_class(name).OPTIONS:
        raise ValueError(
            f"--profiles {profile}: backend {name!r} cannot simulate a chip profile; use golden "
            "(the exact model of the realised network) or golden-fixed-point (its arithmetic)"
        )
    given = options.get("profile")
    if given is not None and str(given) != profile:
        raise ValueError(
            f"--profiles {profile} but --backend {backend} simulates profile {given}: give one"
        )
    return backends.get(name, **(options | {"profile": profile})).spec


def check_time_step(backend: str) -> None:
    """``ValueError`` when ``backend`` steps a chip profile at another time step than the
    profile's own: the chip's fit (refractory counters, decay configurations) and energy
    (steps per sample) follow the profile's step, so a study would score one chip and cost
    another. A chip run at another step is a profile of its own: ``NAME@STEP``
    (``loihi2@40us``, :mod:`spll_hw.timestep`), or a variant file with ``base = "loihi2"`` and
    ``dt = ...`` (:mod:`quantize.profiles`)."""
    spec = backends.get(backend)
    dt, profile = spec.options.get("dt"), backend_profile(spec.spec)
    if dt is None or profile is None:
        return
    own = chips.describe(profile).dt
    if own is not None and not math.isclose(float(dt), own, rel_tol=1e-12):
        base = profile.rpartition("@")[0] or profile
        raise ValueError(
            f"backend {spec.spec} steps profile {profile!r} at dt = {float(dt):g} s, but the "
            f"profile's fit and energy assume its own dt = {own:g} s: tune for the profile at "
            f"that step instead (--profiles {at_step(profile, float(dt))}, or a variant file "
            f'with [profile] base = "{base}", a name, a description and [fixed_point] dt = '
            f"{float(dt):g}), and add --compare-profile {base} to measure it against the chip "
            "as published"
        )


def draw_specs(backend: str, chip_draws: int) -> tuple[str, ...]:
    """One backend spec per chip draw a trial is scored on: ``chip_seed`` 0..K-1 of an analog
    profile, else ``backend`` alone (``chip_draws`` must then be 1).

    ``ValueError`` when ``chip_draws`` < 1, when K > 1 on a backend without an analog profile
    (there is nothing to draw), or when the spec fixes ``chip_seed`` itself.
    """
    if isinstance(chip_draws, bool) or not isinstance(chip_draws, int) or chip_draws < 1:
        raise ValueError(f"chip draws must be an integer >= 1, got {chip_draws!r}")
    profile = backend_profile(backend)
    if not has_mismatch(profile):
        if chip_draws > 1:
            what = f"profile {profile!r} is fixed point" if profile else "no chip profile"
            raise ValueError(
                f"--chip-draws {chip_draws}: {what}, so every draw would be the same network; "
                "mismatch draws are for analog profiles"
            )
        return (backends.get(backend).spec,)
    base = backends.get(backend)
    if base.options.get("chip_seed") is not None:
        raise ValueError(
            f"backend {backend} fixes chip_seed; the study draws chip_seed 0..K-1 itself "
            "(--chip-draws K): drop chip_seed from the spec"
        )
    return tuple(backends.get(base, chip_seed=k).spec for k in range(chip_draws))


def baseline_specs(specs: Sequence[str], profile: str) -> tuple[str, ...]:
    """``specs`` (the study's, one per chip draw) with chip ``profile`` in place of theirs:
    where ``spll-hw tune --compare-profile`` scores the reference quantized afterwards (e.g.
    the chip as published, when the study tunes for a variant of it). ``ValueError`` for an
    unknown profile or one the backend cannot simulate."""
    chips.describe(profile)  # an unknown or broken profile fails here, naming it
    return tuple(backends.get(spec, profile=profile).spec for spec in specs)


def changed_parameters(
    network: Network, profile: str, seeds: Sequence[int | None] = (None,)
) -> tuple[str, ...]:
    """The sPLL parameters (:data:`spll_hw.params.PARAM_NAMES` order) that ``profile``
    realises differently from ``network`` in some sPLL on some mismatch draw of ``seeds``:
    the ones whose format or mismatch can cost accuracy. ``ValueError`` when it does not
    fit."""
    changed: set[str] = set()
    for seed in seeds:
        realised = chips.realise(network, profile, seed=seed).network
        for chip, asked in zip(realised.spll, network.spll, strict=True):
            changed |= {n for n in PARAM_NAMES if getattr(chip, n) != getattr(asked, n)}
    return tuple(n for n in PARAM_NAMES if n in changed)


def exact_specs(specs: Sequence[str], name: str | None = None) -> tuple[str, ...]:
    """The chip draws of ``specs`` simulated by the exact model of the realised network
    (``golden:profile=P``, each draw's ``chip_seed`` kept: a fixed-point backend's formats
    without its arithmetic), with parameter ``name`` kept at its requested value
    (``:exact=NAME``) when given."""
    out = []
    for spec in specs:
        options = {"profile": backend_profile(spec)}
        seed = backends.get(spec).options.get("chip_seed")
        if seed is not None:
            options["chip_seed"] = seed
        if name is not None:
            options["exact"] = name
        out.append(backends.get("golden", **options).spec)
    return tuple(out)


def chip_tables(profile: str) -> set[str]:
    """The chip tables profile ``profile`` has (``"resources"``, ``"timing"``, ``"energy"``)."""
    return {f.table for f in chips.figures(profile)}


def check_objectives(objectives: Sequence[str], profile: str | None) -> None:
    """``ValueError`` when a cost objective cannot be computed: no chip profile, or a profile
    without the table it needs (energy: ``[energy]``, cores: ``[resources]``)."""
    for name in objectives:
        table = NEEDS_TABLE.get(name)
        if table is None:
            continue
        if profile is None:
            raise ValueError(
                f"objective {name!r} is a cost on a chip: tune for one with --profiles "
                "(e.g. --profiles loihi2)"
            )
        if table not in chip_tables(profile):
            with_it = [p for p in chips.names() if table in chip_tables(p)]
            raise ValueError(
                f"objective {name!r} needs a [{table}] table, which profile {profile!r} does "
                f"not have; profiles with one: {', '.join(with_it) or 'none'}"
            )


def has_mismatch(profile: str | None) -> bool:
    """Whether chips of ``profile`` are mismatch draws (:attr:`spll_hw.chips.ProfileInfo.mismatch`;
    ``False`` without a profile)."""
    return profile is not None and chips.describe(profile).mismatch


def profile_kind(profile: str | None) -> str | None:
    """The profile's kind label, for reports (``None`` without a profile); decisions ask its
    capabilities (:func:`has_mismatch`), not this."""
    return None if profile is None else chips.describe(profile).kind


@dataclass(frozen=True)
class Fit:
    """A network against a chip profile.

    Attributes:
        problems: why it does not fit (empty: it fits).
        cores: cores it occupies (``None`` when the profile has no ``[resources]`` table).
    """

    problems: tuple[str, ...]
    cores: int | None

    @property
    def fits(self) -> bool:
        return not self.problems


def check_fit(network: Network, profile: str, seeds: Sequence[int | None] = (None,)) -> Fit:
    """Whether ``network`` fits ``profile`` for every mismatch draw of ``seeds``: realisable
    (``spll_hw.chips.realise``: number formats, offset levels, circuit groups) and, when the
    profile has a ``[resources]`` table, placed on the chip's cores
    (``spll_hw.chips.resources``)."""
    problems: list[str] = []
    for seed in seeds:
        try:
            chips.realise(network, profile, seed=seed)
        except ValueError as exc:
            problems.append(str(exc))
            break
    cores = None
    if not problems and "resources" in chip_tables(profile):
        fit = chips.resources(chips.OnChip(network, profile, seeds[0]))
        problems += list(fit.problems)
        cores = fit.cores
    return Fit(tuple(dict.fromkeys(problems)), cores)


def check_spread(space, settings) -> None:
    """``ValueError`` before the study when the search space's ``spread`` (per-sPLL diversity)
    makes networks the chip cannot realise while the same network without it fits: an analog
    chip builds every sPLL of a group with one circuit (its mismatch is the diversity it has),
    so a study whose trials nearly all draw ``spread > 0`` would prune every one of them.

    ``space`` is a :class:`~spll_hw.tune.space.SearchSpace`, ``settings`` the objective's
    :class:`~spll_hw.tune.objective.ObjectiveSettings`."""
    profile = settings.profile
    dim = space.dims.get("spread")
    if profile is None or dim is None or max(dim.extremes) <= 0:
        return
    plain = NetworkConfig(
        spll=PROBE_SPLL, layout=settings.layout, n=settings.n_spll,
        reference_frequency=settings.reference_frequency,
    )  # fmt: skip
    if not check_fit(plain.build(), profile).fits:
        return  # not the spread's doing: the trials say why
    spread = dataclasses.replace(plain, spread=max(dim.extremes), spread_seed=settings.seed)
    fit = check_fit(spread.build(), profile)
    if not fit.fits:
        raise ValueError(
            f"--spread / [space] spread up to {max(dim.extremes):g}: profile {profile!r} cannot "
            f"realise such networks ({fit.problems[0]}); tune for it without spread"
        )


@dataclass(frozen=True)
class Energy:
    """Mean energy per sample on a chip over the costed samples (and chip draws).

    Attributes:
        dynamic: J per sample of the events (:attr:`spll_hw.chips.ChipCost.dynamic_energy`).
        static: J per sample of static and core power × time on chip, apart (``None``: not
            modelled).
        n: costed samples (times chip draws).
    """

    dynamic: float
    static: float | None
    n: int


def sample_energy(network: Network, profile: str, results: Sequence, seeds: Sequence) -> Energy:
    """:class:`Energy` of simulated samples: ``results[i]`` (a
    :class:`~spll_hw.result.SimulationResult` of ``network``) was run on mismatch draw
    ``seeds[i]`` (``None`` for a fixed-point profile)."""
    if not results:
        raise ValueError("no simulated sample to cost")
    costs = [
        chips.cost(chips.OnChip(network, profile, seed), r)
        for r, seed in zip(results, seeds, strict=True)
    ]
    static = [c.static_energy for c in costs]
    return Energy(
        float(np.mean([c.dynamic_energy for c in costs])),
        None if None in static else float(np.mean(static)),
        len(results),
    )


def signs_of(objectives: Sequence[str]) -> list[float]:
    """+1 for every maximised objective, -1 for every minimised one."""
    return [1.0 if OBJECTIVES[n][0] == "maximize" else -1.0 for n in objectives]


def pareto_front(points: Sequence[Sequence[float]], objectives: Sequence[str]) -> list[int]:
    """Indices of the points no other point dominates (duplicates all kept), sorted by the
    first objective, best first."""
    signs = signs_of(objectives)
    return sorted(front(points, signs), key=lambda i: -signs[0] * points[i][0])


def chosen_points(
    points: Sequence[Sequence[float]], objectives: Sequence[str]
) -> list[tuple[int, str]]:
    """The front points to write out: each objective's best (its extreme) and the knee, the
    point nearest the ideal one once every objective is scaled to [0, 1] over the front;
    ``(index into points, role)``, most accurate first, a point chosen twice listed once with
    both roles."""
    if not points:
        return []
    front = pareto_front(points, objectives)
    signs = signs_of(objectives)
    x = np.array([points[i] for i in front], dtype=float) * np.array(signs)  # larger is better
    span = x.max(axis=0) - x.min(axis=0)
    scaled = np.divide(x - x.min(axis=0), span, out=np.ones_like(x), where=span > 0)
    roles: dict[int, list[str]] = {}
    for j, name in enumerate(objectives):
        best = front[int(np.argmax(x[:, j]))]
        roles.setdefault(best, []).append(f"best {name}")
    knee = front[int(np.argmin(np.linalg.norm(1.0 - scaled, axis=1)))]
    roles.setdefault(knee, []).append("knee")
    order = sorted(roles, key=lambda i: -signs[0] * points[i][0])
    return [(i, " + ".join(roles[i])) for i in order]
