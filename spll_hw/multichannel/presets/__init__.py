"""Multichannel networks shipped with spll-hw, one TOML file each in this folder (the format
of :mod:`spll_hw.multichannel.config`); ``--network NAME`` reads ``NAME.toml`` here."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from ...presets import SUFFIX, is_preset


def names() -> list[str]:
    """Every multichannel preset name, sorted."""
    folder = resources.files(__name__)
    return sorted(e.name[: -len(SUFFIX)] for e in folder.iterdir() if e.name.endswith(SUFFIX))


def path(name: str) -> Path:
    """The file of preset ``name``; ``ValueError`` listing the presets when there is none, and
    saying so where ``name`` is a folder (naming a multichannel file in it, if any)."""
    if name not in names():
        if Path(name).is_dir():
            inside = sorted(Path(name).glob("*" + SUFFIX))
            hint = f" (this one holds {', '.join(map(str, inside[:3]))})" if inside else ""
            raise ValueError(
                f"{name} is a folder, not a multichannel network: give a TOML file of "
                f"[[channel]] tables{hint} or a preset: {', '.join(names())}"
            )
        raise ValueError(f"unknown multichannel network preset {name!r}; choose from {names()}")
    return Path(str(resources.files(__name__).joinpath(name + SUFFIX)))


__all__ = ["is_preset", "names", "path"]
