"""The files of an export check in its folder: what :mod:`spll_hw.exporters.check` writes there
and what a later check or costing of the folder reads back.

:func:`write_check` writes a check's outcome (a :class:`~spll_hw.exporters.check.CheckReport`)
into the folder: :data:`CHECK_FILE` (per input its totals and the folder's TDE and CCO spike
count per sPLL), a section of :data:`README_FILE` with the tables (and, for an export kept
although it is off, a warning at the top) and :data:`INPUTS_FILE` with every input's train
(:func:`write_inputs`: spike times [s]), so that a consumer outside spll-hw can run the same
inputs and compare its counts with ``check.json`` sPLL by sPLL; a later check of the folder
(``spll-hw export --check FOLDER``) runs the user's trains and the encoded inputs among them
again (:func:`stored_inputs`, on reference inputs as long as before: :func:`stored_duration`)
on the network of :data:`NETWORK_FILE` (:func:`read_network`) and the target ``check.json``
names (:func:`stored_target`).
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..config import NetworkConfig
from ..files import atomic_path, write_json, write_npz, write_text
from ..network import Network
from .check import SECTION, WARNING, CheckReport, train_key
from .check_inputs import DURATION, ENCODED_KINDS, REFERENCE_KINDS, CheckInput, user_input

#: Files the check writes into the folder.
CHECK_FILE = "check.json"
INPUTS_FILE = "check_inputs.npz"
README_FILE = "README.md"
#: The network the folder was exported from (``spll-hw export`` writes it).
NETWORK_FILE = "params.toml"
#: Kinds of the inputs a later check of the folder runs again from ``check_inputs.npz``: the
#: user's trains and the encoded ones.
STORED_KINDS = ("file", *ENCODED_KINDS)


def read_network(folder: str | Path) -> Network:
    """The network an export folder was exported from: its ``params.toml``."""
    path = Path(folder) / NETWORK_FILE
    if not path.is_file():
        raise FileNotFoundError(
            f"{path}: no network in the folder (spll-hw export writes it); pass the network "
            "the folder was exported from"
        )
    return NetworkConfig.load(path).build()


def write_check(folder: str | Path, report: CheckReport, title: str | None = None) -> list[Path]:
    """Write ``report`` into ``folder``: ``check.json``, the README's check section (the
    warning at its top where the export is kept although it is off) and ``check_inputs.npz``
    (:func:`write_inputs`); each file atomically. ``title``: the heading of a README the
    folder does not have yet (default: the export's). Returns the files written."""
    folder = Path(folder)
    files = [folder / CHECK_FILE, folder / README_FILE, folder / INPUTS_FILE]
    write_inputs(files[2], report.trains)
    write_json(files[0], report.to_json())
    readme = folder / README_FILE
    title = title or f"sPLL network exported to {report.target}"
    text = readme.read_text() if readme.is_file() else f"# {title}\n"
    text = without_block(without_block(text, WARNING), SECTION).rstrip("\n")
    if not report.passed:
        text = report.warning() + "\n\n" + text
    write_text(readme, f"{text}\n\n{report.markdown()}\n")
    return files


def write_inputs(path: str | Path, inputs: Sequence[CheckInput]) -> None:
    """The check's inputs as an ``.npz`` at ``path`` (atomically): ``train<i>``
    (:func:`.check.train_key`, input ``i``'s spike times [s], shape ``(n_i,)``), ``labels``,
    ``kinds``, ``sources`` (each input's :attr:`CheckInput.source` as JSON) (str, shape
    ``(inputs,)``) and ``durations`` [s] (shape ``(inputs,)``), in the order of
    ``check.json``'s ``inputs``."""
    arrays = {train_key(i): np.asarray(x.spikes, dtype=float) for i, x in enumerate(inputs)}
    arrays |= {"labels": np.array([x.label for x in inputs], dtype=str),
               "kinds": np.array([x.kind for x in inputs], dtype=str),
               "sources": np.array([json.dumps(x.source) for x in inputs], dtype=str),
               "durations": np.array([x.duration for x in inputs], dtype=float)}  # fmt: skip
    with atomic_path(path) as temporary:
        write_npz(temporary, arrays)


def without_block(text: str, markers: tuple[str, str]) -> str:
    """``text`` without the block between ``markers`` (and the blank line after it)."""
    start = text.find(markers[0])
    end = text.find(markers[1])
    if start < 0 or end < start:
        return text
    return text[:start] + text[end + len(markers[1]) :].lstrip("\n")


def read_inputs(folder: str | Path) -> list[tuple[str, str, float, np.ndarray, dict]]:
    """Every input an earlier check of ``folder`` ran (``check_inputs.npz``), in order: its
    label, kind, run length [s] (NaN where an older spll-hw stored none), spike times [s] and
    source (:attr:`CheckInput.source`, empty where an older spll-hw stored none); none where
    there is no such file; ``ValueError`` naming the file when it is not one
    :func:`write_inputs` wrote."""
    path = Path(folder) / INPUTS_FILE
    if not path.is_file():
        return []
    try:
        with np.load(path, allow_pickle=False) as data:
            labels = [str(x) for x in data["labels"]]
            # A folder of an older spll-hw stored the user's trains only, without kinds.
            kinds = [str(x) for x in data["kinds"]] if "kinds" in data else ["file"] * len(labels)
            durations = (data["durations"].astype(float) if "durations" in data
                         else np.full(len(labels), np.nan))  # fmt: skip
            sources = ([json.loads(str(x)) for x in data["sources"]] if "sources" in data
                       else [{}] * len(labels))  # fmt: skip
            return [(label, kind, float(d), data[train_key(i)], source)
                    for i, (label, kind, d, source)
                    in enumerate(zip(labels, kinds, durations, sources, strict=True))]  # fmt: skip
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise ValueError(
            f"{path}: not the check inputs of spll-hw export ({type(exc).__name__}: {exc}): "
            "the file is damaged; export the folder again, or remove this file to check on the "
            "reference inputs alone"
        ) from exc


def stored_inputs(folder: str | Path) -> list[CheckInput]:
    """The user's trains and the encoded inputs an earlier check of ``folder`` ran (those of
    ``check_inputs.npz`` whose kind is one of :data:`STORED_KINDS`, each with its source; the
    reference inputs are made again); ``ValueError`` naming the file when it is not one
    :func:`write_inputs` wrote."""
    return [user_input(label, spikes) if kind == "file"
            else CheckInput(label, np.asarray(spikes, dtype=float), d, kind, source=source)
            for label, kind, d, spikes, source in read_inputs(folder)
            if kind in STORED_KINDS]  # fmt: skip


def reference_duration(trains: Sequence[CheckInput]) -> float:
    """The run length [s] of the reference inputs among a check's ``trains`` (its
    :attr:`CheckReport.trains`), :data:`DURATION` where it ran none."""
    return next((x.duration for x in trains if x.kind in REFERENCE_KINDS), DURATION)


def stored_duration(folder: str | Path) -> float | None:
    """The run length [s] of the reference inputs an earlier check of ``folder`` ran
    (``check_inputs.npz``), ``None`` where it stored none (an older spll-hw's folder);
    ``ValueError`` naming the file when it is not one :func:`write_inputs` wrote."""
    return next((d for _, kind, d, _, _ in read_inputs(folder)
                 if kind in REFERENCE_KINDS and d == d), None)  # fmt: skip


def stored_target(folder: str | Path) -> str | None:
    """The target an earlier check of ``folder`` recorded (``check.json``), if any."""
    path = Path(folder) / CHECK_FILE
    if not path.is_file():
        return None
    try:
        return str(json.loads(path.read_text())["target"])
    except (ValueError, KeyError) as exc:
        raise ValueError(f"{path}: not a check record of spll-hw export: {exc}") from exc
