"""Every channel of BioTac_slide_20_50, not only ``pac``: a :class:`MultiChannelSet`.

The ``*_bio.csv`` rows (:mod:`spll_hw.datasets.biotac`) are BioTac frames at ~100 Hz. Besides the
22 ``pac`` samples per row (one 2.2 kHz signal) each row holds one value of

- ``ele1`` ... ``ele19``: the 19 electrode impedances (the channels Taunyazov et al. classify),
- ``pdc``: the static (DC) fluid pressure, ``tac``: the AC temperature, ``tdc``: the DC
  temperature,

so each of those is a 100 Hz signal (Nyquist 50 Hz). Values are raw ADC counts; as for ``pac``,
each recording's mean is removed before it is cut into samples
(:func:`~spll_hw.datasets.samples.build_sample_set`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from .biotac import (
    _PAC_COLUMNS,
    BIOTAC_FS,
    PAC_PER_ROW,
    _raw_dir,
    material_name,
    read_biotac_columns,
    recording_jobs,
    recording_number,
)
from .multichannel import MultiChannelSet
from .samples import DEFAULT_SAMPLE_DURATION, build_sample_set

#: Rate [Hz] of the one-value-per-row channels (one BioTac frame every ~10 ms).
ROW_FS = BIOTAC_FS / PAC_PER_ROW
#: The longest window [s] of a recording that a decision may see (``--windows``): an hour, far
#: beyond any recording.
LONGEST_WINDOW = 3600.0
#: The 19 electrode channels.
ELECTRODES = tuple(f"ele{i}" for i in range(1, 20))
#: Every channel: ``pac`` (2.2 kHz), the electrodes and the DC pressure / temperature channels.
CHANNELS = ("pac", *ELECTRODES, "pdc", "tac", "tdc")


def channel_fs(name: str) -> float:
    """Sampling rate [Hz] of channel ``name`` (:data:`CHANNELS`); ``ValueError`` for another."""
    if name not in CHANNELS:
        raise ValueError(f"unknown BioTac channel {name!r}; channels: {', '.join(CHANNELS)}")
    return BIOTAC_FS if name == "pac" else ROW_FS


def read_channels(path: str | Path, channels: Sequence[str]) -> dict[str, np.ndarray]:
    """The signals of ``channels`` in one ``*_bio.csv`` file, raw counts: ``pac`` of shape
    ``(22 * rows,)`` at 2.2 kHz, every other channel ``(rows,)`` at 100 Hz. ``ValueError`` names
    the file, row and column of bad data (:func:`~spll_hw.datasets.biotac.read_biotac_columns`).
    """
    for name in channels:
        channel_fs(name)
    singles = [c for c in channels if c != "pac"]
    columns = (*(_PAC_COLUMNS if "pac" in channels else ()), *singles)
    values = read_biotac_columns(path, columns)
    out = {}
    for name in channels:
        if name == "pac":
            out[name] = values[:, :PAC_PER_ROW].reshape(-1)
        else:
            out[name] = values[:, columns.index(name)]
    return out


def load_biotac_channels(
    root: str | Path,
    channels: Sequence[str] = CHANNELS,
    classes: str | Iterable[str | int] = "thesis11",
    recordings: Iterable[int] | None = None,
    duration: float = DEFAULT_SAMPLE_DURATION,
    progress: bool = False,
) -> MultiChannelSet:
    """Load BioTac recordings as samples of ``duration`` s of every one of ``channels``.

    The ``pac`` channel's signals, labels and sources are bit for bit those
    :func:`~spll_hw.datasets.biotac.load_biotac` returns for the same arguments. ``duration``
    must be a whole number of ~10 ms rows, so every channel cuts the same samples.

    Args:
        root: dataset folder (containing ``raw_data/``) or the ``raw_data`` folder itself.
        channels: names from :data:`CHANNELS`, in the order the result keeps.
        classes: ``"thesis11"`` (default), ``"all"``, or materials (``resolve_classes``).
        recordings: recording numbers N to use (default: all present).
        duration: sample length [s].
        progress: show a progress bar over files.
    """
    channels = tuple(dict.fromkeys(channels))
    if not channels:
        raise ValueError("no BioTac channel selected")
    for name in channels:
        channel_fs(name)
    rows = duration * ROW_FS
    if not (duration > 0 and abs(rows - round(rows)) < 1e-6):
        raise ValueError(
            f"sample duration {duration!r} s is not a whole number of {1e3 / ROW_FS:g} ms "
            "BioTac rows: every channel must cut the same samples"
        )
    folders, jobs = recording_jobs(root, classes, recordings)
    raw = _raw_dir(root)
    per_channel: dict[str, list] = {name: [] for name in channels}
    for label, path in tqdm(jobs, desc="reading BioTac", unit="file", disable=not progress):
        source = str(path.relative_to(raw.parent))
        for name, signal in read_channels(path, channels).items():
            per_channel[name].append((label, source, signal, recording_number(path)))
    names = [material_name(f) for f in folders]
    return MultiChannelSet(
        {
            name: build_sample_set(
                recs, channel_fs(name), names, name=f"biotac-{name}", duration=duration
            )
            for name, recs in per_channel.items()
        }
    )
