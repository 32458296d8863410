"""The settings of a tuning study from ``spll-hw tune``'s options, checked before any work: its
backend and chip draws, its objective's settings, its storage and name, and what a stopped study
says; shared by a single network's study (:mod:`.tune`) and a multichannel file's
(:mod:`.tune_multichannel`)."""

from __future__ import annotations

import argparse
import os
import sys

from ...tune.chip import backend_profile, baseline_specs, check_spread, has_mismatch, study_backend
from ...tune.objective import ObjectiveSettings
from ...tune.storage import mask_url, storage_url
from ...tune.study import StudySettings
from ..arguments import TUNE_CHIP_DRAWS
from ..inputs import checked_backend


def chip_settings(args: argparse.Namespace) -> tuple[str, int]:
    """``(backend spec, chip draws)`` of ``--backend``, ``--profiles`` and ``--chip-draws``,
    checked (``ValueError`` before any work)."""
    backend = study_backend(checked_backend(args.backend), args.profile)
    profile = backend_profile(backend)
    draws = args.chip_draws
    if draws is None:
        draws = TUNE_CHIP_DRAWS if has_mismatch(profile) else 1
    elif profile is None:
        raise ValueError("--chip-draws needs a chip profile to draw: give --profiles (analog)")
    return backend, draws


def objective_settings(args: argparse.Namespace, space):
    """The :class:`~spll_hw.tune.objective.ObjectiveSettings` of ``args``, checked with the
    flags that depend on them (``ValueError`` before any work)."""
    backend, chip_draws = chip_settings(args)
    settings = ObjectiveSettings(
        layout=args.layout, n_spll=args.n_spll, reference_frequency=args.reference_frequency,
        repeats=args.repeats, phase_noise=args.phase_noise, folds=args.folds, alpha=args.alpha,
        seed=args.seed, prune_fraction=args.prune_fraction, constraints=args.constraints,
        backend=backend, chip_draws=chip_draws, objectives=args.objectives,
    )  # fmt: skip
    check_spread(space, settings)
    held_out_reference = args.compare and args.holdout_recordings and settings.profile
    for flag, given, does in (
        ("--attribute", args.attribute, "on the chip with one parameter kept exact at a time"),
        ("--compare-profile", args.compare_profile is not None, "on another chip profile"),
    ):
        if given and not held_out_reference:
            raise ValueError(
                f"{flag} scores the reference (--compare) {does} at the end: it needs --profiles "
                "(or a backend naming one), --compare and --holdout-recordings"
            )
    if args.compare_profile is not None:
        baseline_specs(settings.specs, args.compare_profile)  # fails before work
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    if args.rescore < 0 or (args.rescore and not args.per_class):
        raise ValueError(
            f"--rescore {args.rescore}: give K >= 1 trials to re-score on every sample of a study "
            "tuned on --per-class samples (0: off)"
        )
    if args.rescore and settings.multi_objective:
        raise ValueError("--rescore ranks by one objective; a multi-objective study has a front")
    return settings


def study_settings(args: argparse.Namespace, name: str):
    """``(StudySettings, report folder)`` of the study options, ``name`` the default study
    name (``--study`` replaces it)."""
    name = args.study or name
    out = args.out or os.path.join("reports", "tune", name)
    url = storage_url(args.storage, out)
    settings = StudySettings(
        url, name, args.trials, args.seed, args.pruner, args.startup_trials, args.sampler
    )
    return settings, out


def interrupted(url: str) -> int:
    """Say where a stopped study's trials are and how to continue; the exit status (130)."""
    print(
        f"interrupted: finished trials are stored in {mask_url(url)}; continue with the "
        "same command and --resume (--trials 0 --resume only writes the report)",
        file=sys.stderr,
    )
    return 130
