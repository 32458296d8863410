"""Reading what the sub-commands are given: network files, datasets, spike files, recording
ranges, encoder settings, backend specs, chip profiles at their steps, the cores to use and the
command line itself. Every input file is read once; bad input raises ``ValueError`` naming the
flag or file (exit status 2). Only the commands' jobs (:mod:`spll_hw.cli.jobs`) import it: its
imports are the jobs' own, not ``--help``'s."""

from __future__ import annotations

import argparse
import dataclasses
import os
import shlex
import sys
from pathlib import Path

import numpy as np

from .. import backends, chips
from ..backends import backend_class, parse_spec
from ..config import read_network_file
from ..datasets import DEFAULT_SAMPLE_DURATION, load_biotac, load_folder_dataset
from ..datasets.biotac import BIOTAC_ENV
from ..datasets.recordings import check_folds, parse_ranges, split_recordings
from ..datasets.synthetic import SYNTHETIC_DURATION, make_synthetic
from ..encoders import parse_setting
from ..multichannel import presets
from ..params import read_toml
from ..timestep import at_steps, parse_ladder


def read_network(args: argparse.Namespace):
    """The :class:`~spll_hw.config.NetworkFile` of ``--network``, read once, with ``--layouts``
    (where the command has it) applied to its configuration."""
    network = read_network_file(args.network)
    layout = getattr(args, "layout", None)
    if layout:
        network = dataclasses.replace(network, config=network.config.with_layout(layout))
    return network


def is_multichannel(source: str | Path | None) -> bool:
    """Whether ``--network``'s ``source`` is a multichannel network (a preset of
    :mod:`spll_hw.multichannel.presets`, or a TOML file of ``[[channel]]`` tables, or a folder
    holding one) rather than one sPLL network; a source that cannot be read is left to the
    reader that names why."""
    if source is None:
        return False
    if str(source) in presets.names():
        return True
    path = Path(source)
    if path.is_dir():  # refused by the reader of the kind it holds, which names the file inside
        return any(is_multichannel(file) for file in sorted(path.glob("*.toml")))
    if not path.is_file():
        return False
    try:
        return "channel" in read_toml(path, "network file")
    except ValueError:
        return False


def read_network_files(template: str, names: list[str]) -> dict:
    """``{name: NetworkFile}``: the network file or preset of each encoder of ``names``,
    ``template`` with ``{encoder}`` replaced by its name; each distinct file read once."""
    read: dict = {}
    for name in names:
        source = template.replace("{encoder}", name)
        if source not in read:
            read[source] = read_network_file(source)
    return {name: read[template.replace("{encoder}", name)] for name in names}


def read_spike_file(path: Path) -> np.ndarray:
    """Spike times [s] from ``.npy`` (1-D array) or text/CSV (one time per line or comma list)."""
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such spike file")
    if path.suffix == ".npy":
        try:
            times = np.load(path, allow_pickle=False)
        except (ValueError, EOFError, OSError) as exc:
            raise ValueError(f"{path}: not a readable .npy array of spike times: {exc}") from exc
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


def expand_specs(specs: list[str], dts: list[float]) -> list[str]:
    """Give every spec of a clocked backend (one with a ``dt`` option) that sets no ``dt`` one
    spec per time step [s] of ``dts``: its work-precision curve."""
    out = []
    for spec in specs:
        name, options = parse_spec(spec)
        if "dt" in backend_class(name).OPTIONS and "dt" not in options:
            out += [f"{spec}:dt={dt:g}" for dt in dts]
        else:
            out.append(spec)
    return out


def encoder_overrides(settings: list[str], names: list[str]) -> dict[str, dict]:
    """Parse ``--set enc.param=value`` options into per-encoder keyword arguments."""
    out: dict[str, dict] = {n: {} for n in names}
    for item in settings:
        key, sep, value = item.partition("=")
        enc, dot, param = key.strip().partition(".")
        if not sep or not dot:
            raise ValueError(f"--set {item!r}: expected ENCODER.PARAM=VALUE, e.g. lif.gain=3000")
        try:
            out.setdefault(enc, {})[param] = parse_setting(enc, param, value)
        except ValueError as exc:
            raise ValueError(f"--set {item!r}: {exc}") from None
    return out


def tuned_encoder_settings(files: dict, names: list[str]) -> dict[str, dict]:
    """Encoder settings from the ``[encoder]`` tables of the network files ``files`` gives
    the encoders of ``names`` (``{name: NetworkFile}``, read once by the caller; an encoder
    without a file keeps its own settings): ``{name: settings}`` for the files tuned on that
    encoder; a file tuned on another encoder is noted on stderr."""
    out = {}
    for name in names:
        network = files.get(name)
        if network is None or network.encoder is None:
            continue
        tuned_on, settings = network.encoder
        if tuned_on == name:
            out[name] = settings
            print(f"{name}: encoder settings from {network.source} [encoder]", file=sys.stderr)
        else:
            print(
                f"note: {network.source} was tuned on {tuned_on} spike trains; {name} keeps its "
                "own settings",
                file=sys.stderr,
            )
    return out


