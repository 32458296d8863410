"""Multichannel network files: one sPLL network per channel, described in one TOML file.

Every ``[[channel]]`` table names channels and the network and encoder each of them gets (every
channel of a table gets its own copy of the network: the sPLLs of two channels never interact,
they share parameters only)::

    [[channel]]
    channels = ["pac"]
    network = "biotac-tuned-time-scaled-lif"   # a preset or a network TOML file (relative to
                                               # this file); its [encoder] table is the encoder

    [[channel]]
    channels = ["ele1", "ele2", "ele3"]
    [channel.spll]                             # or the network inline: [spll] ...
    tau_cco_syn = 0.0539
    ...
    [channel.network]                          # ... and [network], as in a network file
    layout = "time-scaled"
    f_start = 2.0
    f_end = 45.0
    n = 16
    [channel.encoder]                          # the encoder (overrides a named file's one)
    name = "lif"
    tau = 0.05
    gain = 40.0
    [channel.space]                            # optional: what `spll-hw tune --network FILE`
    f_start = { low = 0.5, high = 5.0 }        # searches for this table (Table 5 overridden,
    f_end = { low = 15.0, high = 50.0 }        # as a --space file's [space] table)

The tables follow :mod:`spll_hw.config` (same keys, same errors, which name this file and the
table's number). A table's encoder ``input_level`` [the channel's raw unit] divides every one of
its channels; without one each channel is divided by its own training samples' median RMS.
Features are the TDE rates of every channel's network, concatenated in table order.
:meth:`MultichannelConfig.to_toml` writes a configuration back in this format (what a tuning
study's ``best.toml`` is).
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from .. import presets as network_presets
from ..config import (
    INPUT_LEVEL,
    NetworkConfig,
    read_encoder_document,
    read_network_file,
    toml_value,
)
from ..encoders import make_encoder
from ..params import read_toml
from ..tune.space import SearchSpace
from . import presets

#: Keys of a ``[[channel]]`` table.
CHANNEL_KEYS = ("channels", "network", "spll", "encoder", "space")
#: A key TOML takes unquoted.
_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


@dataclass(frozen=True)
class ChannelGroup:
    """Channels that each get a copy of one network and encoder.

    Attributes:
        channels: channel names.
        network: the network every channel of the group gets.
        encoder: ``(name, settings)`` for :func:`spll_hw.encoders.make_encoder`.
        input_level: what the group's signals are divided by before encoding [raw unit];
            ``None``: each channel's training samples' median RMS.
        source: where the network came from (a preset, a file, or ``"inline"``), for reports.
        space: the table's ``[space]`` entries (:mod:`spll_hw.tune.space` format: what a tuning
            study searches for this table instead of Table 5's; checked when read), or
            ``None``.
        backend: the simulator spec this group's channels run on where it is not the run's
            own (:func:`spll_hw.multichannel.clocks.with_group_backends`: a chip clocked at
            this group's own step); ``None``: the run's. Not part of the file.
    """

    channels: tuple[str, ...]
    network: NetworkConfig
    encoder: tuple[str, dict]
    input_level: float | None = None
    source: str = "inline"
    space: dict | None = None
    backend: str | None = None

    @property
    def key(self) -> str:
        """What makes two groups' features of one channel the same (network, encoder, level
        and the simulator it runs on)."""
        return repr((self.network, self.encoder, self.input_level, self.backend))

    def make_encoder(self):
        """The group's encoder (:func:`spll_hw.encoders.make_encoder`)."""
        name, settings = self.encoder
        return make_encoder(name, **settings)


