"""Named sPLL networks shipped with spll-hw, one TOML file each in this folder.

A preset is an ordinary network file (the format of :mod:`spll_hw.config`): ``--network NAME``
and ``--network NAME`` read ``spll_hw/presets/NAME.toml``. The thesis's tuned networks are
``<dataset>-<layout>-<encoder>`` (Tables 6 and 7: ``biotac-vary-offset-lif``, ...).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: File name ending of a preset.
SUFFIX = ".toml"


def _folder():
    return resources.files(__name__)


def names() -> list[str]:
    """Every preset name, sorted."""
    return sorted(
        entry.name[: -len(SUFFIX)] for entry in _folder().iterdir() if entry.name.endswith(SUFFIX)
    )


def path(name: str) -> Path:
    """The file of preset ``name``; ``ValueError`` listing the presets when there is none."""
    if name not in names():
        raise ValueError(f"unknown sPLL network preset {name!r}; choose from {names()}")
    return Path(str(_folder().joinpath(name + SUFFIX)))


def is_preset(source: str | Path) -> bool:
    """Whether ``--network`` ``source`` names a preset rather than a TOML file (it neither ends
    in ``.toml`` nor is a file: a folder of the preset's name, such as an export's ``--out``
    beside it, does not hide the preset)."""
    text = str(source)
    return not text.endswith(SUFFIX) and not Path(text).is_file()
