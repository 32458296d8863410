"""The folder an export writes, one way for every export (NIR and Lava, exact and standard).

:class:`ExportFolder` writes the folder atomically (:func:`spll_hw.files.atomic_folder`): into a
temporary sibling, moved into place when the ``with`` block ends, removed when it raises, so a
full disk, a permission error or Ctrl-C leaves no half-written export. A folder that holds an
export already is replaced as a whole, never mixed with the new one; a folder that holds
anything no export writes is refused (:func:`spll_hw.exporters.check_out_folder`). It lists
every file written, in order (the list an ``spll_hw.exporters`` entry point returns, with the
paths the files have once in place). What goes into the files is the exports' own business; how
a JSON manifest, a text, an ``.npz`` of arrays, a copied source file, the model's grid rule
(``spll_grid.py``) or the comparison of a consumer's counts with the folder's check
(``check_counts.py``) are written is stated here once.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Mapping
from contextlib import ExitStack
from pathlib import Path

import numpy as np

from spll_hw.exporters import check_out_folder, is_export_file
from spll_hw.files import atomic_folder, write_npz, writing
from spll_hw.model import grid as model_grid

#: Name of the copy of :mod:`spll_hw.model.grid` beside a clocked export: the rule that bins
#: input spike times into steps, needing numpy only.
GRID_FILE = "spll_grid.py"
#: Name of the copy of :mod:`mappings.standalone_counts` beside an export that a consumer
#: outside spll-hw checks against ``check.json``, needing numpy only.
COUNTS_FILE = "check_counts.py"


class ExportFolder:
    """An export's output folder ``out`` (created with its parents), written inside a ``with``
    block; :attr:`files` lists what was written, in order, as paths in ``out``::

        with ExportFolder(out) as folder:
            folder.json("manifest.json", {...})
        return folder.files
    """

    def __init__(self, out: str | Path) -> None:
        self.path = Path(out)
        self.files: list[Path] = []
        self._stage: Path | None = None
        self._stack = ExitStack()

    def __enter__(self) -> ExportFolder:
        check_out_folder(self.path, "export folder")  # nothing but an export is replaced
        self._stage = self._stack.enter_context(atomic_folder(self.path, whole=True))
        return self

    def __exit__(self, *exc_info) -> bool:
        self._stage = None
        return self._stack.__exit__(*exc_info)

    def file(self, name: str) -> Path:
        """The path to write a file ``name`` to (in the temporary folder until the block
        ends; ``SUBFOLDER/NAME`` in a subfolder, made for it); listed in :attr:`files` as
        ``out / name``. A caller that writes it itself names it in its errors with
        :func:`spll_hw.files.writing`."""
        path = self.stage(name)
        self.files.append(self.path / name)
        path.parent.mkdir(parents=True, exist_ok=True)
        return path

    def stage(self, name: str = "") -> Path:
        """The temporary folder the export is written in until the block ends (where a caller
        writes a subfolder ``name`` itself, its files its own to list in :attr:`files`)."""
        if self._stage is None:
            raise RuntimeError("ExportFolder writes inside its with block only")
        top = Path(name).parts[0] if name else ""
        if top and not is_export_file(top):  # what replaces an export folder must know its files
            raise RuntimeError(f"ExportFolder: add {top!r} to spll_hw.exporters.EXPORT_FILES")
        return self._stage / name if name else self._stage

    def text(self, name: str, text: str) -> Path:
        """A text file."""
        with writing(self.file(name)) as path:
            path.write_text(text)
        return path

    def json(self, name: str, data: Mapping, *, indent: int = 1, newline: bool = False) -> Path:
        """A JSON file (numpy scalars written as numbers); ``newline`` ends it with one."""
        text = json.dumps(data, indent=indent, default=_json_number)
        return self.text(name, text + "\n" if newline else text)

    def arrays(self, name: str, arrays: Mapping[str, np.ndarray]) -> Path:
        """An ``.npz`` of named arrays (``numpy.savez``)."""
        path = self.file(name)
        write_npz(path, arrays)
        return path

    def copy(self, name: str, source: str | Path) -> Path:
        """A copy of the file ``source``."""
        with writing(self.file(name)) as path:
            shutil.copyfile(source, path)
        return path

    def grid(self) -> Path:
        """``spll_grid.py``: the model's grid rule (:mod:`spll_hw.model.grid`), by which a
        clocked export's user bins input spikes into steps."""
        return self.copy(GRID_FILE, model_grid.__file__)

    def counts(self) -> Path:
        """``check_counts.py``: how a consumer's spike counts are compared with the folder's
        ``check.json`` (:mod:`mappings.standalone_counts`)."""
        return self.copy(COUNTS_FILE, Path(__file__).with_name("standalone_counts.py"))


def _json_number(value):
    if isinstance(value, np.integer | np.floating):
        return value.item()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")
