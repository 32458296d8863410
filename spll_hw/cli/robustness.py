"""``spll-hw robustness``: a tuned network's held-out figure with the training recordings, the
test recordings and the input scale varied (:mod:`spll_hw.harness.robustness`).

Example::

    spll-hw robustness --dataset biotac --data ../shared/datasets/biotac_slide_20_50 \\
        --recordings 1-40 --holdout-recordings 33-40 --train-recordings 1-24 \\
        --test-blocks 25-32 --encoders pacinian --network biotac-tuned-vary-offset-pacinian \\
        --reference biotac-vary-offset-pacinian --out reports/robust-pacinian
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .arguments import (
    THESIS_PHASE_NOISE,
    THESIS_REPEATS,
    add_backend_argument,
    add_dataset_arguments,
    add_jobs_argument,
    add_network_argument,
    add_noise_arguments,
    add_one_value_argument,
    split_list,
)
from .inputs import (
    checked_backend,
    command_line,
    jobs,
    parse_ranges,
    read_network_files,
    tuned_encoder_settings,
    tuned_input_level,
)

#: The command's line in ``spll-hw --help``.
HELP = "a tuned network's held-out figure and gain with recordings and input scale varied"
#: What ``spll-hw robustness --help`` says first.
DESCRIPTION = (
    "Score a tuned network and a reference network (same spike trains, ridge classifier "
    "trained on some recordings and tested once on others) with the training recordings, the "
    "test recordings and the input level varied, and report each accuracy and the paired "
    "tuned - reference change with 95 % CIs (bootstrap over the test recordings): whether the "
    "gain survives. Needs numbered recordings (--dataset biotac or folder) and "
    "--holdout-recordings, the baseline's test block."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_dataset_arguments(p)
    add_network_argument(
        p, "biotac-tuned-vary-offset-lif", layout=False,
        why="; the tuned network: its [encoder] table and input_level set the encoding",
    )  # fmt: skip
    r = p.add_argument_group("robustness")
    r.add_argument("--reference", default="biotac-vary-offset-lif", metavar="FILE|PRESET",
                   help="the network the tuned one is compared with (e.g. the thesis preset), "
                   "on the same spike trains")  # fmt: skip
    add_one_value_argument(r, "--encoders", "lif, pacinian or peak", default="lif")
    r.add_argument(
        "--train-recordings", action="append", default=[], metavar="A-B",
        help="a variation trained on these recordings only, tested on --holdout-recordings "
        "(repeatable, e.g. 1-24); the baseline trains on every loaded recording outside it",
    )  # fmt: skip
    r.add_argument(
        "--test-blocks", action="append", default=[], metavar="A-B",
        help="a variation tested on this block instead (repeatable, e.g. 25-32), trained on "
        "every other loaded recording",
    )  # fmt: skip
    r.add_argument("--level-factors", default="0.75,0.9,1.1,1.25",
                   help="the baseline again with the input level times each factor (comma "
                   "list; empty: none)")  # fmt: skip
    add_backend_argument(r)
    add_noise_arguments(r, THESIS_PHASE_NOISE, repeats=THESIS_REPEATS)
    r.add_argument("--seed", type=int, default=0, help="seed of the noise and the bootstrap")
    add_jobs_argument(r, "cores")
    r.add_argument("--quiet", action="store_true", help="no progress output")
    r.add_argument("--out", type=Path, default=Path("reports/robustness"), help="report folder")


def checked_variations(args: argparse.Namespace, loaded: list[int]):
    """The variations ``args`` ask for (:func:`~spll_hw.harness.robustness.standard_variations`)
    of the ``loaded`` recording numbers; ``ValueError`` naming the flag for a range that is not
    loaded, a training block that overlaps the test block, or a bad factor."""
    from ..datasets.recordings import format_numbers
    from ..harness.robustness import standard_variations

    test = parse_ranges(args.holdout_recordings)
    trains = [parse_ranges(t) for t in args.train_recordings]
    tests = [parse_ranges(t) for t in args.test_blocks]
    blocks = [("--holdout-recordings", test)] + [("--train-recordings", t) for t in trains]
    for flag, block in blocks + [("--test-blocks", t) for t in tests]:
        absent = sorted(set(block) - set(loaded))
        if absent:
            raise ValueError(f"{flag}: recording(s) {format_numbers(absent)} are not loaded "
                             f"(loaded: {format_numbers(loaded)})")  # fmt: skip
    for block in trains:
        if set(block) & set(test):
            raise ValueError(f"--train-recordings {format_numbers(block)} overlaps "
                             f"--holdout-recordings {args.holdout_recordings}")  # fmt: skip
    try:
        factors = [float(f) for f in split_list(args.level_factors)]
    except ValueError:
        raise ValueError(
            f"--level-factors {args.level_factors!r}: not a comma list of numbers"
        ) from None
    bad = [f for f in factors if not 0 < f < float("inf")]
    if bad:
        raise ValueError(f"--level-factors: every factor must be finite and > 0, got {bad}")
    return standard_variations(loaded, test, trains, tests, factors)


def run(args: argparse.Namespace) -> int:
    from ..datasets.recordings import recording_numbers
    from ..encoders import make_encoder
    from ..files import atomic_folder
    from ..harness.robustness import score_variations
    from ..harness.robustness_report import survives, table_lines, write_robustness_report
    from .inputs import load_samples

    say = (lambda line: None) if args.quiet else print
    if not args.holdout_recordings:
        raise ValueError("robustness needs --holdout-recordings A-B (the baseline's test block)")
    files = read_network_files(args.network, [args.encoder])
    reference = read_network_files(args.reference, [args.encoder])[args.encoder]
    tuned = tuned_encoder_settings(files, [args.encoder])
    encoder = make_encoder(args.encoder, **tuned.get(args.encoder, {}))
    level = tuned_input_level(files, [args.encoder])
    backend = checked_backend(args.backend)
    samples = load_samples(args)
    loaded = sorted(set(recording_numbers(samples, "robustness").tolist()))
    variations = checked_variations(args, loaded)
    say(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes, "
        f"{len(variations)} variations")  # fmt: skip
    rows = score_variations(
        samples, encoder, files[args.encoder].config.build(), reference.config.build(),
        variations, level, args.phase_noise, args.repeats, args.seed, backend, jobs(args), say,
    )  # fmt: skip
    names = {"tuned": args.network, "reference": args.reference}
    with atomic_folder(args.out) as stage:  # a full disk or Ctrl-C leaves no half a folder
        summary = write_robustness_report(rows, stage, names, command_line())
    say("\n".join(table_lines(rows)))
    say(f"gain survives every variation: {'yes' if survives(rows) else 'no'}")
    say(f"report: {args.out / summary.name}")
    return 0
