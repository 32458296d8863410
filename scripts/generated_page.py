"""What ``scripts/cli_reference.py`` and ``scripts/doc_tables.py`` share: the command line of a
script that rewrites a generated page, or with ``--check`` only says whether it is stale."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path


def rewrite_or_check(doc: Path, description: str, rewrite: Callable[[str], str]) -> int:
    """Write ``rewrite(text)`` over the page ``doc`` (its text now), or with ``--check`` only
    say whether that differs: the exit status, 1 when stale, else 0."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--check", action="store_true", help="only say whether it is stale")
    args = parser.parse_args()
    text = doc.read_text()
    new = rewrite(text)
    if args.check:
        stale = new != text
        print(f"{doc}: {'stale' if stale else 'up to date'}")
        return int(stale)
    doc.write_text(new)
    print(f"wrote {doc}")
    return 0
