"""The export check's inputs of the network's own kind of signal: samples encoded by the
network's own encoder (:mod:`spll_hw.exporters.check` runs them beside its periodic and Poisson
trains).

A network **carries an encoder** (:func:`carried_encoder`) where its file has an ``[encoder]``
table (the tuned presets, a tuning study's ``best.toml``: :mod:`spll_hw.config`), or where it
is a thesis preset ``<dataset>-<layout>-<encoder>`` (``biotac-vary-offset-lif``), whose encoder
``spll-hw evaluate`` runs with its default settings; other networks carry none and are checked
on the reference trains alone. Its check inputs (:func:`encoded_inputs`):

* **Recordings** where a BioTac_slide_20_50 folder is at hand (``spll-hw export --data DIR``;
  for a ``biotac-`` preset also ``$SPLL_HW_BIOTAC_DIR``): :data:`WINDOWS`, one window of the
  check's length from each of four recordings that no tuning saw (recordings 33-40 are held
  out of every tuned preset's study, the presets' header comments), :data:`WINDOW_START` s
  into the recording, the recording's mean removed (as :mod:`spll_hw.datasets.biotac` does),
  divided by the encoder's ``input_level`` (else by the windows' own median RMS), encoded.
  ``check.json`` names each one's file, the CSV line its window starts on and its window.
* **Synthetic signals** elsewhere (a VibTac preset, no BioTac folder): :data:`SYNTHETIC`
  samples of the embedded synthetic textures (:func:`spll_hw.datasets.synthetic.make_synthetic`:
  narrowband peaks and a broadband floor at 2.2 kHz, as the BioTac PAC channel is sampled),
  each of another class, divided by their median RMS (the level every encoder is tuned for) and
  encoded by the same encoder: rate-modulated, bursty trains like an encoded recording's.

Every input lasts the check's length (``--check-duration``, 1 s by default), at most
:data:`LONGEST` (a window must fit in a recording of 6-8 s), its train cut there (the peak
encoder's trains are stationary and may be longer).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import presets
from ..config import NetworkFile
from ..datasets.biotac import BIOTAC_ENV, BIOTAC_FS, PAC_PER_ROW, read_biotac_csv, recording_files
from ..datasets.synthetic import make_synthetic
from ..encoders import ENCODERS, make_encoder
from .check_inputs import DURATION, ENCODED_KINDS, CheckInput

#: ``(material folder, recording)`` of the check's recording windows: four of the thesis's 11
#: classes, recordings the tuned presets' studies held out (33-40).
WINDOWS = (("mat2", 33), ("mat5", 35), ("mat13", 37), ("mat20", 39))
#: Where each window starts in its recording [s] (past the finger's first contact).
WINDOW_START = 2.0
#: Longest encoded input [s]: a window from :data:`WINDOW_START` that every recording holds.
LONGEST = 4.0
#: Classes of the synthetic textures whose first sample each is one synthetic input.
SYNTHETIC = 4
#: Seed of the synthetic textures.
SYNTHETIC_SEED = 0
#: Sampling rate [Hz] of the synthetic signals: the BioTac PAC channel's.
SYNTHETIC_FS = 2200.0
#: Input kinds of ``check.json`` (:data:`~spll_hw.exporters.check_inputs.ENCODED_KINDS`).
RECORDING_KIND, SYNTHETIC_KIND = ENCODED_KINDS


@dataclass(frozen=True)
class CarriedEncoder:
    """The encoder a network carries.

    Attributes:
        name: a key of :data:`spll_hw.encoders.ENCODERS`.
        settings: its keyword arguments (empty: its defaults).
        input_level: the signal level it was tuned at [raw dataset units], or ``None``.
        dataset: ``"biotac"``, ``"vibtac"`` or ``""`` (not known: a file without a preset's
            name), the kind of signal the network was tuned on.
        origin: where it comes from, in words (``check.json`` quotes it).
    """

    name: str
    settings: dict
    input_level: float | None
    dataset: str
    origin: str

    def encoder(self):
        return make_encoder(self.name, **self.settings)


def carried_encoder(network: NetworkFile) -> CarriedEncoder | None:
    """The encoder ``network`` (a read ``--network``) carries (module docstring), ``None``
    where it carries none."""
    source = str(network.source)
    name = Path(source).name if not presets.is_preset(source) else source
    dataset = next((d for d in ("biotac", "vibtac") if name.startswith(f"{d}-")), "")
    if network.encoder is not None:
        encoder, settings = network.encoder
        return CarriedEncoder(encoder, dict(settings), network.input_level, dataset,
                              f"the [encoder] table of {source}")  # fmt: skip
    last = name.rsplit("-", 1)[-1]
    if presets.is_preset(source) and dataset and last in ENCODERS:
        return CarriedEncoder(last, {}, None, dataset,
                              f"the preset's name {source} (its default settings)")  # fmt: skip
    return None


def encoded_inputs(
    network: NetworkFile, data: str | Path | None = None, duration: float | None = None
) -> list[CheckInput]:
    """The check inputs of ``network``'s own kind of signal (module docstring), ``duration``
    [s] each (``None``: :data:`~spll_hw.exporters.check_inputs.DURATION`; at most :data:`LONGEST`):
    recording windows where ``data`` (a BioTac_slide_20_50 folder) is given or, for a
    ``biotac-`` preset, ``$SPLL_HW_BIOTAC_DIR`` is set; synthetic signals elsewhere; none for
    a network that carries no encoder.

    Raises:
        ValueError: ``data`` is given for a network that carries no encoder; the folder is not
            a BioTac_slide_20_50 folder, a window's recording is missing, damaged (naming the
            file and line) or shorter than its window.
    """
    carried = carried_encoder(network)
    duration = min(DURATION if duration is None else float(duration), LONGEST)
    if carried is None:
        if data is not None:
            raise ValueError(
                f"--data {data}: the network {network.source} carries no encoder (no [encoder] "
                "table, not a preset named <dataset>-<layout>-<encoder>), so there is nothing "
                "to encode the recordings with; drop --data or give a network file with an "
                "[encoder] table"
            )
        return []
    if data is None and carried.dataset == "biotac" and os.environ.get(BIOTAC_ENV):
        data = os.environ[BIOTAC_ENV]
    if data is None:
        return synthetic_inputs(carried, duration)
    return recording_inputs(carried, data, duration)


def recording_inputs(carried: CarriedEncoder, data: str | Path,
                     duration: float) -> list[CheckInput]:  # fmt: skip
    """One input per :data:`WINDOWS` entry from the BioTac_slide_20_50 folder ``data``
    (module docstring), each ``duration`` [s] long."""
    root = Path(data)
    if not root.is_dir():
        raise ValueError(f"--data {root}: no such folder (a BioTac_slide_20_50 folder, with "
                         "raw_data/matX/matX_N_bio.csv)")  # fmt: skip
    n = int(round(duration * BIOTAC_FS))
    first = int(round(WINDOW_START * BIOTAC_FS))
    windows, where = [], []
    for folder, recording in WINDOWS:
        path = recording_files(root, folder, [recording])[0]
        signal = read_biotac_csv(path)
        if signal.size < first + n:
            raise ValueError(
                f"{path}: {signal.size / BIOTAC_FS:.2f} s long, shorter than the check's window "
                f"{WINDOW_START:g}-{WINDOW_START + duration:g} s; use a shorter "
                "--check-duration"
            )
        windows.append(signal[first : first + n] - signal.mean())
        # line 1 is the header; each line holds PAC_PER_ROW samples
        where.append((path, 2 + first // PAC_PER_ROW))
    signals = np.array(windows)
    level, level_words = _level(carried, signals)
    trains = carried.encoder().encode(signals / level, BIOTAC_FS, ids=list(range(len(windows))))
    return [
        CheckInput(
            f"{path.name} {WINDOW_START:g}-{WINDOW_START + duration:g} s, {carried.name} encoder",
            _cut(spikes, duration),
            duration,
            RECORDING_KIND,
            source={
                "file": str(path),
                "row": row,
                "window_s": [WINDOW_START, WINDOW_START + duration],
                "encoder": carried.name,
                "encoder_from": carried.origin,
                "level": level,
                "level_from": level_words,
            },
        )
        for (path, row), spikes in zip(where, trains, strict=True)
    ]


def synthetic_inputs(carried: CarriedEncoder, duration: float) -> list[CheckInput]:
    """:data:`SYNTHETIC` synthetic textures (module docstring) through ``carried``'s encoder,
    ``duration`` [s] each."""
    samples = make_synthetic(SYNTHETIC, 1, duration, SYNTHETIC_FS, SYNTHETIC_SEED)
    level = samples.reference_level()
    trains = carried.encoder().encode(samples.signals / level, SYNTHETIC_FS,
                                      ids=list(range(len(samples))))  # fmt: skip
    why = ("no BioTac_slide_20_50 folder at hand (--data, $" + BIOTAC_ENV + ")"
           if carried.dataset == "biotac" else
           f"no {carried.dataset or 'recorded'} data at hand")  # fmt: skip
    return [
        CheckInput(
            f"synthetic {samples.class_names[c]}, {carried.name} encoder",
            _cut(spikes, duration),
            duration,
            SYNTHETIC_KIND,
            source={
                "generator": "spll_hw.datasets.synthetic.make_synthetic",
                "seed": SYNTHETIC_SEED,
                "class": int(c),
                "fs_hz": SYNTHETIC_FS,
                "encoder": carried.name,
                "encoder_from": carried.origin,
                "level": level,
                "level_from": "median RMS of these signals",
                "why": why,
            },
        )
        for c, spikes in zip(samples.labels, trains, strict=True)
    ]


def _level(carried: CarriedEncoder, signals: np.ndarray) -> tuple[float, str]:
    """What the windows ``signals`` (shape ``(windows, samples)``, raw units) are divided by
    before encoding, and where it comes from."""
    if carried.input_level is not None:
        return float(carried.input_level), "the encoder's input_level"
    rms = float(np.median(np.sqrt(np.mean(signals**2, axis=1))))
    if not rms > 0:
        raise ValueError("the check's recording windows are all zero: cannot normalise them")
    return rms, "median RMS of these windows"


def _cut(spikes: np.ndarray, duration: float) -> np.ndarray:
    """``spikes`` (sorted times [s]) up to ``duration`` [s]."""
    spikes = np.asarray(spikes, dtype=float)
    return spikes[spikes <= duration]
