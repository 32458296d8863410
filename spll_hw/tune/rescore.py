"""Re-scoring a study's best trials on every sample (``spll-hw tune --rescore K``).

A study ranks its trials on the samples it was given (``--per-class``: 440 of 1701 BioTac samples),
so the ranking of the top trials carries that subset's sampling noise, on BioTac a few points,
more than the gap between them. :func:`rescore` scores each of the best ``K`` trials again, with
the study's settings (noise draws, folds, encoder) on a larger sample set.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from tqdm.auto import tqdm

from .objective import Objective


@dataclass(frozen=True)
class Rescored:
    """One trial scored on more samples.

    Attributes:
        trial: the study's (complete) trial.
        accuracies: mean CV accuracy (fraction) of every noise draw on all of the samples.
        n_samples: how many samples it was scored on.
    """

    trial: object
    accuracies: tuple[float, ...]
    n_samples: int

    @property
    def accuracy(self) -> float:
        """Mean over the noise draws (fraction), comparable to the study's objective."""
        return float(np.mean(self.accuracies))


def rescore(trials: Sequence, objective: Objective, progress: bool = False) -> list[Rescored]:
    """Score every trial's network (and encoder settings) with ``objective`` on all its samples;
    best first."""
    everything = np.arange(objective.labels.size)
    out = []
    for trial in tqdm(trials, desc="re-scoring", unit="trial", disable=not progress):
        config = objective.config(trial.params)
        accuracies = tuple(
            objective.score(objective.rates(config, draw, everything), everything)[0]
            for draw in objective.draws(trial.params)
        )
        out.append(Rescored(trial, accuracies, int(everything.size)))
    return sorted(out, key=lambda r: r.accuracy, reverse=True)
