"""``spll-hw slide``: accuracy against time into the slide of a multichannel network on BioTac,
beside the single-channel pipeline and the published spiking baselines."""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from ... import backends
from ...datasets.biotac import BIOTAC_ENV, material_name, resolve_classes
from ...datasets.biotac_channels import (
    CHANNELS,
    ELECTRODES,
    LONGEST_WINDOW,
    load_biotac_channels,
)
from ...datasets.recordings import format_numbers, parse_ranges, split_recordings
from ...files import atomic_folder, write_results, write_text
from ...multichannel.anytime import READOUT_LOSS_LIMIT, anytime_over_class_sets, training
from ...multichannel.clocks import group_label, parse_group_steps, with_group_backends
from ...multichannel.config import MultichannelConfig
from ...multichannel.readout_file import SavedReadout, save_readout
from ...multichannel.report import (
    PUBLISHED,
    PUBLISHED_SOURCE,
    change_table,
    markdown_table,
    plot_over_time,
    plot_readout,
    readout_table,
)
from ...multichannel.timecourse import accuracy_over_time
from ..arguments import split_list
from ..inputs import checked_backend, command_line, jobs

#: Label of each class set -> :func:`spll_hw.datasets.biotac.resolve_classes` argument.
CLASS_SETS = {"thesis 11": "thesis11", "all 20": "all"}
#: The most parts ``--window-parts`` splits a window into.
MAX_WINDOW_PARTS = 16
#: Folder of the trained readouts in the report folder (``--readout``).
READOUTS = "readouts"
#: Label of the single-channel pipeline in the report.
SINGLE = "single-channel (pac)"
#: Label of the multichannel network on the golden model, beside it on another backend.
GOLDEN = "multichannel (golden)"
#: What the change against :data:`GOLDEN` is, in the report.
GOLDEN_CHANGE = (
    "The multichannel network on its backend minus the same network on the golden model "
    "(exact), accuracy points [95 % CI, paired bootstrap over test recordings]"
)


def class_sets() -> dict[str, list[str]]:
    """Label of each class set of :data:`CLASS_SETS` -> its material names."""
    return {label: [material_name(f) for f in resolve_classes(key)]
            for label, key in CLASS_SETS.items()}  # fmt: skip


def windows(text: str) -> list[float]:
    """The ``--windows`` list [s]; ``ValueError`` naming the flag for a bad entry."""
    out = []
    for item in split_list(text):
        try:
            value = float(item)
        except ValueError:
            raise ValueError(f"--windows: {item!r} is not a number of seconds") from None
        if not 0 < value <= LONGEST_WINDOW or abs(value * 100 - round(value * 100)) > 1e-6:
            raise ValueError(
                f"--windows: {item!r} must be a number of seconds in (0, "
                f"{LONGEST_WINDOW:g}], a multiple of 10 ms (one BioTac row)"
            )
        out.append(value)
    if not out:
        raise ValueError("--windows: give at least one decision time, e.g. 0.5,1,2")
    return sorted(set(out))


def readout_bits(text: str) -> list[int]:
    """The ``--readout-bits`` list; ``ValueError`` naming the flag for a bad entry."""
    out = []
    for item in split_list(text):
        if not item.isdigit() or not 2 <= int(item) <= 32:
            raise ValueError(f"--readout-bits: {item!r} is not an integer width in 2..32")
        out.append(int(item))
    return out


def channel_list(text: str) -> list[str]:
    """The ``--channels`` list, ``electrodes`` expanded to ``ele1`` ... ``ele19``."""
    out = []
    for item in split_list(text):
        out += ELECTRODES if item == "electrodes" else [item]
    if not out:
        raise ValueError("--channels: give at least one channel, e.g. pac,electrodes")
    return list(dict.fromkeys(out))


