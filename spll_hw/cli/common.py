"""Arguments and helpers shared by several sub-commands."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

DEFAULT_PRESET = "vibtac-vary-offset-lif"


def add_params_argument(parser: argparse.ArgumentParser, default: str = DEFAULT_PRESET) -> None:
    from .. import presets

    parser.add_argument(
        "--params",
        default=default,
        metavar="FILE|PRESET",
        help="network TOML file ([spll] and [network] tables, see spll_hw/config.py) or a preset: "
        f"{', '.join(presets.names())} (default: {default})",
    )
    parser.add_argument(
        "--layout",
        help="override the file's layout: vary-offset, time-scaled or grouped:G",
    )


def add_backend_argument(parser: argparse.ArgumentParser, default: str = "golden") -> None:
    """``--backend SPEC``: the simulator of the sPLL network (``spll-hw backends`` lists them)."""
    from .. import backends

    parser.add_argument(
        "--backend",
        default=default,
        metavar="SPEC",
        help="simulator of the sPLL network: NAME[:key=value...], e.g. golden:profile=loihi2, "
        f"golden-fixed-point:profile=loihi2; backends: {', '.join(backends.names())} "
        f"(spll-hw backends says which run here; default: {default})",
    )


def checked_backend(spec: str) -> str:
    """``spec`` after checking it fully (name, options, availability): the canonical spec.
    ``ValueError`` (exit status 2) before any work when it is wrong."""
    from .. import backends

    return backends.get(spec).spec


def default_backends() -> str:
    """What ``compare`` and ``stability`` measure against golden when ``--backends`` is not
    given: the fixed-point reference of the default chip, and Brian2 (C++ standalone) where it
    is installed."""
    from .. import backends

    specs = ["golden", "golden-fixed-point"]
    if "brian2-cpp_standalone" in backends.available():
        specs.append("brian2-cpp_standalone")
    return ",".join(specs)


def load_network_config(args: argparse.Namespace):
    from ..config import NetworkConfig

    config = NetworkConfig.load(args.params)
    return config.with_layout(args.layout) if args.layout else config


def check_out_dir(path: str | Path, flag: str = "--out") -> Path:
    """``path`` if a report folder can be written there, checked before any work (nothing is
    created): ``ValueError`` naming ``flag`` when it, or the folder it would be made in, is a
    file or not writable."""
    import os

    path = Path(path)
    parent = path
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"{flag} {path}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} {path}: no permission to write in {parent}")
    return path


def read_spike_file(path: Path) -> np.ndarray:
    """Spike times [s] from ``.npy`` (1-D array) or text/CSV (one time per line or comma list)."""
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such spike file")
    if path.suffix == ".npy":
        times = np.load(path, allow_pickle=False)
    else:
        try:
            times = np.loadtxt(path, delimiter="," if path.suffix == ".csv" else None, ndmin=1)
        except ValueError as exc:
            raise ValueError(f"{path}: not a list of spike times: {exc}") from exc
    times = np.asarray(times, dtype=float)
    if times.ndim > 1 and sorted(times.shape)[-2] > 1:
        raise ValueError(
            f"{path}: a {times.shape} array; a spike file holds one train (a 1-D array, one "
            "column or one row of times in seconds)"
        )
    times = times.reshape(-1)
    bad = np.flatnonzero(~np.isfinite(times))
    if bad.size:
        raise ValueError(f"{path}: spike {bad[0]} is not a finite time ({times[bad[0]]})")
    return times
