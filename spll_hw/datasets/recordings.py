"""Samples by the recording they were cut from: numbers, selections and held-out recordings.

Every loaded recording has a number (:attr:`~spll_hw.datasets.SampleSet.numbers`): BioTac's
N of ``matX_N_bio.csv``; for a folder dataset the file's 1-based position in its class folder,
files sorted by name (the third file of every class folder is recording 3). A selection of
numbers takes those recordings of every class; a class without one of them is an error naming
the flag and the recordings that exist. A selection is written as ranges of numbers
(``"1-3,7"``, :func:`parse_ranges`: the command line's ``--recordings`` and its kin).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .samples import SampleSet

#: How many runs of numbers :func:`format_numbers` lists before it says how many more.
LISTED_RUNS = 12


def format_numbers(numbers: Iterable[int], limit: int = LISTED_RUNS) -> str:
    """``[1, 2, 3, 7, 9, 10]`` -> ``"1-3, 7, 9-10"``; past ``limit`` runs the rest is
    counted, not listed (``"1, 3, 5, ... and 40 more numbers up to 99"``), so an error message
    stays one short line however many numbers it names."""
    values = sorted({int(n) for n in numbers})
    parts: list[str] = []
    for i, n in enumerate(values):
        if i and values[i - 1] == n - 1:
            parts[-1] = f"{parts[-1].split('-')[0]}-{n}"
        else:
            parts.append(str(n))
    if len(parts) <= limit:
        return ", ".join(parts)
    shown = parts[:limit]
    rest = len(values) - sum(_run_length(part) for part in shown)
    return f"{', '.join(shown)}, ... and {rest} more numbers up to {values[-1]}"


def _run_length(part: str) -> int:
    """How many numbers a run of :func:`format_numbers` (``"7"`` or ``"9-12"``) holds."""
    first, _, last = part.partition("-")
    return int(last or first) - int(first) + 1


def recording_numbers(samples: SampleSet, flag: str = "recording numbers") -> np.ndarray:
    """The recording number of every sample, shape ``(n,)``; ``ValueError`` naming ``flag``
    for samples that are not numbered recordings (the synthetic textures)."""
    if samples.numbers is None:
        raise ValueError(
            f"{flag} needs numbered recordings (--dataset biotac or folder); the "
            f"{samples.name or 'given'} samples are not cut from numbered recordings"
        )
    return samples.numbers


def split_recordings(
    samples: SampleSet, held: Iterable[int], flag: str
) -> tuple[SampleSet, SampleSet]:
    """``(the other samples, the samples of recordings ``held``)``, both keeping every class.
    ``ValueError`` naming ``flag`` when a number of ``held`` is not loaded (the message lists
    those that are) or when a class would be left without samples on one side."""
    numbers = recording_numbers(samples, flag)
    held = sorted({int(n) for n in held})
    missing = sorted(set(held) - set(numbers.tolist()))
    if missing:
        raise ValueError(
            f"{flag}: recording(s) {format_numbers(missing)} are not loaded (loaded: "
            f"{format_numbers(numbers.tolist()) or 'none'}; check --recordings and the data "
            "folder)"
        )
    try:
        return samples.split_by(np.isin(numbers, held))
    except ValueError as exc:
        raise ValueError(f"{flag}: {exc} (recordings per class: "
                         f"{recordings_per_class(samples)})") from None  # fmt: skip


def recordings_per_class(samples: SampleSet) -> dict[str, int]:
    """``{class name: number of distinct recordings}`` of ``samples``."""
    recordings = samples.recordings
    return {
        name: int(np.unique(recordings[samples.labels == k]).size)
        for k, name in enumerate(samples.class_names)
    }


def check_folds(samples: SampleSet, folds: int, flag: str) -> None:
    """``ValueError`` naming ``flag`` when a class has fewer recordings than ``folds``: folds
    of whole recordings need one recording of every class in every fold."""
    short = {name: n for name, n in recordings_per_class(samples).items() if n < folds}
    if short:
        raise ValueError(
            f"{flag}: class(es) {short} have fewer recordings than the {folds} folds; "
            "use fewer --folds or more recordings"
        )


#: The most numbers a range of :func:`parse_ranges` may hold (a typo such as ``1-1000000000``
#: is refused at once instead of filling the memory with numbers).
MOST_NUMBERS = 100_000


def parse_ranges(text: str) -> list[int]:
    """``"1-3,7"`` → ``[1, 2, 3, 7]``; ``ValueError`` naming the text for a bad range or for
    more than :data:`MOST_NUMBERS` numbers."""
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            lo, hi = (int(v) for v in part.split("-", 1)) if "-" in part else (int(part),) * 2
        except ValueError:
            lo, hi = 1, 0
        if hi < lo:
            raise ValueError(f"bad range {part!r} in {text!r} (use e.g. 1-40 or 1,3,5-9)")
        if len(out) + hi - lo + 1 > MOST_NUMBERS:
            raise ValueError(f"{text!r} holds more than {MOST_NUMBERS} recording numbers "
                             f"({part!r} alone {hi - lo + 1}): give the recordings that exist, "
                             "e.g. 1-40")  # fmt: skip
        out.extend(range(lo, hi + 1))
    if not out:
        raise ValueError(f"empty range {text!r}")
    return out
