"""Fixed-length single-channel samples with class labels: what every dataset loader returns.

Recordings are cut into consecutive, non-overlapping samples of ``duration`` seconds (thesis 2.1:
2 s). A recording's tail shorter than one sample is discarded; discarded time and recordings too
short for even one sample are counted in :attr:`SampleSet.skipped` so reports can show them.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

#: Thesis sample length [s].
DEFAULT_SAMPLE_DURATION = 2.0


def sample_id(source: str) -> int:
    """A stable 64-bit id of one sample named by its ``source`` (e.g.
    ``"raw_data/mat1/mat1_3_bio.csv [4-6 s]"``: the recording file relative to the dataset and
    the time window): the first 8 bytes of its BLAKE2b hash, the same in every process, run
    and machine (unlike Python's salted ``hash``)."""
    return int.from_bytes(hashlib.blake2b(source.encode(), digest_size=8).digest(), "little")


@dataclass(frozen=True)
class SampleSet:
    """Equal-length pressure samples of one dataset.

    Attributes:
        signals: pressure samples, shape ``(n, L)``, float64, in the dataset's units.
        fs: sampling rate [Hz].
        labels: class index of each sample, shape ``(n,)``, int, in ``0..n_classes-1``.
        class_names: display name of each class.
        sources: where each sample came from (file and time span), length ``n``.
        name: dataset name for reports.
        skipped: human-readable notes on discarded data (short recordings, tails).
        unit: what one signal unit is (``"raw"``: the dataset's own units).
        numbers: the recording number of every sample, shape ``(n,)``, int >= 1 (BioTac: N of
            ``matX_N_bio.csv``; folder datasets: the file's 1-based position in its class
            folder, sorted by name), or ``None`` where samples are not numbered recordings
            (synthetic); :mod:`spll_hw.datasets.recordings` selects and holds out by them.
    """

    signals: np.ndarray
    fs: float
    labels: np.ndarray
    class_names: tuple[str, ...]
    sources: tuple[str, ...]
    name: str = ""
    skipped: tuple[str, ...] = field(default=())
    unit: str = "raw"
    numbers: np.ndarray | None = None

    def __post_init__(self) -> None:
        signals = np.asarray(self.signals, dtype=float)
        labels = np.asarray(self.labels, dtype=int)
        if signals.ndim != 2 or signals.shape[0] == 0 or signals.shape[1] < 2:
            raise ValueError(
                f"{self.name}: need a non-empty (n, L) array of samples, got {signals.shape}"
            )
        if not (np.isfinite(self.fs) and self.fs > 0):
            raise ValueError(
                f"{self.name}: sampling rate must be finite and > 0 Hz, got {self.fs!r}"
            )
        if labels.shape != (signals.shape[0],) or len(self.sources) != signals.shape[0]:
            raise ValueError(f"{self.name}: labels and sources must have one entry per sample")
        bad = np.flatnonzero(~np.isfinite(signals).all(axis=1))
        if bad.size:
            raise ValueError(f"{self.sources[bad[0]]}: sample contains NaN or infinite values")
        n_classes = len(self.class_names)
        if labels.min() < 0 or labels.max() >= n_classes:
            raise ValueError(f"{self.name}: labels must lie in 0..{n_classes - 1}")
        empty = [c for i, c in enumerate(self.class_names) if not np.any(labels == i)]
        if empty:
            raise ValueError(f"{self.name}: class(es) {empty} have no samples")
        object.__setattr__(self, "signals", signals)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "class_names", tuple(self.class_names))
        object.__setattr__(self, "sources", tuple(self.sources))
        object.__setattr__(self, "skipped", tuple(self.skipped))
        if self.numbers is not None:
            numbers = np.asarray(self.numbers, dtype=int)
            if numbers.shape != labels.shape:
                raise ValueError(f"{self.name}: need one recording number per sample")
            object.__setattr__(self, "numbers", numbers)

    def __len__(self) -> int:
        return self.signals.shape[0]

    @property
    def n_classes(self) -> int:
        return len(self.class_names)

    @property
    def duration(self) -> float:
        """Length of every sample [s]."""
        return self.signals.shape[1] / self.fs

    @property
    def recordings(self) -> np.ndarray:
        """The recording of every sample, shape ``(n,)``: its source without the time span
        (``"raw_data/mat1/mat1_3_bio.csv [4-6 s]"`` → ``"raw_data/mat1/mat1_3_bio.csv"``); a
        sample without a span is its own recording. Folds by recording group by these."""
        return np.array([re.sub(r" \[[^\]]*\]$", "", s) for s in self.sources])

    @property
    def noise_ids(self) -> np.ndarray:
        """A stable id of every sample, shape ``(n,)``, uint64: :func:`sample_id` of its source
        (recording file and time window). Stochastic encoders seed a sample's noise by it, so a
        recording window gets the same noise whichever other samples are loaded with it."""
        return np.array([sample_id(s) for s in self.sources], dtype=np.uint64)

    def class_counts(self) -> dict[str, int]:
        """Number of samples per class name."""
        counts = np.bincount(self.labels, minlength=self.n_classes)
        return dict(zip(self.class_names, counts.tolist(), strict=True))

    def subset(self, indices: Sequence[int] | np.ndarray) -> SampleSet:
        """The samples at ``indices``; classes left empty are dropped and labels renumbered."""
        idx = np.asarray(indices, dtype=int)
        kept = np.unique(self.labels[idx])
        relabel = np.full(self.n_classes, -1)
        relabel[kept] = np.arange(kept.size)
        return SampleSet(
            signals=self.signals[idx],
            fs=self.fs,
            labels=relabel[self.labels[idx]],
            class_names=tuple(self.class_names[k] for k in kept),
            sources=tuple(self.sources[i] for i in idx),
            name=self.name,
            skipped=self.skipped,
            unit=self.unit,
            numbers=None if self.numbers is None else self.numbers[idx],
        )

    def joined(self, other: SampleSet) -> SampleSet:
        """These samples followed by ``other``'s (same classes, rate and length)."""
        if (other.class_names, other.fs, other.signals.shape[1]) != (
            self.class_names, self.fs, self.signals.shape[1]
        ):  # fmt: skip
            raise ValueError(f"{other.name}: cannot join sample sets of different classes, "
                             "sampling rates or sample lengths")  # fmt: skip
        return replace(
            self,
            signals=np.concatenate([self.signals, other.signals]),
            labels=np.concatenate([self.labels, other.labels]),
            sources=self.sources + other.sources,
            skipped=self.skipped + other.skipped,
            numbers=None
            if self.numbers is None or other.numbers is None
            else np.concatenate([self.numbers, other.numbers]),
        )

    def split_by(self, held_out: np.ndarray) -> tuple[SampleSet, SampleSet]:
        """``(the others, the held-out samples)`` for a boolean mask ``(n,)``, both keeping
        every class (a ``ValueError`` names a class with no sample on one side)."""
        mask = np.asarray(held_out, dtype=bool)
        for side, name in ((~mask, "training"), (mask, "held-out")):
            missing = sorted(set(range(self.n_classes)) - set(self.labels[side].tolist()))
            if missing:
                names = [self.class_names[k] for k in missing]
                raise ValueError(f"{self.name}: class(es) {names} have no {name} samples")
        keep = {"class_names": self.class_names}
        return (replace(self.subset(np.flatnonzero(~mask)), **keep),
                replace(self.subset(np.flatnonzero(mask)), **keep))  # fmt: skip

    def reference_level(self) -> float:
        """Median over samples of each sample's RMS (signals are mean-free per recording)."""
        return float(np.median(np.sqrt(np.mean(self.signals**2, axis=1))))

    def input_scale(self, input_level: float | None = None) -> tuple[float, str]:
        """``(level, where it comes from)``: what the signals of a run that trains on these
        samples are divided by before encoding [this set's unit]: ``input_level`` (the level a
        network file's encoder was tuned at, :mod:`spll_hw.config`) when given, so the encoder
        sees the same amplitudes whichever samples are loaded; else :meth:`reference_level`."""
        if input_level is not None:
            return float(input_level), "the network file's input_level"
        return self.reference_level(), "median RMS of the training samples"

    def normalized(self, level: float | None = None, source: str | None = None) -> SampleSet:
        """The samples divided by :meth:`reference_level`, so a typical sample has RMS 1.

        One dataset-wide factor keeps amplitude differences between samples and classes (which
        carry information) while making encoder gains independent of the dataset's units.
        ``level`` [this set's unit] divides by another level instead: another set's (held-out
        test samples are scaled like the training samples they are scored against) or the one
        a network's encoder was tuned at; ``source`` says which in the new :attr:`unit`.
        """
        if level is None:
            level, source = self.reference_level(), source or "median sample RMS"
        level = float(level)
        if not level > 0:
            raise ValueError(f"{self.name}: samples are all zero, cannot normalise")
        unit = f"{source or 'a level of'} ({level:.6g} {self.unit})"
        return replace(self, signals=self.signals / level, unit=unit)

    def per_class(self, n: int, seed: int = 0) -> SampleSet:
        """At most ``n`` samples of every class, drawn without replacement (seeded), in order."""
        if n < 1:
            raise ValueError(f"samples per class must be >= 1, got {n}")
        rng = np.random.default_rng(seed)
        picks = []
        for k in range(self.n_classes):
            members = np.flatnonzero(self.labels == k)
            picks.append(np.sort(rng.permutation(members)[:n]))
        return self.subset(np.concatenate(picks))

    def summary(self) -> dict:
        """JSON-ready description: name, fs, sample duration, counts, skipped data."""
        return {
            "name": self.name,
            "fs_hz": self.fs,
            "sample_duration_s": self.duration,
            "n_samples": len(self),
            "class_counts": self.class_counts(),
            "skipped": list(self.skipped),
            "unit": self.unit,
        }