@dataclass(frozen=True)
class MultichannelConfig:
    """A multichannel network: its channel groups, in feature order, and where it was read."""

    groups: tuple[ChannelGroup, ...]
    source: str = ""

    def __post_init__(self) -> None:
        if not self.groups:
            raise ValueError(f"{self.source}: no [[channel]] table (a channel and its network)")
        seen: dict[str, int] = {}
        for number, group in enumerate(self.groups, start=1):
            for name in group.channels:
                if name in seen:
                    raise ValueError(
                        f"{self.source}: channel {name!r} is in [[channel]] tables "
                        f"{seen[name]} and {number}; a channel gets one network"
                    )
                seen[name] = number

    @property
    def channels(self) -> tuple[str, ...]:
        """Every channel, in feature order."""
        return self.channels_of(self.groups)

    def to_toml(self, header: str = "") -> str:
        """This configuration as a file :meth:`load` reads back to equal groups (``header``:
        comment lines put first). A group whose network is a preset unchanged names it
        (``network = "PRESET"``); every other network is written inline, and every group's
        encoder is written out (it overrides a named preset's own)."""
        return header + "\n".join(_group_toml(g) for g in self.groups)

    @property
    def n_spll(self) -> int:
        """sPLLs of the whole network (one network per channel)."""
        return sum(len(g.channels) * g.network.n for g in self.groups)

    def only(self, channels: Sequence[str]) -> MultichannelConfig:
        """The same network on ``channels`` only (an ablation): groups keep their networks,
        groups left without a channel go. ``ValueError`` for a channel the network lacks."""
        absent = [c for c in channels if c not in self.channels]
        if absent:
            raise ValueError(
                f"{self.source}: has no channel(s) {absent}; it has {', '.join(self.channels)}"
            )
        groups = tuple(
            replace(g, channels=tuple(c for c in g.channels if c in channels))
            for g in self.groups
            if any(c in channels for c in g.channels)
        )
        return MultichannelConfig(groups, f"{self.source} ({', '.join(self.channels_of(groups))})")

    def split(self, tables: Sequence[int]) -> tuple[MultichannelConfig, list[int]]:
        """This file with each of ``tables`` (numbers, 1 = the first) split into one table per
        channel, each a copy of the table (network, encoder, input level, space): the same
        network and features in the same order, ready to be tuned channel by channel.
        Returns the file and the numbers its split tables have in it, in order."""
        wanted = set(tables)
        groups: list[ChannelGroup] = []
        numbers: list[int] = []
        for k, group in enumerate(self.groups, start=1):
            parts = [replace(group, channels=(c,)) for c in group.channels] if k in wanted else []
            numbers += range(len(groups) + 1, len(groups) + 1 + len(parts))
            groups += parts or [group]
        split = MultichannelConfig(tuple(groups), f"{self.source} (one table per channel)")
        return split, numbers

    def with_network(self, network: NetworkConfig, source: str = "") -> MultichannelConfig:
        """Every channel through copies of one ``network`` (one base sPLL and frequency
        placement shared by all tables, what a chip with few parameter sets needs); each table
        keeps its channels, encoder and input level and drops its ``[channel.space]``.
        ``source`` names the result in reports (default: this file's, with the change)."""
        groups = tuple(replace(g, network=network, source="inline", space=None)
                       for g in self.groups)  # fmt: skip
        label = source or f"{self.source} (one shared {network.layout} network of {network.n})"
        return MultichannelConfig(groups, label)

    @staticmethod
    def channels_of(groups: Sequence[ChannelGroup]) -> tuple[str, ...]:
        """Every channel of ``groups``, in order."""
        return tuple(c for g in groups for c in g.channels)

    def check_channels(self, known: tuple[str, ...]) -> None:
        """``ValueError`` naming the file for a channel that is not in ``known``."""
        unknown = [c for c in self.channels if c not in known]
        if unknown:
            raise ValueError(
                f"{self.source}: unknown channel(s) {unknown}; channels: {', '.join(known)}"
            )

    @classmethod
    def single(cls, channel: str, network: str | Path) -> MultichannelConfig:
        """One ``channel`` through the network file or preset ``network``, encoded with its
        ``[encoder]`` table (default LIF without one): the single-channel pipeline."""
        file = read_network_file(network)
        encoder = file.encoder or ("lif", {})
        group = ChannelGroup((channel,), file.config, encoder, file.input_level, str(network))
        return cls((group,), f"{channel} through {network}")

    @classmethod
    def load(cls, source: str | Path) -> MultichannelConfig:
        """A multichannel preset name (:mod:`spll_hw.multichannel.presets`) or TOML file."""
        path = presets.path(str(source)) if presets.is_preset(source) else Path(source)
        config = cls.from_document(read_toml(path, "multichannel network file"), path)
        return replace(config, source=str(source))  # a preset by its name

    @classmethod
    def from_document(cls, doc: dict, path: Path) -> MultichannelConfig:
        """The configuration of the parsed file ``doc`` (``path`` names it in errors and
        anchors relative network file names)."""
        unknown = sorted(set(doc) - {"channel"})
        if unknown:
            raise ValueError(f"{path}: unknown key(s) or table(s) {unknown}; expected [[channel]]")
        tables = doc.get("channel", [])
        if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
            raise ValueError(f"{path}: channel must be an array of tables ([[channel]])")
        groups = tuple(
            _group(table, path, f"{path} [[channel]] {number}")
            for number, table in enumerate(tables, start=1)
        )
        return cls(groups, str(path))


