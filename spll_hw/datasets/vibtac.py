"""Generic folder-per-class recordings (the shape of the thesis's VibTac dataset).

Layout: ``<root>/<class name>/<recording>.{wav,csv,npy}``; every recording is one continuous
single-channel vibration signal (multi-channel files: ``channel`` picks one). The sampling rate is
read from WAV headers; CSV and NPY files carry none, so ``fs`` must be given for them. When both
exist they must agree.

CSV: one sample per row, the value in column ``channel`` (0-based); one non-numeric header row is
allowed. NPY: a 1-D array, or 2-D ``(samples, channels)``.

Each recording's mean is removed and it is cut into 2-s samples (:mod:`spll_hw.datasets.samples`).
Recordings are numbered by their 1-based position in their class folder, files sorted by name
(a class folder's third file is its recording 3; :mod:`spll_hw.datasets.recordings`), so
``recordings`` and held-out recordings select the same files of every class.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from scipy.io import wavfile
from tqdm.auto import tqdm

from .recordings import format_numbers
from .samples import (
    DEFAULT_SAMPLE_DURATION,
    SampleSet,
    build_sample_set,
    first_nonfinite,
    text_lines,
)

#: File suffixes the loader reads.
SUFFIXES = (".wav", ".csv", ".npy")


def read_recording(
    path: str | Path, fs: float | None = None, channel: int = 0
) -> tuple[np.ndarray, float]:
    """One recording as ``(signal, fs)``; ``ValueError`` naming the file (and row) on bad input."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".wav":
        signal, file_fs = _read_wav(path, channel)
        if fs is not None and not np.isclose(file_fs, fs):
            raise ValueError(
                f"{path}: WAV sampling rate is {file_fs:g} Hz but {fs:g} Hz was requested"
            )
        fs = file_fs
    elif suffix in (".csv", ".npy"):
        if fs is None:
            raise ValueError(
                f"{path}: {suffix} files carry no sampling rate: give it (--fs HZ on the "
                "command line, fs= from Python)"
            )
        signal = _read_csv(path, channel) if suffix == ".csv" else _read_npy(path, channel)
    else:
        raise ValueError(f"{path}: unsupported file type (use one of {SUFFIXES})")
    if not (np.isfinite(fs) and fs > 0):
        raise ValueError(f"{path}: sampling rate must be finite and > 0 Hz, got {fs!r}")
    bad = first_nonfinite(signal)
    if bad is not None:
        where = f"row {bad + 1}" if suffix == ".csv" else f"sample {bad}"
        raise ValueError(f"{path}, {where}: value is NaN or infinite")
    return signal, float(fs)


def _pick_channel(data: np.ndarray, channel: int, path: Path) -> np.ndarray:
    if data.ndim == 1:
        if channel != 0:
            raise ValueError(f"{path}: single-channel recording has no channel {channel}")
        return data
    if data.ndim != 2 or not 0 <= channel < data.shape[1]:
        raise ValueError(f"{path}: shape {data.shape} has no channel {channel}")
    return data[:, channel]


def _read_wav(path: Path, channel: int) -> tuple[np.ndarray, float]:
    try:
        with warnings.catch_warnings():  # a data chunk cut short: scipy only warns, and reads
            warnings.filterwarnings(  # what is there as a shorter recording
                "error", "Reached EOF prematurely", wavfile.WavFileWarning
            )
            rate, data = wavfile.read(path)
    except Exception as exc:  # scipy's parser fails on broken headers in many ways
        plain = isinstance(exc, OSError | ValueError)  # its own words, else not its internals
        kind = type(exc).__qualname__
        kind = kind if type(exc).__module__ == "builtins" else f"{type(exc).__module__}.{kind}"
        reason = exc if plain else f"its header is broken or cut short: {kind}"
        if isinstance(exc, wavfile.WavFileWarning):
            reason = f"its data is cut short: {exc}"
        raise ValueError(
            f"{path}: not a readable WAV file ({reason}); replace or remove the file"
        ) from exc
    return _pick_channel(np.asarray(data, dtype=float), channel, path), float(rate)


