"""Paired statistics of accuracy differences between cells scored on the same folds.

Two feature sets scored on the **same** cross-validation folds (same labels, same fold seed) and
the same noise draws differ fold by fold; their difference is a paired sample. Folds overlap in
their training sets, so the fold differences are correlated and a plain t-interval is too
narrow. :func:`paired_ci` uses the corrected resampled t-test of Nadeau & Bengio (Machine
Learning 52, 2003): with ``J`` fold differences ``d_j`` (``R`` repeats of ``K`` folds), the
variance of their mean is ``(1/J + n_test/n_train) s²`` instead of ``s²/J``, and the interval uses
Student's t with ``J - 1`` degrees of freedom. For K-fold CV ``n_test/n_train = 1/(K-1)``.

Scores of one cell are stored draw-major: ``draws × folds``, where the draws are the phase-noise
draws (and, for an analog chip, the mismatch draws) and the folds are ``R × K`` in the order
scikit-learn's ``RepeatedStratifiedKFold`` yields them. :func:`fold_means` averages the draws, so
cells with different numbers of draws still pair fold by fold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

#: Default confidence level of every interval.
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """A mean with its confidence interval, in the unit of the data (fractions for accuracies).

    ``distinct`` says whether the interval excludes zero (a difference distinguishable from no
    difference at this confidence).
    """

    mean: float
    low: float
    high: float
    confidence: float = CONFIDENCE

    @property
    def distinct(self) -> bool:
        return bool(self.low > 0 or self.high < 0)

    @property
    def half_width(self) -> float:
        return 0.5 * (self.high - self.low)

    def to_dict(self) -> dict:
        return {"mean": self.mean, "low": self.low, "high": self.high, "distinct": self.distinct}


def fold_means(scores: np.ndarray | list, n_folds: int) -> np.ndarray:
    """Average a cell's ``draws × folds`` scores (flat, draw-major, length ``draws · n_folds``)
    over the draws: shape ``(n_folds,)``. ``ValueError`` when the length is not a multiple."""
    x = np.asarray(scores, dtype=float).ravel()
    if n_folds < 1 or x.size == 0 or x.size % n_folds:
        raise ValueError(f"{x.size} scores are not whole draws of {n_folds} folds")
    return x.reshape(-1, n_folds).mean(axis=0)


def corrected_t_interval(
    values: np.ndarray, test_over_train: float, confidence: float = CONFIDENCE
) -> Interval:
    """Mean of the fold values ``(J,)`` with the corrected resampled t interval (module
    docstring); ``test_over_train`` is ``n_test / n_train`` of one fold (``1/(K-1)``)."""
    x = np.asarray(values, dtype=float).ravel()
    if x.size < 2:
        raise ValueError(f"a confidence interval needs at least 2 folds, got {x.size}")
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    mean = float(x.mean())
    spread = float(x.var(ddof=1))
    se = np.sqrt((1.0 / x.size + test_over_train) * spread)
    t = float(stats.t.ppf(0.5 + confidence / 2, x.size - 1))
    return Interval(mean, mean - t * se, mean + t * se, confidence)


def paired_ci(
    scores: np.ndarray | list,
    reference: np.ndarray | list,
    n_folds: int,
    n_splits: int,
    confidence: float = CONFIDENCE,
) -> Interval:
    """Interval of ``mean(scores) - mean(reference)``, paired fold by fold.

    Args:
        scores, reference: draw-major scores of two cells on the same ``n_folds`` folds
            (``R`` repeats × ``n_splits`` folds), any number of draws each.
        n_folds: folds per draw (``R · n_splits``).
        n_splits: K of the K-fold CV (sets the training-set overlap correction).
    """
    if n_splits < 2:
        raise ValueError(f"n_splits must be >= 2, got {n_splits}")
    diff = fold_means(scores, n_folds) - fold_means(reference, n_folds)
    return corrected_t_interval(diff, 1.0 / (n_splits - 1), confidence)


def accuracy_ci(
    scores: np.ndarray | list, n_folds: int, n_splits: int, confidence: float = CONFIDENCE
) -> Interval:
    """Interval of one cell's mean accuracy over its folds (draws averaged first)."""
    if n_splits < 2:
        raise ValueError(f"n_splits must be >= 2, got {n_splits}")
    return corrected_t_interval(fold_means(scores, n_folds), 1.0 / (n_splits - 1), confidence)


def bootstrap_ci(
    correct: np.ndarray,
    groups: np.ndarray,
    n_boot: int = 2000,
    seed: int = 0,
    confidence: float = CONFIDENCE,
) -> Interval:
    """Accuracy on held-out data with a percentile bootstrap over **groups** (recordings):
    ``correct`` is ``(n,)`` (1 = right) or ``(n, m)`` for ``m`` paired quantities (e.g. a
    difference of two classifiers as ``correct_a - correct_b``), ``groups`` ``(n,)`` the
    recording of each test sample. Recordings are resampled with replacement, so samples of
    one recording stay together."""
    x = np.asarray(correct, dtype=float)
    g = np.asarray(groups)
    if x.shape[0] != g.shape[0] or x.shape[0] == 0:
        raise ValueError("need one group per test sample and at least one sample")
    keys, index = np.unique(g, return_inverse=True)
    sums = np.zeros(keys.size)
    np.add.at(sums, index, x if x.ndim == 1 else x.mean(axis=1))
    counts = np.bincount(index, minlength=keys.size).astype(float)
    rng = np.random.default_rng(seed)
    picks = rng.integers(0, keys.size, size=(n_boot, keys.size))
    boot = sums[picks].sum(axis=1) / counts[picks].sum(axis=1)
    tail = 50 * (1 - confidence)
    low, high = np.percentile(boot, [tail, 100 - tail])
    return Interval(float(sums.sum() / counts.sum()), float(low), float(high), confidence)
