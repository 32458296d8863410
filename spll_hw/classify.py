"""Ridge classifier with stratified K-fold cross-validation (thesis 2.6).

Features are standardised (zero mean, unit variance per feature, fitted on the training folds
only) and fed to scikit-learn's ``RidgeClassifier`` (L2 penalty ``alpha``); the reported figure is
the mean ± sample standard deviation of the test accuracy over the ``n_splits`` stratified folds
(repeated ``repeats`` times with fresh shuffles), with the confusion matrix summed over the test
folds. With ``groups`` (the recording of each sample) the folds keep every recording whole
(``StratifiedGroupKFold``), so no fold tests on a recording it trained on. Two feature sets
scored with the same labels, seed, repeats and groups get identical folds, so their fold
accuracies pair (:mod:`spll_hw.stats`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .stats import Interval, accuracy_ci, bootstrap_ci, paired_ci


@dataclass(frozen=True)
class CVResult:
    """Cross-validated accuracy of one feature set.

    Attributes:
        fold_accuracies: test accuracy of every fold, fractions in [0, 1], draw-major: for
            every pooled draw (:func:`combine`) its ``repeats × n_splits`` folds in order.
        confusion: counts, shape ``(k, k)``, rows true class, columns predicted, summed over folds.
        class_names: the ``k`` class names.
        n_splits: K of the K-fold CV.
        repeats: CV repeats per draw (fresh fold shuffles).
    """

    fold_accuracies: tuple[float, ...]
    confusion: np.ndarray
    class_names: tuple[str, ...]
    n_splits: int = 5
    repeats: int = 1

    @property
    def n_folds(self) -> int:
        """Folds per draw (``repeats · n_splits``)."""
        return self.repeats * self.n_splits

    def accuracy_ci(self) -> Interval:
        """95 % interval of the mean accuracy (corrected resampled t over the folds)."""
        return accuracy_ci(self.fold_accuracies, self.n_folds, self.n_splits)

    def change_against(self, reference: CVResult) -> Interval:
        """95 % interval of ``accuracy - reference.accuracy``, paired fold by fold (both must
        be scored on the same folds)."""
        if (reference.n_splits, reference.repeats) != (self.n_splits, self.repeats):
            raise ValueError("a paired change needs both results scored on the same folds")
        return paired_ci(self.fold_accuracies, reference.fold_accuracies, self.n_folds,
                         self.n_splits)  # fmt: skip

    @property
    def accuracy(self) -> float:
        """Mean test accuracy (fraction)."""
        return float(np.mean(self.fold_accuracies))

    @property
    def accuracy_sd(self) -> float:
        """Sample standard deviation of the fold accuracies (fraction)."""
        return float(np.std(self.fold_accuracies, ddof=1)) if len(self.fold_accuracies) > 1 else 0.0

    def confusion_normalized(self) -> np.ndarray:
        """Confusion matrix with each row divided by its total (rows sum to 1)."""
        return row_normalized(self.confusion)

    def to_dict(self) -> dict:
        return {
            "accuracy": self.accuracy,
            "accuracy_sd": self.accuracy_sd,
            "accuracy_ci": self.accuracy_ci().to_dict() if len(self.fold_accuracies) > 1 else None,
            "n_splits": self.n_splits,
            "repeats": self.repeats,
            "fold_accuracies": list(self.fold_accuracies),
            "confusion": self.confusion.tolist(),
            "class_names": list(self.class_names),
        }


def row_normalized(confusion: np.ndarray) -> np.ndarray:
    """A confusion matrix ``(k, k)`` with each row divided by its total (empty rows stay 0)."""
    totals = confusion.sum(axis=1, keepdims=True)
    return np.divide(confusion, totals, out=np.zeros(confusion.shape), where=totals > 0)


@dataclass(frozen=True)
class HoldoutResult:
    """Accuracy on held-out recordings: trained on the others, tested once on these.

    Attributes:
        correct: 1.0 where a test sample was classified right, shape ``(draws, n_test)`` (one
            row per pooled noise or mismatch draw, :func:`combine`).
        recordings: the recording of every test sample, shape ``(n_test,)``; intervals
            resample whole recordings (:func:`spll_hw.stats.bootstrap_ci`).
        confusion: counts, shape ``(k, k)``, summed over draws.
        class_names: the ``k`` class names.
        seed: seed of the bootstrap.
    """

    correct: np.ndarray
    recordings: np.ndarray
    confusion: np.ndarray
    class_names: tuple[str, ...]
    seed: int = 0

    @property
    def accuracy(self) -> float:
        return float(np.mean(self.correct))

    @property
    def accuracy_sd(self) -> float:
        """Standard deviation of the accuracy over draws (0 with one draw)."""
        per_draw = np.mean(self.correct, axis=1)
        return float(np.std(per_draw, ddof=1)) if per_draw.size > 1 else 0.0

    def accuracy_ci(self) -> Interval:
        """95 % bootstrap interval over test recordings."""
        return bootstrap_ci(self.correct.T, self.recordings, seed=self.seed)

    def change_against(self, reference: HoldoutResult) -> Interval:
        """95 % bootstrap interval of ``accuracy - reference.accuracy`` over test recordings,
        paired sample by sample (draws averaged per sample first)."""
        if not np.array_equal(reference.recordings, self.recordings):
            raise ValueError("a paired change needs both results tested on the same samples")
        diff = self.correct.mean(axis=0) - reference.correct.mean(axis=0)
        return bootstrap_ci(diff, self.recordings, seed=self.seed)

    @classmethod
    def of_predictions(
        cls,
        predicted: np.ndarray,
        labels: np.ndarray,
        recordings: np.ndarray,
        class_names: Sequence[str],
        seed: int = 0,
    ) -> HoldoutResult:
        """One draw's result from ``predicted`` and true ``labels`` (class indices, shape
        ``(m,)``) of test samples grouped by ``recordings`` ``(m,)``."""
        predicted, labels = np.asarray(predicted), np.asarray(labels)
        confusion = np.zeros((len(class_names), len(class_names)), dtype=int)
        np.add.at(confusion, (labels, predicted), 1)
        correct = (predicted == labels).astype(float)[None, :]
        return cls(correct, np.asarray(recordings), confusion, tuple(class_names), seed)

    def accuracy_fields(self) -> dict:
        """``accuracy`` and its 95 % interval's ``ci_low``, ``ci_high`` (fractions), for
        results.json rows."""
        interval = self.accuracy_ci()
        return {"accuracy": self.accuracy, "ci_low": interval.low, "ci_high": interval.high}

    def confusion_normalized(self) -> np.ndarray:
        return row_normalized(self.confusion)

    def to_dict(self) -> dict:
        return {
            "accuracy": self.accuracy,
            "accuracy_ci": self.accuracy_ci().to_dict(),
            "test_recordings": int(np.unique(self.recordings).size),
            "correct": self.correct.astype(int).tolist(),
            "confusion": self.confusion.tolist(),
            "class_names": list(self.class_names),
        }


def holdout(
    train: np.ndarray,
    train_labels: np.ndarray,
    test: np.ndarray,
    test_labels: np.ndarray,
    test_recordings: np.ndarray,
    class_names: Sequence[str],
    alpha: float = 1.0,
    seed: int = 0,
) -> HoldoutResult:
    """Fit the standardised ridge classifier on ``train`` ``(n, d)`` and score it on ``test``
    ``(m, d)`` (one draw); ``test_recordings`` ``(m,)`` group the test samples."""
    from sklearn.linear_model import RidgeClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    x, y = check_features(train, train_labels, 1)
    xt, yt = check_features(test, test_labels, 1)
    model = make_pipeline(StandardScaler(), RidgeClassifier(alpha=alpha)).fit(x, y)
    return HoldoutResult.of_predictions(model.predict(xt), yt, test_recordings, class_names, seed)


def check_features(
    features: np.ndarray, labels: np.ndarray, n_splits: int
) -> tuple[np.ndarray, np.ndarray]:
    """Check features ``(n, d)`` and labels ``(n,)``; ``ValueError`` says what is wrong."""
    x = np.asarray(features, dtype=float)
    y = np.asarray(labels)
    if x.ndim != 2 or x.shape[0] != y.shape[0]:
        raise ValueError(
            f"features must be (n_samples, n_features) with one label per row; "
            f"got {x.shape}, {y.shape}"
        )
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        i, j = bad[0]
        raise ValueError(f"feature matrix has NaN/inf (first at sample {i}, feature {j})")
    classes, counts = np.unique(y, return_counts=True)
    if classes.size < 2:
        raise ValueError("need at least two classes to classify")
    small = classes[counts < n_splits]
    if small.size:
        raise ValueError(
            f"class(es) {small.tolist()} have fewer samples than the {n_splits} CV folds "
            f"(counts {dict(zip(classes.tolist(), counts.tolist(), strict=True))})"
        )
    return x, y


def cross_validate(
    features: np.ndarray,
    labels: np.ndarray,
    class_names: Sequence[str] | None = None,
    n_splits: int = 5,
    alpha: float = 1.0,
    seed: int = 0,
    repeats: int = 1,
    groups: np.ndarray | None = None,
) -> CVResult:
    """Stratified ``n_splits``-fold CV accuracy of a standardised ridge classifier.

    ``labels`` are integers ``0..k-1`` (``class_names[k]`` names class k). Folds are shuffled with
    ``seed``, ``repeats`` times (repeat ``r`` with ``seed + r``); ``groups`` ``(n,)`` keeps the
    samples of one group (recording) in one fold.
    """
    from sklearn.linear_model import RidgeClassifier
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    x, y = check_features(features, labels, n_splits)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"CV repeats must be an integer >= 1, got {repeats!r}")
    k = int(y.max()) + 1
    names = tuple(class_names) if class_names is not None else tuple(str(i) for i in range(k))
    if len(names) < k:
        raise ValueError(f"{len(names)} class names for labels up to {k - 1}")
    confusion = np.zeros((len(names), len(names)), dtype=int)
    accuracies = []
    for train, test in fold_indices(y, n_splits, seed, repeats, groups):
        model = make_pipeline(StandardScaler(), RidgeClassifier(alpha=alpha))
        model.fit(x[train], y[train])
        predicted = model.predict(x[test])
        accuracies.append(float(np.mean(predicted == y[test])))
        np.add.at(confusion, (y[test], predicted), 1)
    return CVResult(tuple(accuracies), confusion, names, n_splits, repeats)


def fold_indices(
    labels: np.ndarray, n_splits: int, seed: int, repeats: int = 1, groups=None
) -> list[tuple[np.ndarray, np.ndarray]]:
    """The ``(train, test)`` index arrays of every fold, ``repeats × n_splits`` of them
    (module docstring); ``ValueError`` when a class has fewer groups than folds."""
    from sklearn.model_selection import StratifiedGroupKFold, StratifiedKFold

    y = np.asarray(labels)
    out = []
    for r in range(repeats):
        if groups is None:
            splitter = StratifiedKFold(n_splits=n_splits, shuffle=True, random_state=seed + r)
            out += list(splitter.split(y, y))
            continue
        g = np.asarray(groups)
        if g.shape != y.shape:
            raise ValueError(f"need one group per sample: {g.shape} groups, {y.shape} labels")
        for k in np.unique(y):
            n = np.unique(g[y == k]).size
            if n < n_splits:
                raise ValueError(
                    f"class {k} has {n} recording(s), fewer than the {n_splits} folds: "
                    "folds by recording need at least one recording per class and fold"
                )
        splitter = StratifiedGroupKFold(n_splits=n_splits, shuffle=True, random_state=seed + r)
        out += list(splitter.split(y, y, g))
    return out


def combine(results: Sequence[CVResult | HoldoutResult]) -> CVResult | HoldoutResult:
    """Pool repeats (phase-noise draws, thesis 2.9): all folds' accuracies (or all held-out
    draws), summed confusions."""
    if not results:
        raise ValueError("nothing to combine")
    first = results[0]
    if isinstance(first, HoldoutResult):
        return HoldoutResult(
            np.concatenate([r.correct for r in results]), first.recordings,
            np.sum([r.confusion for r in results], axis=0), first.class_names, first.seed,
        )  # fmt: skip
    if any((r.n_splits, r.repeats) != (first.n_splits, first.repeats) for r in results):
        raise ValueError("can only pool results of the same folds (n_splits and repeats)")
    return CVResult(
        tuple(a for r in results for a in r.fold_accuracies),
        np.sum([r.confusion for r in results], axis=0),
        first.class_names,
        first.n_splits,
        first.repeats,
    )
