"""``spll-hw slide``: accuracy against time into the slide of a multichannel network on BioTac,
beside the single-channel pipeline and the published spiking baselines.

Examples::

    spll-hw slide --data ../shared/datasets/biotac_slide_20_50 --out reports/slide
    spll-hw slide --network my-multichannel.toml --windows 0.5,1,2 --train-recordings 1-32
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from .arguments import add_backend_argument, add_jobs_argument, split_list
from .inputs import BIOTAC_ENV, checked_backend, jobs, parse_ranges

#: The command's line in ``spll-hw --help``.
HELP = "BioTac accuracy against time into the slide: every channel through its own sPLL network"
#: What ``spll-hw slide --help`` says first.
DESCRIPTION = (
    "Decide the material from the first T seconds of each BioTac recording, for several T, with "
    "a multichannel network (every channel through its own encoder and sPLL network, TDE rates "
    "concatenated, ridge classifier) and the single-channel pipeline (pac only); trained on "
    "--train-recordings, scored once on --holdout-recordings, on the thesis's 11 materials and all "
    "20, with 95 % CIs by a bootstrap over test recordings. Writes summary.md, results.json and "
    "accuracy_over_time.png (the published SNN/LSTM/SVM curves of Taunyazov et al. beside)."
)
#: Default multichannel network (:mod:`spll_hw.multichannel.presets`).
DEFAULT_NETWORK = "biotac-multichannel-lif"
#: Default single-channel network (pac; its [encoder] table is its encoder).
DEFAULT_SINGLE = "biotac-tuned-time-scaled-lif"
#: Label of each class set -> :func:`spll_hw.datasets.biotac.resolve_classes` argument.
CLASS_SETS = {"thesis 11": "thesis11", "all 20": "all"}
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


def add_arguments(p: argparse.ArgumentParser) -> None:
    from ..multichannel import presets

    d = p.add_argument_group("data")
    d.add_argument("--data", help=f"BioTac_slide_20_50 folder (default ${BIOTAC_ENV})")
    d.add_argument(
        "--train-recordings",
        default="1-32",
        metavar="A-B",
        help="recording numbers the classifier trains on",
    )
    d.add_argument(
        "--holdout-recordings",
        dest="test_recordings",
        default="33-40",
        metavar="A-B",
        help="recording numbers it is scored on, once (never tune on them)",
    )
    d.add_argument(
        "--windows",
        default="0.25,0.5,1,2,4",
        metavar="SECONDS",
        help="comma list of decision times into the slide [s] (multiples of 10 ms)",
    )
    n = p.add_argument_group("networks")
    n.add_argument(
        "--network",
        default=DEFAULT_NETWORK,
        metavar="FILE|PRESET",
        help="multichannel network: a TOML file of [[channel]] tables "
        f"(spll_hw/multichannel/config.py) or a preset: {', '.join(presets.names())}",
    )
    n.add_argument(
        "--channels",
        metavar="LIST",
        help="keep only these channels of --network (an ablation): comma list of its channels, "
        "'electrodes' for ele1-ele19 (default: all of them)",
    )
    n.add_argument(
        "--single",
        default=DEFAULT_SINGLE,
        metavar="FILE|PRESET",
        help="the single-channel pipeline's network (pac; its [encoder], else LIF "
        "defaults); 'none' to leave it out",
    )
    add_backend_argument(n)
    n.add_argument(
        "--group-steps",
        metavar="CHANNEL=STEP,...",
        help="separate clocks: run the [[channel]] table holding CHANNEL on --backend's chip "
        "profile stepped every STEP (its own chip), e.g. pac=80us,ele1=640us with --backend "
        "golden-fixed-point:profile=loihi2; a step the chip cannot write the table's network at "
        "is refused, naming the steps that can (default: every table at the profile's own step)",
    )
    c = p.add_argument_group("classifier and run")
    c.add_argument("--alpha", type=float, default=1.0, help="ridge L2 penalty")
    c.add_argument(
        "--alpha-cv",
        action="store_true",
        help="choose the fixed windows' ridge penalty per window and class set among 0.1-1000 "
        "by 5-fold CV by recording on the training recordings (issue 60: +17 points at 0.5 "
        "and 1 s on recordings 25-32; --alpha stays the readout's)",
    )
    c.add_argument(
        "--readout",
        action="store_true",
        help="also decide while sliding: the multichannel network's ridge as integrate-and-fire "
        "readout neurons with winner-take-all, on causally encoded spikes of the longest window "
        "(accuracy against time to decision, float and --readout-bits integer weights; "
        "readout.png); the trained readouts go to OUT/readouts/SET-WIDTH.npz, which "
        "spll-hw export --network FILE --readout exports with the network",
    )
    c.add_argument(
        "--readout-train",
        choices=("prefixes", "end", "staged"),
        default="prefixes",
        help="what the readout's ridge trains on: the training recordings' rates over prefixes "
        "of several lengths (0.25, 0.5, 1, 2 s and the longest window; every score plus 1, so "
        "a membrane rises from the start: it decides early) or over the longest window only "
        "(best at the end, poor early); staged: five readouts that take turns (switched at "
        "0.5, 1, 2 and 3 s), each trained on its own stretch's prefixes, ridge alpha 100, integer "
        "weights scaled per channel and class (issue 60: early as prefixes and as good as the "
        "end training at the end; not yet exportable)",
    )
    c.add_argument(
        "--readout-bits",
        default="8,4",
        metavar="LIST",
        help="comma list of integer widths of the readout's weights and bias",
    )
    c.add_argument("--seed", type=int, default=0, help="seed of the bootstrap")
    add_jobs_argument(c, "encoder processes and engine threads")
    c.add_argument("--out", default=os.path.join("reports", "slide"), help="report folder")
    c.add_argument("--quiet", action="store_true", help="no progress bars")


#: The longest decision time ``--windows`` takes [s]: an hour, far beyond any recording.
LONGEST_WINDOW = 3600.0


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
    from ..datasets.biotac_channels import ELECTRODES

    out = []
    for item in split_list(text):
        out += ELECTRODES if item == "electrodes" else [item]
    if not out:
        raise ValueError("--channels: give at least one channel, e.g. pac,electrodes")
    return list(dict.fromkeys(out))


def run(args: argparse.Namespace) -> int:

    from ..datasets.biotac import material_name, resolve_classes
    from ..datasets.biotac_channels import CHANNELS, load_biotac_channels
    from ..datasets.recordings import format_numbers, split_recordings
    from ..files import atomic_folder, write_results, write_text
    from ..multichannel.clocks import parse_group_steps, with_group_backends
    from ..multichannel.config import MultichannelConfig
    from ..multichannel.readout import anytime_over_class_sets, training
    from ..multichannel.report import (
        PUBLISHED,
        PUBLISHED_SOURCE,
        change_table,
        markdown_table,
        plot_over_time,
        plot_readout,
        readout_table,
    )
    from ..multichannel.timecourse import accuracy_over_time
    from .inputs import command_line

    root = args.data or os.environ.get(BIOTAC_ENV)
    if not root:
        raise ValueError(f"spll-hw slide needs --data PATH (or ${BIOTAC_ENV})")
    times = windows(args.windows)
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
    class_sets = {
        label: [material_name(f) for f in resolve_classes(key)] for label, key in CLASS_SETS.items()
    }
    points = accuracy_over_time(
        train,
        test,
        networks,
        class_sets,
        times,
        "cv" if args.alpha_cv else args.alpha,
        args.seed,
        backend,
        jobs(args),
        not args.quiet,
    )
    anytime, trained = {}, None
    if args.readout:
        trained = anytime_over_class_sets(
            train, test, multichannel, class_sets, max(times), [None, *bits], args.alpha,
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


def save_readouts(folder: Path, trained, channels: tuple[str, ...]) -> list[Path]:
    """Write every trained readout of ``trained`` (:class:`~spll_hw.multichannel.readout.
    Anytime`) to ``folder/SET-WIDTH.npz`` (``SET``: the class set's label without spaces,
    ``WIDTH``: ``float`` or ``8-bit``), with ``channels`` and their input levels."""
    from ..multichannel.readout_file import SavedReadout, save_readout

    folder.mkdir()
    levels = np.array([trained.levels[c] for c in channels])
    return [
        save_readout(
            folder / f"{label.replace(' ', '')}-{width}.npz",
            SavedReadout(readout, channels, levels),
        )
        for label, widths in trained.readouts.items()
        for width, readout in widths.items()
    ]


def _backends(config, backend: str) -> dict[str, str]:
    """Which simulator each group of ``config`` ran on (``backend``: the run's)."""
    from ..multichannel.clocks import group_label

    return {group_label(g): g.backend or backend for g in config.groups}


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
    from ..multichannel.report import PUBLISHED_SOURCE
    from .inputs import command_line

    lines = [
        "# Accuracy against time into the slide (BioTac_slide_20_50)",
        "",
        f"Trained on recordings {args.train_recordings} ({len(train)} recordings), scored once on "
        f"{args.test_recordings} ({len(test)}); one decision per recording from its first T "
        "seconds; accuracy % [95 % CI, bootstrap over test recordings]. "
        f"Published rows: {PUBLISHED_SOURCE}.",
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
            + "; ".join(f"{g} on `{b}`" for g, b in _backends(v, backend).items())
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