def _group(table: dict, path: Path, where: str) -> ChannelGroup:
    """The :class:`ChannelGroup` of one ``[[channel]]`` table (``where`` names it in errors)."""
    bad = sorted(set(table) - set(CHANNEL_KEYS))
    if bad:
        raise ValueError(f"{where}: unknown key(s) {bad}; known: {list(CHANNEL_KEYS)}")
    channels = table.get("channels")
    if (
        not isinstance(channels, list)
        or not channels
        or not all(isinstance(c, str) and c for c in channels)
    ):
        raise ValueError(f"{where}: channels must be a non-empty list of channel names")
    network = table.get("network")
    encoder, level = read_encoder_document(table, where)
    if isinstance(network, str):
        if "spll" in table:
            raise ValueError(f"{where}: give network = FILE|PRESET or [spll] and [network] tables")
        named = network if network_presets.is_preset(network) else path.parent / network
        file = read_network_file(named)
        config, source = file.config, network
        if encoder is None:
            encoder, level = file.encoder, file.input_level
    else:
        doc = {"spll": table.get("spll"), "network": network or {}}
        if doc["spll"] is None:
            raise ValueError(f"{where}: no network: give network = FILE|PRESET or a [spll] table")
        config, source = NetworkConfig.from_document(doc, where), "inline"
    if encoder is None:
        raise ValueError(f'{where}: no encoder: add an [encoder] table (name = "lif", ...)')
    space = table.get("space")
    if space is not None:
        place = f"{where} [channel.space]"
        try:
            SearchSpace.table5().with_overrides(space, source=place)
        except ValueError as exc:  # a dimension's own error does not say where it is
            text = str(exc)
            raise ValueError(text if text.startswith(place) else f"{place}: {text}") from None
    return ChannelGroup(tuple(channels), config, encoder, level, source, space)


def _group_toml(group: ChannelGroup) -> str:
    """One ``[[channel]]`` table of :meth:`MultichannelConfig.to_toml`."""
    lines = ["[[channel]]", f"channels = {json.dumps(list(group.channels))}"]
    named = group.source in network_presets.names()
    if named and NetworkConfig.preset(group.source) == group.network:
        lines.append(f"network = {json.dumps(group.source)}")
    else:
        lines += ["", *_nested(group.network.to_toml())]
    name, settings = group.encoder
    lines += ["", "[channel.encoder]", f"name = {json.dumps(name)}"]
    lines += [f"{_key(k)} = {_setting(v)}" for k, v in settings.items()]
    if group.input_level is not None:
        lines.append(f"{INPUT_LEVEL} = {float(group.input_level)!r}")
    if group.space is not None:
        lines += ["", "[channel.space]"]
        lines += [f"{_key(k)} = {_space_value(v)}" for k, v in group.space.items()]
    return "\n".join(lines) + "\n"


def _nested(text: str) -> list[str]:
    """The lines of a network file's tables (``[spll]``, ``[network]``) as tables of the
    current ``[[channel]]`` (``[channel.spll]``, ...)."""
    return [f"[channel.{line[1:]}" if line.startswith("[") else line for line in text.splitlines()]


def _key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key)


def _setting(value) -> str:
    """An encoder setting as its TOML value (``None`` as ``"none"``, as ``--set`` reads it)."""
    if value is None:
        return '"none"'
    if isinstance(value, bool):
        return str(value).lower()
    return toml_value(value)


def _space_value(spec) -> str:
    """A ``[space]`` entry: a number, or an inline table of a range or choices."""
    if isinstance(spec, dict):
        items = []
        for k, v in spec.items():
            if isinstance(v, list):
                v = "[" + ", ".join(toml_value(c) for c in v) + "]"
            else:
                v = _setting(v)
            items.append(f"{k} = {v}")
        return "{ " + ", ".join(items) + " }"
    return toml_value(spec)
