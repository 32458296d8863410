"""Tuning the tables of a multichannel network file (``spll-hw tune --network FILE``).

A ``[[channel]]`` table (:mod:`spll_hw.multichannel.config`) gives every one of its channels a
copy of one network, so a table is tuned as one network: its base sPLL and frequency placement,
shared by its channels.

- **Search space** (:class:`TableSpaces`): per tuned table, Table 5 with the table's
  ``[channel.space]`` entries on top (the ``--space`` file format); Optuna sees the parameters
  as ``<table>:<parameter>`` (``2:tau_cco``). The table's layout, number of sPLLs, reference
  frequency and encoder stay as the file says, and so does a spread its space does not tune.
  Encoder parameters are not tuned here.
- **Objective** (:class:`MultichannelObjective`): the single network's
  :class:`~spll_hw.tune.objective.Objective` (noise draws, pruning subset, ridge CV,
  constraints) on the features :mod:`spll_hw.multichannel` decides from: every channel's TDE
  rates, concatenated in the file's order, of one sample per recording (its first ``window``
  s), each channel divided by its input level (:func:`~spll_hw.multichannel.features
  .input_levels` of the study's samples). Every channel is encoded once; the tables left
  fixed are simulated once per noise draw, so a trial costs only its tuned tables'
  simulation. A trial's constraints are the worst of its tuned tables'.
- **Channel by channel** (:meth:`MultichannelObjective.focus`, :mod:`spll_hw.tune.per_channel`):
  the objective keeps the spike trains of every table it may tune (``retunable``) and moves
  its tuned table from one to the next; a fixed table's rates are cached with the network
  they are of and simulated again only when the file gives that table another network.
- **Result**: the file with the tuned tables' networks written inline and every other table
  as it was (:meth:`~spll_hw.multichannel.config.MultichannelConfig.to_toml`).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from tqdm.auto import tqdm

from ..config import NetworkConfig
from ..datasets.multichannel import MultiChannelSet
from ..multichannel.config import ChannelGroup, MultichannelConfig
from ..multichannel.features import channel_trains, input_levels
from ..pipeline import jitter
from .objective import Objective, ObjectiveSettings, fingerprint
from .space import SearchSpace, constraint_values, network_config, network_values

#: Between a table's number and a parameter in the study's parameter names (``2:tau_cco``).
SEP = ":"
#: Phase-noise seed offset per table number, so two tables' channels never share a generator.
TABLE_SEED_STRIDE = 100_000


class TableSpaces(SearchSpace):
    """The search spaces of several tables as one: table ``k``'s dimension ``name`` is
    ``f"{k}:{name}"`` (every :class:`SearchSpace` method works on the joined names)."""

    def __init__(self, spaces: Mapping[int, SearchSpace]):
        self.tables = dict(spaces)
        self.dims = {
            f"{k}{SEP}{name}": dim
            for k, space in self.tables.items()
            for name, dim in space.dims.items()
        }

    def of(self, params: dict[str, float], table: int) -> dict[str, float]:
        """Table ``table``'s entries of the joined ``params``, by their own names."""
        prefix = f"{table}{SEP}"
        return {k.removeprefix(prefix): v for k, v in params.items() if k.startswith(prefix)}


def describe_table(config: MultichannelConfig, table: int) -> str:
    """``table 2 (ele1 ... tdc, 22 channels)``: a table of ``config`` by number and channels."""
    channels = config.groups[table - 1].channels
    names = ", ".join(channels) if len(channels) <= 3 else f"{channels[0]} ... {channels[-1]}"
    count = f", {len(channels)} channels" if len(channels) > 1 else ""
    return f"table {table} ({names}{count})"


def table_numbers(config: MultichannelConfig, items: Sequence[str], flag: str) -> list[int]:
    """The ``[[channel]]`` tables ``items`` name, sorted: a table's number (1 = the file's
    first) or any channel of it; ``ValueError`` naming ``flag`` and listing the tables."""
    tables = {c: k for k, g in enumerate(config.groups, start=1) for c in g.channels}
    out = set()
    for item in items:
        if item.isdigit() and 1 <= int(item) <= len(config.groups):
            out.add(int(item))
        elif item in tables:
            out.add(tables[item])
        else:
            listed = "; ".join(describe_table(config, k) for k in range(1, len(config.groups) + 1))
            raise ValueError(
                f"{flag}: {item!r} is neither a [[channel]] table's number nor one of its "
                f"channels; {config.source} has {listed}"
            )
    if not out:
        raise ValueError(f"{flag}: name at least one table (its number or one of its channels)")
    return sorted(out)


