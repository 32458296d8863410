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


#: Presets kept as network files although what they were tuned for is withdrawn: the note
#: that says so wherever they are offered (``--network``'s help, :func:`listing`).
WITHDRAWN = {
    "biotac-tuned-vary-offset-pacinian": "its tuned gain is withdrawn: it does not hold on "
    "other recordings, docs/tuning.md",
}


def listing() -> str:
    """Every preset name, comma-separated, each withdrawn one with its note (:data:`WITHDRAWN`)."""
    return ", ".join(
        f"{name} ({WITHDRAWN[name]})" if name in WITHDRAWN else name for name in names()
    )


#: Network files a folder may hold, as ``spll-hw`` writes them: an export's, a tuning study's.
FOLDER_FILES = ("params.toml", "best.toml")


def path(name: str) -> Path:
    """The file of preset ``name``; ``ValueError`` listing the presets when there is none,
    and saying so where ``name`` is a folder (naming the network file in it, if any)."""
    if name not in names():
        if Path(name).is_dir():
            inside = [Path(name) / f for f in FOLDER_FILES if (Path(name) / f).is_file()]
            hint = f" (this one holds {inside[0]})" if inside else ""
            raise ValueError(
                f"{name} is a folder, not a network: give a network TOML file{hint}, with "
                "[spll] and [network] tables as an export's params.toml or a tuning study's "
                f"best.toml, or a preset: {', '.join(names())}"
            )
        raise ValueError(f"unknown sPLL network preset {name!r}; choose from {names()}")
    return Path(str(_folder().joinpath(name + SUFFIX)))


def is_preset(source: str | Path) -> bool:
    """Whether ``--network`` ``source`` names a preset rather than a TOML file (it neither ends
    in ``.toml`` nor is a file: a folder of the preset's name, such as an export's ``--out``
    beside it, does not hide the preset)."""
    text = str(source)
    return not text.endswith(SUFFIX) and not Path(text).is_file()
