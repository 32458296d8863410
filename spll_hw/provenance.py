"""Where a result came from: the spll-hw version, the git commit of its source and the time,
recorded in every ``results.json`` (:func:`spll_hw.files.write_results`)."""

from __future__ import annotations

import subprocess
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as installed
from pathlib import Path


def version() -> str:
    """The installed spll-hw version (``"unknown (not installed)"`` in a source tree that was
    never installed)."""
    try:
        return installed("spll-hw")
    except PackageNotFoundError:
        return "unknown (not installed)"


def git_commit() -> str | None:
    """The commit (40 hex digits) of the git checkout this package is imported from: ``git
    rev-parse HEAD`` in its folder; ``None`` when that is no checkout or git is missing."""
    try:
        done = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent, capture_output=True,
            text=True, timeout=10, check=False,
        )  # fmt: skip
    except (OSError, subprocess.TimeoutExpired):
        return None
    commit = done.stdout.strip()
    return commit if done.returncode == 0 and commit else None


def provenance() -> dict:
    """``{"version", "git_commit", "utc_time"}``: the version, the commit (or ``None``) and the
    present UTC time in ISO 8601 (``2025-01-31T12:00:00+00:00``)."""
    return {
        "version": version(),
        "git_commit": git_commit(),
        "utc_time": datetime.now(UTC).isoformat(timespec="seconds"),
    }
