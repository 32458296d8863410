"""A multichannel network exported like any network: each channel group's network into a
folder of its own by the target's one-network exporter, checked there on its channels' own
encoded signals (``spll-hw export --network MULTICHANNEL --to nir-standard|lava-standard``).

Every channel of a group runs a copy of one network (:class:`~spll_hw.multichannel.config.
ChannelGroup`), so one exported network serves the whole group: a consumer runs it on the
group's channels side by side (a batch). Group ``g`` (1-based, in the file's order) goes into
``channels/G-FIRST[-LAST]/`` (:func:`group_folder`), written by :func:`.checked_folder.
export_into` exactly as ``spll-hw export --network FILE`` writes one network: the target's step
ladder where it has one, ``params.toml``, ``check.json`` and the README's verdict, ``cost.json``.

**Check inputs of each group** (:func:`group_inputs`): beside the reference trains, every
channel of the group in each of :data:`CHECK_RECORDINGS` (training recordings 1-32 only: recordings
33-40 stay unseen by every choice, the step a ladder picks included), each the first
``duration`` s of the recording, scaled by the channel's input level, its mean so far
subtracted and encoded by the group's encoder as the spiking readout sees them
(:func:`spll_hw.multichannel.readout.causal_trains`), so a group whose export fails on its own
channels' signals is refused, naming the group.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..datasets.biotac_channels import load_biotac_channels
from ..datasets.multichannel import MultiChannelSet
from ..files import atomic_folder, writing
from ..multichannel.config import ChannelGroup, MultichannelConfig
from ..multichannel.features import input_levels
from ..multichannel.readout import causal_trains
from . import check_out_folder, get
from .check import CheckReport
from .check_inputs import CheckInput
from .checked_folder import ExportOptions, export_into
from .encoded import RECORDING_KIND

#: ``(material folder, recording)`` of the check's recordings: four of the thesis's 11 classes,
#: training recordings (1-32) only.
CHECK_RECORDINGS = (("mat2", 1), ("mat5", 9), ("mat13", 17), ("mat20", 25))
#: The folder of the groups' exports in a multichannel export folder.
CHANNELS_DIR = "channels"


@dataclass(frozen=True)
class GroupExport:
    """One group's export.

    Attributes:
        folder: its folder, relative to the multichannel export folder.
        channels: the group's channels (its batch, in order).
        n_spll: sPLLs of the group's network (TDE features per channel).
        report: the folder's check.
        files: the files written, relative to the multichannel export folder.
    """

    folder: str
    channels: tuple[str, ...]
    n_spll: int
    report: CheckReport
    files: tuple[str, ...]


def group_folder(index: int, group: ChannelGroup) -> str:
    """``channels/G-FIRST[-LAST]``: group ``index`` (0-based) of a multichannel export."""
    names = group.channels[0] + (f"-{group.channels[-1]}" if len(group.channels) > 1 else "")
    return f"{CHANNELS_DIR}/{index + 1}-{names}"


def check_recordings(data: str | Path, duration: float, channels: Sequence[str]) -> MultiChannelSet:
    """The first ``duration`` s of each of :data:`CHECK_RECORDINGS` in the BioTac_slide_20_50
    folder ``data``, ``channels`` only (one sample per recording, in that order)."""
    root = Path(data)
    if not root.is_dir():
        raise ValueError(f"--data {root}: no such folder (a BioTac_slide_20_50 folder, with "
                         "raw_data/matX/matX_N_bio.csv)")  # fmt: skip
    materials = [m for m, _ in CHECK_RECORDINGS]
    numbers = sorted({n for _, n in CHECK_RECORDINGS})
    loaded = load_biotac_channels(root, channels, materials, numbers, duration).openings()
    keep = [
        next(i for i, src in enumerate(loaded.first_set.sources)
             if src.startswith(f"raw_data/{m}/{m}_{n}_bio.csv"))
        for m, n in CHECK_RECORDINGS
    ]  # fmt: skip
    return loaded.subset(keep)


def group_inputs(
    samples: MultiChannelSet, group: ChannelGroup, levels: dict[str, float], duration: float
) -> list[CheckInput]:
    """Every channel of the group in every sample of ``samples``, as the readout sees them
    (module docstring), ``duration`` [s] each, labelled with their recording and channel."""
    encoder = group.encoder[0]
    inputs = []
    for channel in group.channels:
        trains = causal_trains(samples, group, channel, levels[channel])
        sources = samples.channel(channel).sources
        for spikes, source in zip(trains, sources, strict=True):
            spikes = np.asarray(spikes, float)
            inputs.append(CheckInput(
                f"{source} {channel}, {encoder} encoder", spikes[spikes <= duration], duration,
                RECORDING_KIND,
                source={"file": source, "channel": channel, "window_s": [0.0, duration],
                        "encoder": encoder, "level": levels[channel],
                        "level_from": "the readout's input level of the channel"},
            ))  # fmt: skip
    return inputs


def export_groups(
    export,
    target: str,
    config: MultichannelConfig,
    stage: Path,
    options: ExportOptions,
    inputs: Sequence[Sequence[CheckInput]] | None = None,
) -> list[GroupExport]:
    """Every group of ``config`` exported by ``export`` (target ``target``) into its folder under
    ``stage`` (:func:`group_folder`) and checked there on the reference trains and ``inputs[g]``
    (none where ``inputs`` is ``None``). ``ValueError`` (:class:`~.checked_folder.CheckFailed`
    where a check fails, unless ``options.allow_error``) naming the group where one's export is
    refused."""
    done = []
    for g, group in enumerate(config.groups):
        folder = group_folder(g, group)
        extra = [] if inputs is None else list(inputs[g])
        try:
            made = export_into(export, target, group.network, stage / folder, extra, options)
        except ValueError as exc:  # a refusal or a failed check (CheckFailed), named by group
            where = f"channel group {g + 1} ({', '.join(group.channels)})"
            raise type(exc)(f"{where}: {exc}") from None
        files = tuple(str(p.relative_to(stage)) for p in made.files)
        done.append(GroupExport(folder, group.channels, group.network.build().n_spll,
                                made.report, files))  # fmt: skip
    return done


#: The multichannel folder's manifest: the groups, their steps, the feature order.
MANIFEST = "multichannel.json"
#: Its copy of the configuration (channels' networks and encoders).
CONFIG_FILE = "multichannel.toml"


@dataclass(frozen=True)
class GroupsExport:
    """A multichannel network's groups exported into one folder (:func:`export_all_groups`).

    Attributes:
        groups: each group's export, in the file's order.
        steps: each group's time step [s] (``standard.json``'s ``dt``; ``None`` where the
            target writes none).
        samples: the check's recordings (``None`` without a dataset).
        levels: each channel's input level [its raw unit] (``None`` without a dataset).
        files: every file written, relative to the folder.
    """

    groups: list[GroupExport]
    steps: list[float | None]
    samples: MultiChannelSet | None
    levels: dict[str, float] | None
    files: list[str]

    def manifest(self, config: MultichannelConfig, target: str) -> dict:
        """``multichannel.json``'s content."""
        return {
            "format": f"spll-hw multichannel sPLL network, {target} groups v1",
            "channels": list(config.channels),
            "groups": [
                {"folder": g.folder, "channels": list(g.channels), "n_spll": g.n_spll, "dt": s}
                for g, s in zip(self.groups, self.steps, strict=True)
            ],  # fmt: skip
        }

    def table(self) -> list[str]:
        """The README's table of the groups and their checks (Markdown lines)."""
        lines = ["| group | channels | sPLLs each | dt | check |", "|---|---|---|---|---|"]
        for g, s in zip(self.groups, self.steps, strict=True):
            r = g.report
            step = "-" if s is None else f"{s * 1e6:g} µs"
            lines.append(f"| `{g.folder}` | {', '.join(g.channels)} | {g.n_spll} | {step} | "
                         f"{'passed' if r.passed else 'FAILED'}: TDE rates "
                         f"{100 * r.tde_error:.1f} % off golden (limit "
                         f"{100 * r.max_error:.1f} %) |")  # fmt: skip
        return lines


