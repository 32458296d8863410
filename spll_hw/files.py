"""Output files written atomically: to a temporary file in the same folder, then renamed over
the target (``os.replace``), so an interrupted run (Ctrl-C, a crash) leaves the old file or the
new one, never half of one."""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` (same suffix, so writers that go by it still work) to
    write to; renamed to ``path`` when the block ends, removed when it raises."""
    path = Path(path)
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        yield temporary
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
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
    from .provenance import provenance

    write_json(path, {"provenance": provenance()} | payload)


def _json_default(value):
    """A numpy scalar or array as a JSON number or list (what ``json`` cannot write itself)."""
    import numpy as np

    if isinstance(value, np.integer | np.floating | np.bool_):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON: {type(value).__name__}")


def save_figure(fig, path: str | Path, **options) -> None:
    """``fig.savefig(path, **options)`` (a matplotlib figure), atomically."""
    with atomic_path(path) as temporary:
        fig.savefig(temporary, **options)