def table_space(config: MultichannelConfig, table: int) -> SearchSpace:
    """Table 5 with table ``table``'s ``[channel.space]`` entries on top; ``ValueError`` when
    it tunes an encoder parameter or nothing at all."""
    group = config.groups[table - 1]
    where = f"{config.source} {describe_table(config, table)}"
    space = SearchSpace.table5().with_overrides(group.space or {}, source=f"{where} [space]")
    if space.encoders:
        raise ValueError(
            f"{where}: its [space] tunes encoder parameter(s) {sorted(space.encoders)}; a "
            "multichannel study tunes the networks only: fix the encoder in [channel.encoder]"
        )
    if not space.tuned:
        raise ValueError(
            f"{where}: its [space] fixes every parameter, so there is nothing to tune; leave "
            "the table out of --groups or give a range"
        )
    return space


def start_params(config: MultichannelConfig, space: TableSpaces) -> tuple[dict, list[str]]:
    """The tuned parameters of the file's own networks (a first trial to run) and the names of
    those outside the search space (left for Optuna to sample)."""
    params, outside = {}, []
    for table, own in space.tables.items():
        values = network_values(config.groups[table - 1].network)
        for name in own.tuned:
            joined = f"{table}{SEP}{name}"
            if own.dims[name].contains(values[name]):
                params[joined] = values[name]
            else:
                outside.append(f"{joined} = {values[name]:g} ({own.dims[name].describe()})")
    return params, outside


def first_params(objective: MultichannelObjective) -> tuple[dict[str, float], bool]:
    """The first trial of a study of ``objective``'s tuned tables, the file's own values
    (:func:`start_params`), and whether some lay outside the search space (a note on stderr
    names them: Optuna samples those)."""
    enqueue, outside = start_params(objective.file, objective.space)
    if outside:
        print(
            f"note: {objective.file.source}: the first trial samples {', '.join(outside)}: the "
            "file's value lies outside the table's search space",
            file=sys.stderr,
        )
    return enqueue, bool(outside)


def check_exact(settings: ObjectiveSettings) -> None:
    """``ValueError`` when ``settings`` score on a chip profile: a multichannel study tunes
    the networks on the exact model."""
    if settings.profile is not None:
        raise ValueError(
            f"backend {settings.backend!r} simulates chip profile {settings.profile}; a "
            "multichannel study tunes the networks on the exact model (--backend golden)"
        )


@dataclass(frozen=True)
class ChannelDraw:
    """One noise draw of a multichannel study's data.

    Attributes:
        trains: tuned or retunable table → spike times [s] of its channels' samples,
            channel-major (channel ``c``, sample ``i`` at ``c * n + i``; ``n`` samples).
        fixed: table not tuned now → its features (TDE rates [Hz]), shape
            ``(n, channels * sPLLs)``.
        networks: table of ``fixed`` → the network its features are of.
    """

    trains: dict[int, list[np.ndarray]]
    fixed: dict[int, np.ndarray]
    networks: dict[int, NetworkConfig]