def _read_npy(path: Path, channel: int) -> np.ndarray:
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: not a readable .npy array ({exc})") from exc
    if not np.issubdtype(data.dtype, np.number):
        raise ValueError(f"{path}: array of dtype {data.dtype} is not numeric")
    return _pick_channel(np.asarray(data, dtype=float), channel, path)


def _read_csv(path: Path, channel: int) -> np.ndarray:
    lines = text_lines(path, "CSV recording")
    values = []
    for lineno, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        fields = line.split(",")
        if len(fields) <= channel:
            raise ValueError(
                f"{path}, row {lineno}: short row with {len(fields)} field(s), "
                f"need column {channel}"
            )
        try:
            values.append(float(fields[channel]))
        except ValueError:
            if lineno == 1:  # a header row
                continue
            raise ValueError(f"{path}, row {lineno}: not a number: {fields[channel]!r}") from None
    if not values:
        raise ValueError(f"{path}: no numeric rows")
    return np.asarray(values)


def _class_dirs(root: Path, classes: Iterable[str] | None) -> list[Path]:
    """The class folders of ``root``: ``classes`` (each must exist) or every subfolder, sorted
    (hidden ones left out); ``ValueError`` naming the folder otherwise."""
    if not root.is_dir():
        raise ValueError(f"{root}: dataset folder not found")
    if classes is None:
        class_dirs = sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith("."))
        if not class_dirs:
            raise ValueError(f"{root}: no class subfolders")
        return class_dirs
    class_dirs = [root / c for c in classes]
    for d in class_dirs:
        if not d.is_dir():
            raise ValueError(f"{d}: class folder not found")
    return class_dirs


def _numbered_files(folder: Path, recordings: Iterable[int] | None) -> list[tuple[Path, int]]:
    """``(file, recording number)`` of the recordings ``recordings`` of a class folder (its
    files sorted by name, numbered from 1; default: every file); ``ValueError`` naming the
    folder for an empty class or a number it does not have."""
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() in SUFFIXES)
    if not files:
        raise ValueError(
            f"{folder}: no recordings ({', '.join(SUFFIXES)}) in class folder (empty class)"
        )
    numbers = range(1, len(files) + 1) if recordings is None else sorted(set(recordings))
    absent = [n for n in numbers if not 1 <= n <= len(files)]
    if absent:
        raise ValueError(
            f"{folder}: no recording(s) {format_numbers(absent)}: the class folder has "
            f"{len(files)} "
            f"(1-{len(files)}, its {', '.join(SUFFIXES)} files sorted by name)"
        )
    return [(files[n - 1], n) for n in numbers]


def load_folder_dataset(
    root: str | Path,
    fs: float | None = None,
    classes: Iterable[str] | None = None,
    channel: int = 0,
    duration: float = DEFAULT_SAMPLE_DURATION,
    name: str | None = None,
    progress: bool = False,
    recordings: Iterable[int] | None = None,
) -> SampleSet:
    """Load ``<root>/<class>/*.{wav,csv,npy}`` as 2-s samples.

    Args:
        root: folder with one subfolder per class.
        fs: sampling rate [Hz]; required for CSV/NPY, checked against WAV headers.
        classes: class folder names to use (default: every subfolder, sorted).
        channel: column / channel of multi-channel recordings.
        duration: sample length [s].
        name: dataset name for reports (default: the folder name).
        progress: show a progress bar over files.
        recordings: recording numbers to use, each a file's 1-based position in its class
            folder sorted by name (default: every file); ``ValueError`` naming the folder when
            a class has no file of one of them.
    """
    root = Path(root)
    class_dirs = _class_dirs(root, classes)
    jobs = [
        (label, path, number)
        for label, d in enumerate(class_dirs)
        for path, number in _numbered_files(d, recordings)
    ]
    recs, rates = [], set()
    for label, path, number in tqdm(
        jobs, desc="reading recordings", unit="file", disable=not progress
    ):
        signal, rate = read_recording(path, fs, channel)
        rates.add(rate)
        if len(rates) > 1:
            raise ValueError(
                f"{path}: sampling rate {rate:g} Hz differs from other files ({sorted(rates)})"
            )
        recs.append((label, str(path.relative_to(root.parent)), signal, number))
    return build_sample_set(
        recs, rates.pop(), [d.name for d in class_dirs], name=name or root.name, duration=duration
    )
