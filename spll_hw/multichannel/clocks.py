"""Separate clocks for the channel groups of a multichannel network.

A clocked chip steps every neuron it holds at one time step. The groups of a multichannel network
need different ones: the BioTac preset's ``pac`` network (sPLLs up to ~670 Hz, refractory periods
down to 79 µs) can be written in Loihi 2's integers at 40–80 µs only, its row channels (2–45 Hz,
CCO time constants up to 1.6 s) at 320 µs–1.28 ms only (:mod:`quantize.steps`), so no single step
writes the whole network. Where a group has a step of its own, it runs on a chip (or chips) of its
own at that step: its own clock, its own per-step energy and static power, and its own placement.

``--group-steps CHANNEL=STEP,...`` (``spll-hw slide`` and ``spll-hw chips --network``) names
a group by any of its channels: ``pac=80us,ele1=640us`` puts the group holding ``pac`` at 80 µs
and the one holding ``ele1`` (every row channel of the preset) at 640 µs. Groups without a step
run at the step the command was given (the backend's or profile's own).
"""

from __future__ import annotations

from dataclasses import replace

from quantize import load_profile
from quantize.steps import check_step

from .. import backends
from ..timestep import at_step, parse_step
from .config import ChannelGroup, MultichannelConfig

#: What ``--group-steps`` looks like, for messages.
SYNTAX = "CHANNEL=STEP,..., e.g. pac=80us,ele1=640us"
#: Steps [s] a refusal names as those that can write a group: 10 µs doubled up to 2.56 ms
#: (slow channel groups need steps far coarser than the default ``--steps`` ladder).
GROUP_LADDER = tuple(10e-6 * 2**k for k in range(9))


def parse_group_steps(text: str | None, config: MultichannelConfig) -> dict[int, float]:
    """``"pac=80us,ele1=640us"`` → ``{group index: step [s]}`` for ``config`` (index into
    ``config.groups``); ``{}`` for ``None`` or ``""``. ``ValueError`` naming the entry for a
    malformed entry, a channel the network lacks, a bad step or two steps for one group."""
    if not text or not text.strip():
        return {}
    owner = {c: k for k, g in enumerate(config.groups) for c in g.channels}
    steps: dict[int, float] = {}
    named: dict[int, str] = {}
    for entry in filter(None, (e.strip() for e in text.split(","))):
        channel, eq, step = (s.strip() for s in entry.partition("="))
        if not eq or not channel or not step:
            raise ValueError(f"--group-steps entry {entry!r}: write {SYNTAX}")
        if channel not in owner:
            raise ValueError(
                f"--group-steps entry {entry!r}: {config.source} has no channel {channel!r}; "
                f"it has {', '.join(config.channels)}"
            )
        group = owner[channel]
        if group in steps:
            raise ValueError(
                f"--group-steps: {named[group]!r} and {channel!r} are in one [[channel]] table "
                f"({group_label(config.groups[group])}), which runs at one step: give it once"
            )
        try:
            steps[group] = parse_step(step)
        except ValueError as exc:
            raise ValueError(f"--group-steps entry {entry!r}: {exc}") from None
        named[group] = channel
    return steps


def group_label(group: ChannelGroup) -> str:
    """A group as a reader names it: ``pac``, or ``ele1…tdc (22 channels)``."""
    if len(group.channels) == 1:
        return group.channels[0]
    return f"{group.channels[0]}…{group.channels[-1]} ({len(group.channels)} channels)"


def group_config(config: MultichannelConfig, index: int) -> MultichannelConfig:
    """The network of group ``index`` alone (its channels through its network)."""
    return config.only(config.groups[index].channels)


def clocked_profile(profile: str, group: ChannelGroup, dt: float) -> str:
    """Chip ``profile`` stepped every ``dt`` [s] for ``group`` (``loihi2`` → ``loihi2@80us``);
    ``ValueError`` naming the group and the steps of :data:`GROUP_LADDER` that can when the
    chip cannot write the group's network at ``dt`` (:func:`quantize.steps.check_step`)."""
    name = at_step(profile, dt)
    stepped = load_profile(name)  # an unclocked profile is refused here, by name
    try:
        check_step(group.network.build(), stepped, GROUP_LADDER)
    except ValueError as exc:
        raise ValueError(f"--group-steps, {group_label(group)}: {exc}") from None
    return name


def clocked_backend(spec: str, group: ChannelGroup, dt: float) -> str:
    """The backend ``spec`` with its chip profile stepped every ``dt`` [s] for ``group``
    (``golden-fixed-point:profile=loihi2`` → ``…:profile=loihi2@80us``, :func:`clocked_profile`);
    ``ValueError`` for a backend without a chip profile."""
    backend = backends.get(spec)
    profile = backend.options.get("profile")
    if not profile:
        raise ValueError(
            f"--group-steps needs a backend that runs a chip profile (e.g. "
            f"golden-fixed-point:profile=loihi2); {spec!r} has none"
        )
    return backends.get(backend, profile=clocked_profile(str(profile), group, dt)).spec


def with_group_backends(
    config: MultichannelConfig, spec: str, steps: dict[int, float]
) -> MultichannelConfig:
    """``config`` with each group of ``steps`` run on ``spec`` stepped at its own step
    (:func:`clocked_backend`; :attr:`ChannelGroup.backend`); the other groups keep ``spec``."""
    spec = backends.get(spec).spec
    groups = tuple(
        replace(g, backend=clocked_backend(spec, g, steps[k]) if k in steps else spec)
        for k, g in enumerate(config.groups)
    )
    return replace(config, groups=groups)