def split_recording(
    signal: np.ndarray, fs: float, duration: float = DEFAULT_SAMPLE_DURATION
) -> tuple[np.ndarray, float]:
    """Cut a 1-D recording into consecutive samples of ``duration`` seconds.

    Returns ``(samples, tail)``: samples of shape ``(k, round(duration * fs))`` and the length of
    the discarded tail [s]. ``k`` is 0 when the recording is shorter than one sample.
    """
    if not duration > 0:
        raise ValueError(f"sample duration must be > 0 s, got {duration!r}")
    length = int(round(duration * fs))
    if length < 2:
        raise ValueError(f"sample duration {duration} s at {fs} Hz gives fewer than 2 samples")
    x = np.asarray(signal, dtype=float)
    k = x.size // length
    return x[: k * length].reshape(k, length), (x.size - k * length) / fs


def text_lines(path, what: str) -> list[str]:
    """The lines of the text file ``path`` (a recording: ``what`` says which kind);
    ``ValueError`` naming the file where it cannot be read or is not text (a binary file,
    say, where UTF-8 decoding fails: the byte and where it is)."""
    try:
        return path.read_text().splitlines()
    except UnicodeDecodeError as exc:
        raise ValueError(
            f"{path}: not a text file (byte 0x{exc.object[exc.start]:02x} at offset "
            f"{exc.start} is not UTF-8): a {what} is a text file of comma-separated numbers"
        ) from None
    except OSError as exc:
        raise ValueError(f"{path}: cannot read {what} ({exc.strerror or exc})") from exc


