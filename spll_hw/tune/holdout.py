"""Honest scores: the study's networks tested on recordings the study never saw.

``spll-hw tune --holdout-recordings 33-40`` keeps those recordings (BioTac or folder) out of the
study entirely; it tunes on the others (``--per-class`` samples of them). At the end every network
to report (the best one, the chosen points of a Pareto front, the ``--compare`` reference) is
trained on **every** sample of the tuning recordings and tested once on every held-out sample
(:func:`spll_hw.classify.holdout`), for each of the study's noise draws and chip draws (pooled),
with a 95 % interval by a bootstrap over the held-out recordings; two networks pair sample by
sample (:meth:`spll_hw.classify.HoldoutResult.change_against`).

The held-out spike trains get their own phase-noise seeds (``seed + 10000 + r``, as
``spll-hw report`` draws them), the training ones the study's (``seed + r``). Both sides are
scaled by the study samples' reference level, as the study's own samples were.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..classify import HoldoutResult, combine, holdout
from ..config import NetworkConfig
from ..datasets.recordings import format_numbers
from ..datasets.samples import SampleSet
from ..encoders import Encoder, train_duration
from ..pipeline import encode_samples, jitter
from .objective import Objective

#: Offset of the held-out samples' phase-noise seeds from the study's.
TEST_SEED_OFFSET = 10_000


def check_split(tuning: SampleSet, folds: int, flag: str = "--holdout-recordings") -> None:
    """``ValueError`` when a class keeps fewer recordings for the study than CV ``folds``."""
    recordings = tuning.recordings
    short = {}
    for k, name in enumerate(tuning.class_names):
        n = np.unique(recordings[tuning.labels == k]).size
        if n < folds:
            short[name] = n
    if short:
        raise ValueError(
            f"{flag} leaves class(es) {short} (recordings each) with fewer recordings to tune "
            f"on than the {folds} CV folds; hold out fewer recordings"
        )


@dataclass
class HoldoutData:
    """What the final scores train and test on.

    Attributes:
        train: every sample of the tuning recordings (scaled like the study's samples).
        test: every held-out sample (scaled the same way).
        encoder: the study's encoder (its fixed settings); a network's tuned encoder
            settings replace fields of it.
        tuned_on, tested_on: recording numbers of each side
            (:attr:`~spll_hw.datasets.SampleSet.numbers`).
        n_study: samples the study itself scored trials on.
    """

    train: SampleSet
    test: SampleSet
    encoder: Encoder
    tuned_on: tuple[int, ...]
    tested_on: tuple[int, ...]
    n_study: int
    _trains: dict = field(default_factory=dict, repr=False)

    @property
    def duration(self) -> float:
        """Length [s] of the spike trains (:func:`spll_hw.encoders.train_duration`)."""
        return train_duration(self.encoder, self.train.duration)

    def trains(self, encoder: Encoder) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Spike times [s] of the training and test samples encoded by ``encoder`` (cached)."""
        key = repr(dataclasses.asdict(encoder))
        if key not in self._trains:
            self._trains[key] = (
                encode_samples(encoder, self.train),
                encode_samples(encoder, self.test),
            )
        return self._trains[key]

    def describe(self) -> str:
        """One line: which recordings the study tuned on and which it was tested on."""
        return (
            f"tuned on recordings {format_numbers(self.tuned_on)} ({self.n_study} samples in "
            f"the study, {len(self.train)} on those recordings), tested on recordings "
            f"{format_numbers(self.tested_on)} ({len(self.test)} samples) it never saw"
        )

    def to_dict(self) -> dict:
        return {
            "tuned_on_recordings": list(self.tuned_on),
            "tested_on_recordings": list(self.tested_on),
            "study_samples": self.n_study,
            "train_samples": len(self.train),
            "test_samples": len(self.test),
        }


def holdout_score(
    objective: Objective,
    config: NetworkConfig,
    encoder: Encoder,
    data: HoldoutData,
    specs: Sequence[str] | None = None,
) -> HoldoutResult:
    """Train the ridge classifier on the features of ``config``'s network of every training
    sample and test it on every held-out one, for each noise draw and chip draw of
    ``objective``'s settings (module docstring); the draws pooled. ``specs`` replaces the
    study's backend specs (one per chip draw), e.g. ``("golden",)`` for the network off the
    chip."""
    s = objective.settings
    train, test = data.trains(encoder)
    window = data.duration
    every_train, every_test = np.arange(len(train)), np.arange(len(test))
    results = []
    for r in range(s.n_repeats):
        noisy_train = jitter(train, s.phase_noise, window, s.seed + r)
        noisy_test = jitter(test, s.phase_noise, window, s.seed + TEST_SEED_OFFSET + r)
        for spec in specs or objective.specs:
            x = objective.simulate(config, noisy_train, every_train, spec)[0]
            xt = objective.simulate(config, noisy_test, every_test, spec)[0]
            results.append(
                holdout(x, data.train.labels, xt, data.test.labels, data.test.recordings,
                        data.train.class_names, s.alpha, s.seed)
            )  # fmt: skip
    return combine(results)
