"""The folder an export writes, one way for every export (NIR and Lava, exact and standard).

:class:`ExportFolder` creates the folder and lists every file written into it, in order: the
list an ``spll_hw.exporters`` entry point returns. What goes into the files is the exports'
own business; how a JSON manifest, a text, an ``.npz`` of arrays, a copied source file or the
model's grid rule (``spll_grid.py``) are written is stated here once.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from spll_hw.model import grid as model_grid

#: Name of the copy of :mod:`spll_hw.model.grid` beside a clocked export: the rule that bins
#: input spike times into steps, needing numpy only.
GRID_FILE = "spll_grid.py"


class ExportFolder:
    """An export's output folder (created with its parents); :attr:`files` lists what was
    written, in order."""

    def __init__(self, out: str | Path) -> None:
        self.path = Path(out)
        self.path.mkdir(parents=True, exist_ok=True)
        self.files: list[Path] = []

    def file(self, name: str) -> Path:
        """The path of a file ``name`` that the caller writes itself; listed in :attr:`files`."""
        path = self.path / name
        self.files.append(path)
        return path

    def text(self, name: str, text: str) -> Path:
        """A text file."""
        path = self.file(name)
        path.write_text(text)
        return path

    def json(self, name: str, data: Mapping, *, indent: int = 1, newline: bool = False) -> Path:
        """A JSON file (numpy scalars written as numbers); ``newline`` ends it with one."""
        text = json.dumps(data, indent=indent, default=_json_number)
        return self.text(name, text + "\n" if newline else text)

    def arrays(self, name: str, arrays: Mapping[str, np.ndarray]) -> Path:
        """An ``.npz`` of named arrays (``numpy.savez``)."""
        path = self.file(name)
        np.savez(path, **arrays)
        return path

    def copy(self, name: str, source: str | Path) -> Path:
        """A copy of the file ``source``."""
        path = self.file(name)
        shutil.copyfile(source, path)
        return path

    def grid(self) -> Path:
        """``spll_grid.py``: the model's grid rule (:mod:`spll_hw.model.grid`), by which a
        clocked export's user bins input spikes into steps."""
        return self.copy(GRID_FILE, model_grid.__file__)


def _json_number(value):
    if isinstance(value, np.integer | np.floating):
        return value.item()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")
