"""Ridge classifier with stratified K-fold cross-validation (thesis 2.6).

Features are standardised (zero mean, unit variance per feature, fitted on the training folds
only) and fed to scikit-learn's ``RidgeClassifier`` (L2 penalty ``alpha``); the reported figure is
the mean ± sample standard deviation of the test accuracy over the ``n_splits`` stratified folds,
with the confusion matrix summed over the test folds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CVResult:
    """Cross-validated accuracy of one feature set.

    Attributes:
        fold_accuracies: test accuracy of every fold (of every repeat), fractions in [0, 1].
        confusion: counts, shape ``(k, k)``, rows true class, columns predicted, summed over folds.
        class_names: the ``k`` class names.
    """

    fold_accuracies: tuple[float, ...]
    confusion: np.ndarray
    class_names: tuple[str, ...]

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
        totals = self.confusion.sum(axis=1, keepdims=True)
        return np.divide(
            self.confusion, totals, out=np.zeros(self.confusion.shape), where=totals > 0
        )

    def to_dict(self) -> dict:
        return {
            "accuracy": self.accuracy,
            "accuracy_sd": self.accuracy_sd,
            "fold_accuracies": list(self.fold_accuracies),
            "confusion": self.confusion.tolist(),
            "class_names": list(self.class_names),
        }


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
) -> CVResult:
    """Stratified ``n_splits``-fold CV accuracy of a standardised ridge classifier.

    ``labels`` are integers ``0..k-1`` (``class_names[k]`` names class k). Folds are shuffled with
    ``seed``.
    """
    from sklearn.linear_model import RidgeClassifier
    from sklearn.model_selection import StratifiedKFold
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    x, y = check_features(features, labels, n_splits)
    k = int(y.max()) + 1
    names = tuple(class_names) if class_names is not None else tuple(str(i) for i in range(k))
    if len(names) < k:
        raise ValueError(f"{len(names)} class names for labels up to {k - 1}")
    confusion = np.zeros((len(names), len(names)), dtype=int)
    accuracies = []
    folds = StratifiedKFold(n_splits=n_splits, shuffle=True, random_state=seed)
    for train, test in folds.split(x, y):
        model = make_pipeline(StandardScaler(), RidgeClassifier(alpha=alpha))
        model.fit(x[train], y[train])
        predicted = model.predict(x[test])
        accuracies.append(float(np.mean(predicted == y[test])))
        np.add.at(confusion, (y[test], predicted), 1)
    return CVResult(tuple(accuracies), confusion, names)


def combine(results: Sequence[CVResult]) -> CVResult:
    """Pool repeats (phase-noise draws, thesis 2.9): all folds' accuracies, summed confusions."""
    if not results:
        raise ValueError("nothing to combine")
    return CVResult(
        tuple(a for r in results for a in r.fold_accuracies),
        np.sum([r.confusion for r in results], axis=0),
        results[0].class_names,
    )