class MultichannelObjective(Objective):
    """Optuna objective of a multichannel study (module docstring); picklable.

    Args:
        config: the multichannel network file.
        tuned: numbers (1-based) of the tables to tune (:func:`table_numbers`).
        samples: one sample per tuning recording, every channel of ``config``.
        settings: :class:`~spll_hw.tune.objective.ObjectiveSettings` (``layout``, ``n_spll``
            and ``reference_frequency`` unused: the tables say them); the exact model only.
        threads: engine threads per trial.
        jobs: processes encoding the samples (once, here).
        progress: progress bars while encoding and simulating the fixed tables.
        retunable: tables (besides ``tuned``) whose spike trains are kept, so that
            :meth:`focus` can tune them later.
    """

    def __init__(
        self,
        config: MultichannelConfig,
        tuned: Sequence[int],
        samples: MultiChannelSet,
        settings: ObjectiveSettings,
        threads: int | None = None,
        jobs: int = 1,
        progress: bool = False,
        retunable: Sequence[int] = (),
    ):

        check_exact(settings)
        self.file = config
        self.tuned = tuple(sorted(set(tuned)))
        self.kept = set(self.tuned) | set(retunable)
        spaces = TableSpaces({k: table_space(config, k) for k in self.tuned})
        self.levels = input_levels(config, samples)
        self.encoding, self.input_level, self._encoded = None, None, None
        self.n_samples = len(samples)
        self.durations: dict[int, float] = {}
        trains: dict[int, list[np.ndarray]] = {}
        units = [(k, g, c) for k, g in enumerate(config.groups, start=1) for c in g.channels]
        for k, group, channel in tqdm(units, desc="encoding", unit="channel", disable=not progress):
            found, self.durations[k] = channel_trains(
                samples, channel, group, self.levels[channel], jobs
            )
            trains.setdefault(k, []).extend(found)
        flat = [t for k in sorted(trains) for t in trains[k]]
        self._score_on(
            spaces, samples.labels, samples.class_names, samples.duration, settings, threads,
            fingerprint(flat, samples.labels),
        )  # fmt: skip
        self._bar = None
        self.noisy = [self._draw(trains, r, progress) for r in range(settings.n_repeats)]

    def _draw(self, trains: dict[int, list[np.ndarray]], r: int, progress: bool) -> ChannelDraw:
        """Noise draw ``r`` (table ``k``'s trains jittered with seed ``seed + r +``
        :data:`TABLE_SEED_STRIDE` ``* k``, one generator per channel and sample), the fixed
        tables simulated."""
        s = self.settings
        noisy = {
            k: jitter(own, s.phase_noise, self.durations[k], s.seed + r + TABLE_SEED_STRIDE * k)
            for k, own in trains.items()
        }
        draw = ChannelDraw({k: noisy[k] for k in self.kept}, {}, {})
        self._cache(draw, [k for k in noisy if k not in self.tuned], noisy, r, progress)
        return draw

    def _cache(
        self,
        draw: ChannelDraw,
        tables: Sequence[int],
        trains: Mapping[int, list[np.ndarray]],
        r: int,
        progress: bool,
    ) -> None:
        """Simulate ``tables`` of :attr:`file` on their ``trains`` of noise draw ``r`` into
        ``draw``'s fixed features."""
        total = sum(len(trains[k]) for k in tables)
        everything = np.arange(self.n_samples)
        with tqdm(total=total, desc=f"fixed tables, noise draw {r + 1}", unit="train",
                  disable=not progress or not total) as self._bar:  # fmt: skip
            for k in tables:
                group = self.file.groups[k - 1]
                draw.fixed[k] = self._table_rates(k, group, trains[k], everything)
                draw.networks[k] = group.network
        self._bar = None

    def focus(self, table: int, config: MultichannelConfig, progress: bool = False) -> None:
        """Tune ``table`` (one of the tables whose trains are kept) of ``config`` (the study's
        file with other networks in some tables, e.g. those tuned before) from now on: every
        other kept table whose cached features are of another network than ``config``'s is
        simulated again."""
        if table not in self.kept:
            raise ValueError(
                f"table {table} is not among the tables this objective keeps the spike trains "
                f"of ({sorted(self.kept)}); build it with retunable=[..., {table}]"
            )
        self.file = config
        self.tuned = (table,)
        self.space = TableSpaces({table: table_space(config, table)})
        for r, draw in enumerate(self.noisy):
            draw.fixed.pop(table, None)
            draw.networks.pop(table, None)
            stale = [k for k in sorted(self.kept - {table})
                     if draw.networks.get(k) != config.groups[k - 1].network]  # fmt: skip
            self._cache(draw, stale, draw.trains, r, progress)

    def _checkpoint(self, done: int = 0) -> None:
        super()._checkpoint(done)
        if self._bar is not None:
            self._bar.update(done)

    def _table_rates(
        self,
        table: int,
        group: ChannelGroup,
        trains: list[np.ndarray],
        indices: np.ndarray,
        spec: str | None = None,
    ) -> np.ndarray:
        """Features of samples ``indices`` of one table (every channel through its own copy of
        ``group``'s network, one engine batch), shape ``(len(indices), channels * sPLLs)``."""
        c = len(group.channels)
        flat = (np.arange(c)[:, None] * self.n_samples + np.asarray(indices)[None, :]).ravel()
        rates = super().simulate(group.network, trains, flat, spec, duration=self.durations[table])[
            0
        ]
        return rates.reshape(c, len(indices), -1).transpose(1, 0, 2).reshape(len(indices), -1)

    def simulate(
        self,
        config: MultichannelConfig,
        draw: ChannelDraw,
        indices: np.ndarray,
        spec: str | None = None,
        keep: np.ndarray | None = None,
        duration: float | None = None,
    ) -> tuple[np.ndarray, list]:
        """Features of samples ``indices`` of ``config`` (the study's file with its tuned
        tables' networks replaced) on noise ``draw`` (a :class:`ChannelDraw`): the tuned
        tables simulated, and a kept one whose cached features are of another network; the
        fixed ones as drawn; shape ``(len(indices), config.n_spll)``,
        and no simulation results (nothing is costed on a chip: ``keep`` is unused, and each
        table's trains have their own ``duration``)."""
        parts = []
        for k, group in enumerate(config.groups, start=1):
            if k in self.tuned or (k in draw.trains and draw.networks.get(k) != group.network):
                parts.append(self._table_rates(k, group, draw.trains[k], indices, spec))
            elif draw.networks.get(k) != group.network:
                raise ValueError(
                    f"{describe_table(config, k)} has another network than the one its "
                    "features were simulated with, and its spike trains are not kept: build "
                    f"the objective with retunable=[..., {k}]"
                )
            else:
                parts.append(draw.fixed[k][indices])
        return np.concatenate(parts, axis=1), []

    def features_per_sample(self, config: MultichannelConfig) -> int:
        return config.n_spll

    def config(self, params: dict[str, float]) -> MultichannelConfig:
        """The file with the tuned tables' networks made from a trial's ``params``."""
        full = self.space.complete(params)
        groups = list(self.file.groups)
        for k in self.tuned:
            own = groups[k - 1].network
            values = {"spread": own.spread} | self.space.of(full, k)
            network = network_config(
                values, own.layout, own.n, own.reference_frequency, own.spread_seed
            )
            groups[k - 1] = replace(groups[k - 1], network=network, source="tuned")
        return replace(self.file, groups=tuple(groups))

    def constraints(self, config: MultichannelConfig) -> tuple[float, ...]:
        """The worst of the tuned tables' constraints, constraint by constraint."""
        each = [constraint_values(config.groups[k - 1].network) for k in self.tuned]
        return tuple(float(v) for v in np.max(each, axis=0))

    def describe_network(self) -> str:
        def table(k: int) -> str:
            g = self.file.groups[k - 1]
            return f"{describe_table(self.file, k)}: {len(g.channels)} x {g.network.n} sPLLs"

        fixed = [k for k in range(1, len(self.file.groups) + 1) if k not in self.tuned]
        text = f"multichannel `{self.file.source}`, {self.file.n_spll} sPLLs; tuned: "
        text += "; ".join(table(k) for k in self.tuned)
        return text + ("; fixed: " + "; ".join(table(k) for k in fixed) if fixed else "")

    def metadata(self) -> dict:
        """The single network's metadata and the file's tables: the fixed ones in full, the
        tuned ones' layout and size (a resumed study must have the same)."""

        def table(k: int, g: ChannelGroup) -> dict:
            net = g.network
            out = {"channels": list(g.channels), "tuned": k in self.tuned}
            out["encoder"] = [g.encoder[0], g.encoder[1]]
            out["input_level"] = g.input_level
            if k in self.tuned:
                out["network"] = {"layout": net.layout, "n": net.n,
                                  "reference_frequency": net.reference_frequency,
                                  "spread_seed": net.spread_seed}  # fmt: skip
            else:
                out["network"] = net.to_toml()
            return out

        tables = [table(k, g) for k, g in enumerate(self.file.groups, start=1)]
        return super().metadata() | {"multichannel": {"file": self.file.source, "tables": tables}}
