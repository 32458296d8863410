"""The export check's per-sPLL verdict: which sPLLs of an export fail against golden.

:func:`spll_failures` judges each sPLL from its TDE spikes over every input of the check, the
export's and golden's (shape ``(N,)`` each, ``N`` sPLLs): one fails whose CCO runs open-loop
(its ``g_cco`` not in what was written: :func:`open_loop`) or whose TDE falls silent
(:data:`SILENT_FRACTION`) or runs away (:data:`RUNAWAY_FACTOR`) against golden where golden's
or its spikes are at least :data:`MIN_RATE` a second of input; :data:`FAILURE_CRITERIA` says
so in words. At most ``max_failed`` sPLLs may fail (:func:`failed_limit`, ``--max-failed-splls``,
default :data:`MAX_FAILED` = 0). :func:`spll_hw.exporters.check.check_run` records the
failures in :attr:`~spll_hw.exporters.check.CheckReport.failed`, :func:`failure_words` says
them in one sentence, and :func:`count_error` is each sPLL's relative count error against
golden (shape ``(N,)``) that a failed check names its worst sPLLs by.
"""

from __future__ import annotations

import numpy as np

from ..network import Network
from . import FolderRun

#: How many sPLLs may fail the per-sPLL verdict by default (``--max-failed-splls``).
MAX_FAILED = 0
#: A TDE *falls silent* with fewer than this fraction of golden's spikes over the check's
#: inputs (where golden's are at least :data:`MIN_RATE` per second of input).
SILENT_FRACTION = 0.1
#: A TDE *runs away* with more than this many times golden's spikes over the check's inputs
#: (and at least :data:`MIN_RATE` per second of input more).
RUNAWAY_FACTOR = 2.0
#: Fewest spikes per second of the check's inputs [Hz] that judge a TDE silent or running
#: away: a TDE of a few spikes that doubles is not one that runs away
#: (``vibtac-vary-offset-lif`` on lava-standard: an sPLL of 24 golden spikes over 10 s of
#: input has 56).
MIN_RATE = 5.0
#: When the per-sPLL verdict fails an sPLL (:func:`spll_failures`), in words.
FAILURE_CRITERIA = (
    "its CCO runs open-loop (its TDE's feedback, g_cco, is not in what was written), or its "
    f"TDE falls silent (under {100 * SILENT_FRACTION:g} % of golden's spikes over all inputs, "
    f"where golden's are at least {MIN_RATE:g} a second of input) or runs away (over "
    f"{RUNAWAY_FACTOR:g} times golden's, and at least {MIN_RATE:g} a second more)"
)


def spll_failures(tde_spikes: np.ndarray, golden_spikes: np.ndarray, open_ccos: np.ndarray,
                  seconds: float) -> list[dict]:  # fmt: skip
    """The per-sPLL verdict's failures (:data:`FAILURE_CRITERIA`): per failed sPLL, by index,
    ``{"spll": index, "why": [reasons]}``, from its TDE spikes over every input of the check,
    the export's and golden's (shape ``(N,)`` each), ``open_ccos``, the sPLLs whose CCO runs
    open-loop (:func:`open_loop`, indices), and ``seconds`` [s], the inputs' length in all."""
    mine = np.asarray(tde_spikes, dtype=int)
    ref = np.asarray(golden_spikes, dtype=int)
    why: dict[int, list[str]] = {int(i): ["open-loop CCO (g_cco not written)"]
                                 for i in open_ccos}  # fmt: skip
    least = MIN_RATE * seconds
    silent = (ref >= least) & (mine < SILENT_FRACTION * ref)
    runaway = (mine > RUNAWAY_FACTOR * ref) & (mine >= ref + least)
    for i in np.flatnonzero(silent | runaway):
        words = "falls silent" if silent[i] else "runs away"
        why.setdefault(int(i), []).append(f"TDE {words} ({mine[i]} spikes, golden {ref[i]})")
    return [{"spll": i, "why": why[i]} for i in sorted(why)]


def failure_words(failed: list[dict], n: int, free_frequencies: np.ndarray,
                  max_failed: int) -> str:  # fmt: skip
    """The per-sPLL verdict in one sentence (the README's, the CLI's, a failure's), from its
    failures ``failed`` (:func:`spll_failures`) among ``n`` sPLLs of ``free_frequencies`` [Hz]
    (shape ``(n,)``) of which ``max_failed`` may fail: each reason with the sPLLs it fails
    (their free frequency and, for a TDE, its spikes)."""
    if not failed:
        return f"no sPLL of {n} fails (open-loop CCO, silent or runaway TDE)"
    groups: dict[str, list[str]] = {}
    for x in failed:
        for why in x["why"]:
            head, _, detail = why.partition(" (")
            spikes = f", {detail.rstrip(')')}" if head.startswith("TDE") else ""
            groups.setdefault(head if spikes else why, []).append(
                f"{x['spll']} ({free_frequencies[x['spll']]:.1f} Hz{spikes})"
            )
    named = "; ".join(f"{why}: {', '.join(splls)}" for why, splls in groups.items())
    over = "" if len(failed) <= max_failed else ", more than allowed"
    return (f"{len(failed)} of {n} sPLLs fail (at most {max_failed} may, "
            f"--max-failed-splls){over}: {named}")  # fmt: skip


def open_loop(run: FolderRun, network: Network) -> np.ndarray:
    """The sPLLs of ``network`` whose CCO runs open-loop in what ``run`` simulates, indices:
    those the built object of ``run``'s backend names (its ``open_loop()``: Loihi's integers
    of ``--to lava-standard``, the graph of ``--to nir-standard``) where ``run`` reads as
    that backend's (:attr:`FolderRun.reads_as`); none where it has no such method or the
    folder is not what the backend builds."""
    none = np.zeros(0, dtype=int)
    if run.reads_as is None or not run.reads_as(run.backend, network):
        return none
    find = getattr(run.backend.prepared(network), "open_loop", None)
    return none if find is None else np.asarray(find(), dtype=int)


def failed_limit(max_failed: object) -> int:
    """The per-sPLL verdict's limit ``max_failed`` as an int (``None``: :data:`MAX_FAILED`);
    ``ValueError`` naming ``--max-failed-splls`` where it is not a whole number >= 0."""
    if max_failed is None:
        return MAX_FAILED
    try:
        whole = float(max_failed) == int(max_failed)
    except (TypeError, ValueError, OverflowError):
        whole = False
    if not whole or int(max_failed) < 0:
        raise ValueError(f"--max-failed-splls must be a whole number of sPLLs >= 0, got "
                         f"{max_failed!r}")  # fmt: skip
    return int(max_failed)


def count_error(mine, golden, part: str) -> np.ndarray:
    """Per sPLL, ``sum |c - c_ref| / max(sum c_ref, 1)`` of its ``part`` counts over the
    inputs, shape ``(N,)``."""
    c = np.array([getattr(r, f"{part}_counts") for r in mine])  # (inputs, N)
    ref = np.array([getattr(g, f"{part}_counts") for g in golden])
    return np.abs(c - ref).sum(axis=0) / np.maximum(ref.sum(axis=0), 1)
