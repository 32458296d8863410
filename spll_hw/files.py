"""Output files and folders written atomically, so an interrupted run (Ctrl-C, a crash, a full
disk) leaves the old file or the new one, never half of one.

* A file (:func:`atomic_path`, :func:`write_text`, :func:`write_json`, :func:`save_figure`): to a
  temporary file in the same folder, then renamed over the target (``os.replace``).
* A whole output folder (:func:`atomic_folder`): into a temporary sibling folder, moved into
  place when every file is written; on failure the sibling is removed and an ``OSError`` is
  raised again as one line naming the path. Every command that writes an output folder should
  write it this way (``spll-hw export`` does): ``with atomic_folder(out) as stage:`` and write
  plain files into ``stage``.
"""

from __future__ import annotations

import errno
import io
import json
import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .provenance import provenance


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` (same suffix, so writers that go by it still work) to
    write to; renamed to ``path`` when the block ends, removed when it raises (an ``OSError``
    that names the temporary path then names ``path``)."""
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException as exc:
        temporary.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.filename is not None:
            if Path(os.fsdecode(exc.filename)) == temporary:
                exc.filename = str(path)
        raise


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as temporary:
        temporary.write_text(text)


def write_json(path: str | Path, payload: dict) -> None:
    """Write ``payload`` as indented JSON to ``path`` atomically (numpy scalars and arrays as
    numbers and lists)."""
    write_text(path, json.dumps(payload, indent=2, default=_json_default) + "\n")


def write_results(path: str | Path, payload: dict) -> None:
    """A command's ``results.json``: ``payload`` after a ``"provenance"`` entry (the spll-hw
    version, git commit and UTC time, :func:`spll_hw.provenance.provenance`), atomically."""
    write_json(path, {"provenance": provenance()} | payload)


def _json_default(value):
    """A numpy scalar or array as a JSON number or list (what ``json`` cannot write itself)."""
    if isinstance(value, np.integer | np.floating | np.bool_):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON: {type(value).__name__}")


def write_npz(path: str | Path, arrays) -> None:
    """``numpy.savez(path, **arrays)``, the archive built in memory and written with one plain
    write: on a full disk that write fails once, naming ``path``, where ``numpy.savez``'s zip
    writer would fail again while being collected (a ``ZipFile.__del__`` traceback after the
    error). Not atomic by itself: write to an :func:`atomic_path` or into an
    :func:`atomic_folder`."""
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    with writing(path) as target:
        target.write_bytes(buffer.getbuffer())


def save_figure(fig, path: str | Path, **options) -> None:
    """``fig.savefig(path, **options)`` (a matplotlib figure), atomically."""
    with atomic_path(path) as temporary:
        fig.savefig(temporary, **options)


@contextmanager
def atomic_folder(path: str | Path, whole: bool = False) -> Iterator[Path]:
    """A temporary folder beside ``path`` (``.NAME.tmp-PID``) to write a whole output folder in.

    When the block ends, its files move to ``path``: the folder is renamed as a whole where
    ``path`` does not exist or is an empty folder; into an existing folder each file is renamed
    over its namesake (``os.replace``, atomic per file) and the folder's other files stay,
    unless ``whole``: then the existing folder is replaced as a whole (renamed aside, the new
    one renamed into place, the old one removed), so that nothing of it is left beside the new
    files (an export folder: :func:`spll_hw.exporters.foreign_files` says which may be).
    When the block raises (a full disk, a permission error, Ctrl-C), the temporary folder and
    the parent folders made for it are removed and ``path`` is left as it was; an ``OSError``
    is raised again as one naming the file of ``path`` it was writing (:func:`named_error`).
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise NotADirectoryError(f"{path} is a file, not a folder")
    made = [p for p in (path.parent, *path.parent.parents) if not p.exists()]
    temporary = path.parent / f".{path.name}.tmp-{os.getpid()}"
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        shutil.rmtree(temporary, ignore_errors=True)  # a leftover of a killed run of this pid
        temporary.mkdir()
        yield temporary
        if whole:
            _replace_whole(temporary, path)
        else:
            _move_into(temporary, path)
    except BaseException as exc:
        shutil.rmtree(temporary, ignore_errors=True)
        for folder in made:  # deepest first; stops at the first that is not empty
            try:
                if folder.exists():
                    folder.rmdir()
            except OSError:
                break
        if isinstance(exc, OSError):
            raise named_error(exc, temporary, path) from exc
        raise


def _move_into(source: Path, target: Path) -> None:
    """Move the contents of folder ``source`` to ``target`` and remove ``source``."""
    if target.is_dir() and not any(target.iterdir()):
        target.rmdir()
    if not target.exists():
        os.rename(source, target)
        return
    for entry in sorted(source.iterdir()):
        if entry.is_dir() and (target / entry.name).is_dir():
            _move_into(entry, target / entry.name)
        else:
            os.replace(entry, target / entry.name)
    source.rmdir()


def _replace_whole(source: Path, target: Path) -> None:
    """Put folder ``source`` in place of folder ``target`` (which may not exist): ``target``
    renamed aside, ``source`` renamed to it, the old one removed; where the second rename
    fails the old folder is renamed back."""
    if target.is_dir() and not any(target.iterdir()):
        target.rmdir()
    if not target.exists():
        os.rename(source, target)
        return
    old = target.parent / f".{target.name}.old-{os.getpid()}"
    shutil.rmtree(old, ignore_errors=True)
    os.rename(target, old)
    try:
        os.rename(source, target)
    except BaseException:
        os.rename(old, target)
        raise
    shutil.rmtree(old, ignore_errors=True)


@contextmanager
def writing(path: str | Path) -> Iterator[Path]:
    """Name ``path`` in an ``OSError`` raised in the block without a file name (a full disk
    fails a ``write``, which names none), for :func:`named_error`."""
    try:
        yield Path(path)
    except OSError as exc:
        if exc.filename is None:
            exc.filename = str(path)
        raise


class WriteError(OSError):
    """An ``OSError`` whose message names what could not be written (:func:`named_error`):
    :attr:`where` the file, :attr:`folder` the output folder left as it was."""

    def __init__(self, errno_: int | None, reason: str, where: Path, folder: Path) -> None:
        super().__init__(errno_, reason, str(where))
        self.reason, self.where, self.folder = reason, Path(where), Path(folder)

    def __str__(self) -> str:
        room = " (free some space or write elsewhere)" if self.errno in _NO_SPACE else ""
        return f"cannot write {self.where}: {self.reason}{room}; {self.folder} was left as it was"


#: ``errno`` values of a write that failed for want of room.
_NO_SPACE = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG}


def named_error(exc: OSError, temporary: Path, path: Path) -> OSError:
    """``exc`` as one line naming what could not be written: its file, with the temporary
    folder ``temporary`` read as ``path``, or ``path`` itself when it names none (a
    :class:`WriteError`, whose file is read the same way where it is already one: an export
    writes its folder inside the command's)."""
    where = path
    name = exc.where if isinstance(exc, WriteError) else exc.filename
    if name is not None:
        name = Path(os.fsdecode(name))
        where = path / name.relative_to(temporary) if name.is_relative_to(temporary) else name
    if isinstance(exc, WriteError):
        reason = exc.reason
    else:
        reason = exc.strerror or str(exc) or type(exc).__name__
    return WriteError(exc.errno, reason, where, path)