def first_nonfinite(values: np.ndarray) -> int | None:
    """Index of the first NaN/inf entry of a 1-D array, or ``None``."""
    bad = np.flatnonzero(~np.isfinite(values))
    return int(bad[0]) if bad.size else None


def build_sample_set(
    recordings: Sequence[tuple[int, str, np.ndarray, int]],
    fs: float,
    class_names: Sequence[str],
    name: str,
    duration: float = DEFAULT_SAMPLE_DURATION,
) -> SampleSet:
    """Split labelled, numbered recordings ``(label, source, signal, number)`` into a
    :class:`SampleSet` (every sample keeps its recording's number, :attr:`SampleSet.numbers`).

    Each recording's mean is removed before splitting. Recordings shorter than one sample and
    discarded tails are listed in ``skipped``.
    """
    signals, labels, sources, numbers, skipped = [], [], [], [], []
    tail_total = 0.0
    for label, source, recording, number in recordings:
        x = np.asarray(recording, dtype=float)
        chunks, tail = split_recording(x - x.mean(), fs, duration)
        if chunks.shape[0] == 0:
            skipped.append(f"{source}: {x.size / fs:.3f} s is shorter than one {duration} s sample")
            continue
        tail_total += tail
        for i, chunk in enumerate(chunks):
            signals.append(chunk)
            labels.append(label)
            numbers.append(number)
            sources.append(f"{source} [{i * duration:g}-{(i + 1) * duration:g} s]")
    if tail_total > 0:
        skipped.append(f"{tail_total:.2f} s of recording tails shorter than one sample discarded")
    if not signals:
        raise ValueError(f"{name}: no recording is at least one {duration} s sample long")
    return SampleSet(
        signals=np.stack(signals),
        fs=fs,
        labels=np.asarray(labels),
        class_names=tuple(class_names),
        sources=tuple(sources),
        name=name,
        skipped=tuple(skipped),
        numbers=np.asarray(numbers),
    )