def run(args: argparse.Namespace) -> int:

    root = args.data or os.environ.get(BIOTAC_ENV)
    if not root:
        raise ValueError(f"spll-hw slide needs --data PATH (or ${BIOTAC_ENV})")
    times = windows(args.windows)
    if not 1 <= args.window_parts <= MAX_WINDOW_PARTS:
        raise ValueError(
            f"--window-parts: {args.window_parts} is not a number of parts in 1.."
            f"{MAX_WINDOW_PARTS} (e.g. 4: every TDE's rate in each quarter of the window)"
        )
    bits = readout_bits(args.readout_bits)
    train_numbers = parse_ranges(args.train_recordings)
    test_numbers = parse_ranges(args.test_recordings)
    shared = sorted(set(train_numbers) & set(test_numbers))
    if shared:
        raise ValueError(
            f"--holdout-recordings: recording(s) {format_numbers(shared)} are also "
            "training recordings (--train-recordings)"
        )
    multichannel = MultichannelConfig.load(args.network)
    if args.channels:
        try:
            multichannel = multichannel.only(channel_list(args.channels))
        except ValueError as exc:
            raise ValueError(f"--channels {args.channels}: {exc}") from None
    multichannel.check_channels(CHANNELS)
    backend = checked_backend(args.backend)
    networks = {"multichannel": multichannel}
    steps = parse_group_steps(args.group_steps, multichannel)
    if steps:
        networks["multichannel"] = with_group_backends(multichannel, backend, steps)
    if steps or backend != "golden":  # the paired change against the exact model
        networks[GOLDEN] = with_group_backends(multichannel, "golden", {})
    if args.single != "none":
        networks[SINGLE] = MultichannelConfig.single("pac", args.single)
    for config in networks.values():
        config.check_channels(CHANNELS)
    channels = list(dict.fromkeys(c for n in networks.values() for c in n.channels))
    start = time.perf_counter()
    loaded = load_biotac_channels(
        root, channels, "all", train_numbers + test_numbers, max(times), not args.quiet
    ).openings()
    train, test = split_recordings(loaded, test_numbers,
                                   f"--holdout-recordings {args.test_recordings}")  # fmt: skip
    sets = class_sets()
    points = accuracy_over_time(
        train,
        test,
        networks,
        sets,
        times,
        "cv" if args.alpha_cv else args.alpha,
        args.seed,
        backend,
        jobs(args),
        not args.quiet,
        args.window_parts,
    )
    anytime, trained = {}, None
    if args.readout:
        trained = anytime_over_class_sets(
            train, test, multichannel, sets, max(times), [None, *bits], args.alpha,
            args.seed, jobs(args), not args.quiet, args.readout_train,
        )  # fmt: skip
        anytime = trained.points
    seconds = time.perf_counter() - start
    prefixes = ", ".join(f"{t:g}" for t in training(args.readout_train, max(times))[0])
    table = markdown_table(points)
    if anytime:
        table += (
            "\n"
            + "\n".join(
                f"Spiking readout, {classes} classes (decisions from the first {max(times):g} s; "
                f"trained on the rates over the first {prefixes} s):"
                f"\n\n{readout_table(p)}"
                for classes, p in anytime.items()
            )
            + loss_lines(trained.losses)
            + "\n![spiking readout: accuracy against time to decision](readout.png)\n"
        )
    change = change_table(points, "multichannel", SINGLE)
    against_golden = change_table(points, "multichannel", GOLDEN)
    out = Path(args.out)
    with atomic_folder(out) as stage:
        plot_over_time(points, stage / "accuracy_over_time.png")
        if trained is not None:
            plot_readout(anytime, points, "multichannel", stage / "readout.png")
            save_readouts(stage / READOUTS, trained, multichannel.channels)
        write_text(
            stage / "summary.md",
            _summary(
                args, backend, networks, train, test, table, change, against_golden, seconds
            ),  # fmt: skip
        )
        write_results(
            stage / "results.json",
            {
                "command": command_line(),
                "backend": backend,
                "networks": {
                    k: {
                        "source": v.source,
                        "channels": list(v.channels),
                        "n_spll": v.n_spll,
                        "backends": _backends(v, backend),
                    }  # fmt: skip
                    for k, v in networks.items()
                },
                "train_recordings": train_numbers,
                "test_recordings": test_numbers,
                "n_train": len(train),
                "n_test": len(test),
                "wall_seconds": seconds,
                "points": [p.to_dict() for p in points],
                "readout": {k: [p.to_dict() for p in v] for k, v in anytime.items()},
                "window_parts": args.window_parts,
                "readout_train": args.readout_train if args.readout else None,
                "published": {
                    "source": PUBLISHED_SOURCE,
                    "accuracy": {
                        k: {str(w): a for w, a in v.items()} for k, v in PUBLISHED.items()
                    },
                },
            },
        )
    golden_note = f"\n{GOLDEN_CHANGE}:\n\n{against_golden}" if against_golden else ""
    print(table + change + golden_note, end="")
    print(f"{seconds:.0f} s; report: {out / 'summary.md'}")
    return 0


