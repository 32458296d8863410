"""``spll-hw robustness``: a tuned network's held-out figure with the training recordings, the
test recordings and the input scale varied (:mod:`spll_hw.harness.robustness`)."""

from __future__ import annotations

import argparse

from ...datasets.recordings import format_numbers, parse_ranges, recording_numbers
from ...encoders import make_encoder
from ...files import atomic_folder
from ...harness.robustness import score_variations, standard_variations
from ...harness.robustness_report import survives, table_lines, write_robustness_report
from ..arguments import split_list
from ..inputs import (
    checked_backend,
    command_line,
    jobs,
    load_samples,
    read_network_files,
    tuned_encoder_settings,
    tuned_input_level,
)


def checked_variations(args: argparse.Namespace, loaded: list[int]):
    """The variations ``args`` ask for (:func:`~spll_hw.harness.robustness.standard_variations`)
    of the ``loaded`` recording numbers; ``ValueError`` naming the flag for a range that is not
    loaded, a training block that overlaps the test block, or a bad factor."""
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
