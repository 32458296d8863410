"""Exports of a network for other toolchains, reached through a registry: the core never
imports the package that writes them.

An exporter is a function ``export(network, out, *, profile=None, dt=None) -> list[Path]``
that writes its files into folder ``out`` and returns them (``profile``: a chip profile for
exports with integer parameters; ``dt`` [s]: a time step for clocked exports; an exporter that
has no use for one raises ``ValueError`` when it is given). Exporters register in the
``spll_hw.exporters`` entry-point group (spll-hw's own in its ``pyproject.toml``); the first
paragraph of the function's docstring is its description in ``spll-hw export --help``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from importlib.metadata import entry_points
from pathlib import Path

#: Entry-point group exporters register in.
GROUP = "spll_hw.exporters"

Exporter = Callable[..., list[Path]]


@cache
def _entry_points() -> dict:
    return {ep.name: ep for ep in entry_points(group=GROUP)}


def names() -> list[str]:
    """Registered export targets, sorted."""
    return sorted(_entry_points())


def get(name: str) -> Exporter:
    """The exporter registered as ``name``; ``ValueError`` for an unknown one or one that does
    not load (a missing extra, say)."""
    eps = _entry_points()
    if name not in eps:
        raise ValueError(f"unknown export target {name!r}; known: {', '.join(names()) or 'none'}")
    try:
        return eps[name].load()
    except Exception as exc:  # a missing optional dependency is a message, not a traceback
        raise ValueError(
            f"export target {name!r} ({eps[name].value}) does not load: {type(exc).__name__}: {exc}"
        ) from exc


def describe(name: str) -> str:
    """One line on what target ``name`` writes (its exporter's docstring), without loading
    anything heavier than the exporter's module."""
    try:
        doc = get(name).__doc__ or ""
    except ValueError as exc:
        return str(exc)
    first = doc.strip().split("\n\n")[0]
    return " ".join(first.split()) or name
