"""Compare a consumer's spike counts with the ones an export folder's ``check.json`` records.

This file is copied as ``check_counts.py`` into the folders of ``spll-hw export --to
nir-standard`` and ``--to lava-standard``; it needs numpy only, not spll-hw. The folder's
``check_consumer.py`` (NIR: Norse, snnTorch) and ``run.py --check`` (Lava) run the inputs of
``check_inputs.npz`` (:func:`read_inputs`) through their consumer and hand the counts to
:func:`report`, which prints a table and says whether every count is the one ``check.json``
records for the folder (spll-hw's own run of it by the same rules): exactly, or within a
:class:`Tolerance` where the consumer computes in float32 and the record in float64.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import NamedTuple

import numpy as np

#: Files of the folder this reads.
CHECK_FILE = "check.json"
INPUTS_FILE = "check_inputs.npz"
#: How many differing sPLLs a failure names per input.
NAMED = 8


class Tolerance(NamedTuple):
    """How far a consumer's counts may be from ``check.json``'s, per input and part (TDE,
    CCO): the sum over sPLLs of ``|count - recorded|`` at most ``total`` of the recorded
    total or ``spikes``, and each sPLL's ``|count - recorded|`` at most ``spikes`` or
    ``fraction`` of its recorded count, whichever is larger in each (a threshold crossing
    rounded the other way moves a spike or two, whatever the total: on an input of ~100 TDE
    spikes 1 % is one spike)."""

    total: float
    spikes: int
    fraction: float

    def describe(self) -> str:
        return (f"per input, sum |count - check.json| <= {100 * self.total:g} % of check.json's "
                f"total or {self.spikes} spikes; per sPLL <= {self.spikes} spikes or "
                f"{100 * self.fraction:g} % of its count")  # fmt: skip


def read_check(folder: Path) -> dict:
    """The folder's ``check.json``.

    Raises:
        FileNotFoundError: the folder has no ``check.json`` or ``check_inputs.npz`` (it was
            written without its check), saying how to add them.
    """
    folder = Path(folder)
    missing = [name for name in (CHECK_FILE, INPUTS_FILE) if not (folder / name).is_file()]
    if missing:
        raise FileNotFoundError(
            f"{folder}: no {' or '.join(missing)}, so there is nothing to compare with: the "
            "folder was written without its check. `spll-hw export` writes both; `spll-hw "
            "export --check FOLDER --to TARGET` adds them to a folder with its params.toml"
        )
    return json.loads((folder / CHECK_FILE).read_text())


def read_inputs(folder: Path, check: dict) -> list[tuple[str, np.ndarray, float]]:
    """``(label, spike times [s], duration [s])`` of every input ``check.json`` lists, from
    ``check_inputs.npz``."""
    with np.load(Path(folder) / INPUTS_FILE, allow_pickle=False) as data:
        return [(x["label"], data[x["train"]], float(x["duration_s"])) for x in check["inputs"]]


def _parts(x: dict, counts: tuple[np.ndarray, np.ndarray]):
    """``(part, the consumer's counts, check.json's)`` of input row ``x``, TDE then CCO."""
    for part, mine in zip(("TDE", "CCO"), counts, strict=True):
        yield part, np.asarray(mine, dtype=np.int64), np.asarray(x[f"{part.lower()}_counts"])


def differences(
    check: dict, counts: list[tuple[np.ndarray, np.ndarray]], tolerance: Tolerance | None = None
) -> list[str]:
    """One line per input whose counts differ from ``check.json``'s (beyond ``tolerance``;
    ``None``: any difference), naming the sPLLs. ``counts``: per input of ``check.json``, the
    consumer's TDE and CCO counts per sPLL, shape ``(N,)`` each."""
    lines = []
    for x, c in zip(check["inputs"], counts, strict=True):
        wrong = []
        for part, mine, theirs in _parts(x, c):
            d = np.abs(mine - theirs)
            if tolerance is None:
                off = d > 0
            else:
                off = d > np.maximum(tolerance.spikes, tolerance.fraction * theirs)
                total = d.sum() / max(int(theirs.sum()), 1)
                if d.sum() > max(tolerance.total * theirs.sum(), tolerance.spikes):
                    wrong.append(f"{part} total off by {100 * total:.2f} % (sum over sPLLs)")
            wrong += [f"sPLL {i} {part} {mine[i]} (check.json {theirs[i]})"
                      for i in np.flatnonzero(off)]  # fmt: skip
        if wrong:
            more = f" and {len(wrong) - NAMED} more" if len(wrong) > NAMED else ""
            lines.append(f"{x['label']}: " + ", ".join(wrong[:NAMED]) + more)
    return lines


def table(check: dict, counts: list[tuple[np.ndarray, np.ndarray]]) -> str:
    """Per input: TDE and CCO spikes, the consumer's and check.json's, and how many sPLLs'
    counts are not equal."""
    rows = [f"{'input':<28} {'TDE spikes':>21} {'CCO spikes':>21} {'sPLLs not equal':>16}",
            f"{'':<28} {'consumer / check':>21} {'consumer / check':>21}"]  # fmt: skip
    for x, c in zip(check["inputs"], counts, strict=True):
        parts = list(_parts(x, c))
        tde, cco = (f"{int(mine.sum())} / {int(theirs.sum())}" for _, mine, theirs in parts)
        unequal = np.logical_or.reduce([mine != theirs for _, mine, theirs in parts])
        rows.append(f"{x['label'][:28]:<28} {tde:>21} {cco:>21} {np.count_nonzero(unequal):>16}")
    return "\n".join(rows)


def report(
    consumer: str,
    check: dict,
    counts: list[tuple[np.ndarray, np.ndarray]],
    tolerance: Tolerance | None = None,
) -> int:
    """Print the table and the verdict; 0 when every count is ``check.json``'s (within
    ``tolerance``), else 1, naming on stderr the inputs and sPLLs that differ."""
    print(table(check, counts))
    wrong = differences(check, counts, tolerance)
    within = "exactly" if tolerance is None else f"within the tolerance ({tolerance.describe()})"
    if wrong:
        print(f"{consumer} differs from check.json on {len(wrong)} of {len(counts)} inputs "
              f"(compared {within}):", *wrong, sep="\n", file=sys.stderr)  # fmt: skip
        return 1
    print(f"{consumer} counts the TDE and CCO spikes of every sPLL on every input as "
          f"check.json does, {within}")  # fmt: skip
    return 0