def loss_lines(losses: dict[str, dict[str, tuple[float, float]]]) -> str:
    """One Markdown line per class set and integer width: the accuracy points its weights lose
    against float on the training recordings, and whether ``spll-hw export`` takes them."""
    lines = [
        f"- {label}, {width} weights: {-loss:+.1f} points against float on the training "
        f"recordings (worst at {t:g} s): "
        + (
            "exported"
            if loss <= READOUT_LOSS_LIMIT
            else f"**export refuses them** (limit {READOUT_LOSS_LIMIT:g} points)"
        )
        for label, widths in losses.items()
        for width, (loss, t) in widths.items()
    ]
    return "\n".join(["", "Integer readouts, decided on the training recordings' rates:", "",
                       *lines, ""]) if lines else ""  # fmt: skip


def save_readouts(folder: Path, trained, channels: tuple[str, ...]) -> list[Path]:
    """Write every trained readout of ``trained`` (:class:`~spll_hw.multichannel.readout.
    Anytime`) to ``folder/SET-WIDTH.npz`` (``SET``: the class set's label without spaces,
    ``WIDTH``: ``float`` or ``8-bit``), with ``channels``, their input levels and each integer
    width's loss against float on the training runs."""
    folder.mkdir()
    levels = np.array([trained.levels[c] for c in channels])
    return [
        save_readout(
            folder / f"{label.replace(' ', '')}-{width}.npz",
            SavedReadout(readout, channels, levels, trained.losses.get(label, {}).get(width)),
        )
        for label, widths in trained.readouts.items()
        for width, readout in widths.items()
    ]


def _backends(config, backend: str) -> dict[str, str]:
    """Which simulator each group of ``config`` ran on (``backend``: the run's)."""
    return {group_label(g): g.backend or backend for g in config.groups}


def _classifier(args) -> str:
    """What the fixed windows' classifier reads and how it is penalised, in words."""
    features = (
        "every TDE's rate over the window"
        if args.window_parts == 1
        else f"every TDE's rate in each of the window's {args.window_parts} equal parts"
    )
    alpha = (
        "chosen per window and class set by CV on the training recordings"
        if args.alpha_cv
        else f"{args.alpha:g}"
    )
    return f"ridge on {features}, each feature standardised; penalty alpha {alpha}"


def _summary(
    args,
    backend: str,
    networks,
    train,
    test,
    table: str,
    change: str,
    against_golden: str,
    seconds: float,
) -> str:
    """The report's ``summary.md`` of a run on ``backend`` (the canonical spec of
    ``--backend``): the accuracy ``table``, the multichannel network's
    ``change`` against the single-channel pipeline and, on another backend than golden, its
    change ``against_golden`` (Markdown tables; either may be "")."""
    lines = [
        "# Accuracy against time into the slide (BioTac_slide_20_50)",
        "",
        f"Trained on recordings {args.train_recordings} ({len(train)} recordings), scored once on "
        f"{args.test_recordings} ({len(test)}); one decision per recording from its first T "
        "seconds; accuracy % [95 % CI, bootstrap over test recordings]. "
        f"Published rows: {PUBLISHED_SOURCE}.",
        "",
        f"Classifier: {_classifier(args)}.",
        "",
        table,
        *(
            [
                "Multichannel minus single-channel, accuracy points [95 % CI, paired "
                "bootstrap over test recordings]:",
                "",
                change,
            ]
            if change
            else []
        ),
        *(
            [
                f"{GOLDEN_CHANGE}:",
                "",
                against_golden,
            ]
            if against_golden
            else []
        ),
        "Networks (and the simulator of each [[channel]] table):",
        "",
        *[
            f"- {k}: {v.source}, channels {', '.join(v.channels)}, {v.n_spll} sPLLs; "
            + "; ".join(f"{g} on `{backends.label(b)}`" for g, b in _backends(v, backend).items())
            for k, v in networks.items()
        ],
        "",
        f"Wall time {seconds:.0f} s (loading, encoding, simulation, classifiers).",
        "",
        "![accuracy over time](accuracy_over_time.png)",
    ]
    if command_line():
        lines += ["", f"Command: `{command_line()}`"]
    return "\n".join(lines) + "\n"