def tuned_input_level(files: dict, names: list[str]) -> float | None:
    """The ``input_level`` of the network files ``files`` gives the encoders of ``names``
    (``{name: NetworkFile}``), from the files tuned on that encoder (the level belongs to the
    encoder's settings); ``None`` when none has one. ``ValueError`` when two disagree: one
    run divides every signal by one level."""
    levels = {
        network.source: network.input_level
        for name in names
        if (network := files.get(name)) is not None and network.input_level is not None
        and network.encoder is not None and network.encoder[0] == name
    }  # fmt: skip
    if len(set(levels.values())) > 1:
        raise ValueError(
            "the network files were tuned at different input levels ("
            + ", ".join(f"{source}: {level:g}" for source, level in levels.items())
            + "); evaluate them in separate runs"
        )
    return next(iter(levels.values()), None)


def load_samples(args: argparse.Namespace):
    """The :class:`~spll_hw.datasets.SampleSet` the dataset options select
    (:func:`spll_hw.cli.arguments.add_dataset_arguments`)."""
    progress = not args.quiet
    duration = args.duration
    if duration is None:
        duration = SYNTHETIC_DURATION if args.dataset == "synthetic" else DEFAULT_SAMPLE_DURATION
    recordings = parse_ranges(args.recordings) if args.recordings else None
    if args.dataset == "synthetic":
        if recordings is not None:
            raise ValueError("--recordings needs --dataset biotac or folder (numbered recordings)")
        samples = make_synthetic(
            args.synthetic_classes, args.synthetic_samples, duration, seed=args.seed
        )
    elif args.dataset == "biotac":
        root = args.data or os.environ.get(BIOTAC_ENV)
        if not root:
            raise ValueError(f"--dataset biotac needs --data PATH (or ${BIOTAC_ENV})")
        samples = load_biotac(root, args.classes or "thesis11", recordings, duration, progress)
    else:
        if not args.data:
            raise ValueError("--dataset folder needs --data PATH")
        classes = [c.strip() for c in args.classes.split(",")] if args.classes else None
        try:
            samples = load_folder_dataset(args.data, args.fs, classes, duration=duration,
                                          progress=progress, recordings=recordings)  # fmt: skip
        except ValueError as exc:
            if recordings is None or "no recording(s)" not in str(exc):
                raise
            raise ValueError(f"--recordings {args.recordings}: {exc}") from None
    if args.per_class:
        samples = samples.per_class(args.per_class, args.seed)
    return samples


def held_out_numbers(args: argparse.Namespace) -> list[int] | None:
    """The recording numbers of ``--holdout-recordings`` (``None`` when not given);
    ``ValueError`` for a dataset without numbered recordings (synthetic)."""
    if not getattr(args, "holdout_recordings", None):
        return None
    if args.dataset == "synthetic":
        raise ValueError(
            "--holdout-recordings needs --dataset biotac or folder (numbered recordings)"
        )
    return parse_ranges(args.holdout_recordings)


def load_split(args: argparse.Namespace):
    """``(training samples, held-out samples or None)``: :func:`load_samples` split by
    ``--holdout-recordings`` (recording numbers, :mod:`spll_hw.datasets.recordings`; refused
    for the synthetic textures and when one of them is not loaded); with ``--cv recordings``
    (where the command has it) checked to have a recording of every class per fold."""
    held = held_out_numbers(args)
    samples = load_samples(args)
    if held is None:
        if getattr(args, "cv", None) == "recordings":
            check_folds(samples, args.folds, f"--cv recordings --folds {args.folds}")
        return samples, None
    return split_recordings(samples, held, f"--holdout-recordings {args.holdout_recordings}")


def stepped_profiles(profiles: list[str], steps: str | None) -> list[str]:
    """``profiles`` with each clocked one at every step of the ladder ``steps``
    (:func:`spll_hw.timestep.parse_ladder`; ``None`` or ``"none"``: as they are);
    ``ValueError`` for an unknown profile or a bad step."""
    if steps is None or steps.strip().lower() == "none":
        return profiles
    ladder = parse_ladder(steps)
    clocked = [p != "none" and chips.describe(p).clocked for p in profiles]
    return at_steps(profiles, clocked, ladder)


def jobs(args: argparse.Namespace) -> int:
    """``--jobs``, every core when not given, at least 1."""
    return max(1, args.jobs or os.cpu_count() or 1)


def command_line() -> str | None:
    """The command as typed (``spll-hw ...``, shell-quoted) for a report; ``None`` when run
    without arguments from Python."""
    if not sys.argv[1:]:
        return None
    return "spll-hw " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def checked_backend(spec: str) -> str:
    """``spec`` after checking it fully (name, options, availability): the canonical spec.
    ``ValueError`` (exit status 2) before any work when it is wrong."""
    return backends.get(spec).spec


def default_backends() -> str:
    """What ``compare`` and ``stability`` measure against golden when ``--backends`` is not
    given: the fixed-point reference of the default chip, and Brian2 (C++ standalone) where it
    is installed."""
    specs = ["golden", "golden-fixed-point"]
    if "brian2-cpp_standalone" in backends.available():
        specs.append("brian2-cpp_standalone")
    return ",".join(specs)
