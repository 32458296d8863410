"""Ridge classifier with stratified 5-fold cross-validation."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.classify import combine, cross_validate


def _blobs(separation: float, n_per_class: int = 30, k: int = 3, seed: int = 0):
    rng = np.random.default_rng(seed)
    labels = np.repeat(np.arange(k), n_per_class)
    centres = rng.standard_normal((k, 10)) * separation
    return centres[labels] + rng.standard_normal((labels.size, 10)), labels


def test_separable_classes_are_classified_perfectly():
    x, y = _blobs(separation=20.0)
    r = cross_validate(x, y, ["a", "b", "c"])
    assert r.accuracy == 1.0 and r.accuracy_sd == 0.0
    assert len(r.fold_accuracies) == 5
    np.testing.assert_array_equal(r.confusion, np.diag([30, 30, 30]))
    np.testing.assert_allclose(r.confusion_normalized(), np.eye(3))


def test_uninformative_features_score_near_chance_and_folds_are_stratified():
    rng = np.random.default_rng(1)
    x = rng.standard_normal((200, 20))
    y = np.repeat(np.arange(4), 50)
    r = cross_validate(x, y)
    assert 0.1 < r.accuracy < 0.4
    assert r.confusion.sum() == 200
    np.testing.assert_array_equal(r.confusion.sum(axis=1), [50, 50, 50, 50])
    d = r.to_dict()
    assert d["class_names"] == ["0", "1", "2", "3"] and len(d["fold_accuracies"]) == 5


def test_scale_of_features_does_not_matter():
    x, y = _blobs(separation=1.0, seed=2)
    a = cross_validate(x, y)
    b = cross_validate(x * np.logspace(-3, 3, 10), y)
    assert a.fold_accuracies == pytest.approx(b.fold_accuracies)


def test_bad_features_and_small_classes_are_rejected():
    x, y = _blobs(separation=5.0)
    x[7, 3] = np.nan
    with pytest.raises(ValueError, match="sample 7, feature 3"):
        cross_validate(x, y)
    x, y = _blobs(separation=5.0)
    with pytest.raises(ValueError, match="fewer samples than the 5 CV folds"):
        cross_validate(x[:64], y[:64])  # class 2 keeps 4 samples
    with pytest.raises(ValueError, match="one label per row"):
        cross_validate(x, y[:-1])


def test_combine_pools_folds_and_confusions():
    x, y = _blobs(separation=0.8, seed=3)
    runs = [cross_validate(x, y, seed=s) for s in (0, 1)]
    pooled = combine(runs)
    assert len(pooled.fold_accuracies) == 10
    assert pooled.accuracy == pytest.approx(np.mean([r.accuracy for r in runs]))
    np.testing.assert_array_equal(pooled.confusion, runs[0].confusion + runs[1].confusion)