def export_all_groups(
    export,
    target: str,
    config: MultichannelConfig,
    stage: Path,
    options: ExportOptions,
    data: str | Path | None = None,
    levels: dict[str, float] | None = None,
    duration: float = 4.0,
) -> GroupsExport:
    """Every group exported into ``stage`` (:func:`export_groups`) and checked on its channels'
    encoded signals where ``data`` (a BioTac_slide_20_50 folder) is given: the check's
    recordings (:func:`check_recordings`, ``duration`` [s] loaded), scaled by ``levels`` (else
    by their own median RMS), each check input the check's length (``options.check_duration``,
    default 1 s); ``multichannel.toml`` beside them. The caller writes the manifest."""
    samples = None
    if data is not None:
        samples = check_recordings(data, duration, config.channels)
        levels = levels or input_levels(config, samples)
    length = options.check_duration or 1.0
    inputs = None if samples is None else [
        group_inputs(samples.first(length), group, levels, length) for group in config.groups
    ]  # fmt: skip
    groups = export_groups(export, target, config, stage, options, inputs)
    steps = []
    for g in groups:
        info = stage / g.folder / "standard.json"
        steps.append(float(json.loads(info.read_text())["dt"]) if info.is_file() else None)
    with writing(stage / CONFIG_FILE) as path:
        path.write_text(config.to_toml())
    files = [f for g in groups for f in g.files] + [CONFIG_FILE]
    return GroupsExport(groups, steps, samples, levels if samples is not None else None, files)


def write_groups_only(
    target: str,
    config: MultichannelConfig,
    out: str | Path,
    saved=None,
    *,
    data: str | Path | None = None,
    options: ExportOptions | None = None,
) -> list[Path]:
    """A multichannel export of the channel groups alone (a target whose readout no writer
    states yet): every group by ``target``'s own exporter (:func:`export_all_groups`), the
    manifest and a README; written whole into ``out`` or not at all. ``ValueError`` where a
    readout (``saved``) is given: it names the target that writes one."""
    if saved is not None:
        raise ValueError(f"--to {target} writes a multichannel network's channel groups without "
                         "a readout: drop --readout and --threshold (--to nir-standard writes "
                         "the readout as standard nodes)")  # fmt: skip
    check_out_folder(out)
    with atomic_folder(out, whole=True) as stage:
        done = export_all_groups(get(target), target, config, stage, options or ExportOptions(),
                                 data)  # fmt: skip
        with writing(stage / MANIFEST) as path:
            path.write_text(json.dumps(done.manifest(config, target), indent=1))
        readme = [
            f"# Multichannel sPLL network, {target}",
            "",
            f"{config.n_spll} sPLLs of {len(config.channels)} channels, written by spll-hw from "
            f"`{config.source}` as one {target} export per channel group: every channel of a "
            "group runs a copy of the group's network (run the group's folder once per "
            f"channel). `{CONFIG_FILE}`: the channels' networks and encoders; `{MANIFEST}`: the "
            "groups and the feature order.",
            "",
            *done.table(),
        ]
        with writing(stage / "README.md") as path:
            path.write_text("\n".join(readme) + "\n")
    return [Path(out) / f for f in (*done.files, MANIFEST, "README.md")]
