"""Paired statistics of accuracy differences (spll_hw.stats) on planted data."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.linear_model import RidgeClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from spll_hw.classify import combine, cross_validate, fold_indices
from spll_hw.stats import accuracy_ci, bootstrap_ci, fold_means, paired_ci

#: Three Gaussian classes in 5 dimensions; "weak" features replace 2 informative ones by noise.
MEANS = np.random.default_rng(99).normal(0.0, 0.6, (3, 5))


def draw(n: int, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    y = rng.integers(0, 3, n)
    strong = MEANS[y] + rng.normal(0.0, 1.0, (n, 5))
    weak = strong.copy()
    weak[:, :2] = rng.normal(0.0, 1.0, (n, 2))
    return strong, weak, y


def accuracy(x, y, x_test, y_test) -> float:
    model = make_pipeline(StandardScaler(), RidgeClassifier()).fit(x, y)
    return float(np.mean(model.predict(x_test) == y_test))


def test_a_planted_loss_is_inside_the_paired_interval_at_the_nominal_rate():
    """The population loss of the weak features (trained on a fold's training size, tested on
    50 000 fresh samples) lies inside the 95 % interval for >= 85 % of 30 data sets; an
    uncorrected t interval would be far narrower."""
    rng = np.random.default_rng(0)
    n, k = 150, 5
    strong_test, weak_test, y_test = draw(50_000, rng)
    losses = []
    for _ in range(40):
        strong, weak, y = draw(n * (k - 1) // k, rng)
        losses.append(
            accuracy(weak, y, weak_test, y_test) - accuracy(strong, y, strong_test, y_test)
        )
    truth = float(np.mean(losses))
    assert truth < -0.03  # the weak features really lose
    inside, widths = 0, []
    for seed in range(30):
        strong, weak, y = draw(n, np.random.default_rng(1000 + seed))
        a = cross_validate(strong, y, n_splits=k, seed=seed, repeats=3)
        b = cross_validate(weak, y, n_splits=k, seed=seed, repeats=3)
        ci = paired_ci(b.fold_accuracies, a.fold_accuracies, a.n_folds, k)
        inside += ci.low <= truth <= ci.high
        widths.append(ci.half_width)
    assert inside / 30 >= 0.85, inside
    assert 0.01 < np.median(widths) < 0.15


def test_identical_cells_have_a_zero_interval_and_are_a_tie():
    scores = [0.5, 0.6, 0.7, 0.55, 0.65, 0.6]
    ci = paired_ci(scores, scores, 6, 3)
    assert (ci.mean, ci.low, ci.high, ci.distinct) == (0.0, 0.0, 0.0, False)


def test_draws_are_averaged_per_fold_so_cells_with_more_draws_still_pair():
    reference = [0.5, 0.6, 0.7, 0.8]  # one draw of 4 folds
    chip = [0.4, 0.5, 0.6, 0.7, 0.2, 0.3, 0.4, 0.5]  # two mismatch draws of the same folds
    np.testing.assert_allclose(fold_means(chip, 4), [0.3, 0.4, 0.5, 0.6])
    ci = paired_ci(chip, reference, 4, 4)
    assert ci.mean == pytest.approx(-0.2)
    assert ci.low == pytest.approx(-0.2) and ci.high == pytest.approx(-0.2)
    assert ci.distinct
    with pytest.raises(ValueError, match="whole draws of 4 folds"):
        fold_means(chip[:-1], 4)


def test_the_corrected_interval_is_wider_than_the_naive_one():
    from scipy import stats

    values = np.array([0.62, 0.58, 0.7, 0.55, 0.66, 0.61, 0.59, 0.68, 0.57, 0.64])
    ci = accuracy_ci(values, 10, 5)
    naive = stats.t.ppf(0.975, 9) * values.std(ddof=1) / np.sqrt(10)
    # (1/J + 1/(K-1)) / (1/J) = 1 + J/(K-1) = 3.5: the corrected half-width is sqrt(3.5) wider.
    assert ci.half_width == pytest.approx(naive * np.sqrt(3.5))


def test_folds_are_identical_for_every_cell_and_keep_recordings_whole():
    y = np.repeat([0, 1, 2], 12)
    groups = np.repeat(np.arange(18), 2)  # two samples per recording
    a = fold_indices(y, 3, seed=4, repeats=2, groups=groups)
    b = fold_indices(y, 3, seed=4, repeats=2, groups=groups)
    assert len(a) == 6
    for (train_a, test_a), (_, test_b) in zip(a, b, strict=True):
        np.testing.assert_array_equal(test_a, test_b)
        assert not set(groups[train_a]) & set(groups[test_a])  # no recording on both sides
    with pytest.raises(ValueError, match="class 0 has 2 recording"):
        fold_indices(y, 3, seed=0, groups=np.where(y == 0, np.arange(36) % 2, np.arange(36)))
    first, second = (cross_validate(np.c_[y + 0.1 * k, -y], y, n_splits=3, repeats=2)
                     for k in range(2))  # fmt: skip
    assert combine([first, second]).n_folds == 6
    with pytest.raises(ValueError, match="same folds"):
        combine([first, cross_validate(np.c_[y, -y], y, n_splits=3)])


def test_bootstrap_over_recordings():
    rng = np.random.default_rng(3)
    groups = np.repeat(np.arange(40), 5)
    # Each recording is right with its own probability: samples of a recording are correlated.
    p = rng.uniform(0.3, 0.9, 40)
    correct = (rng.uniform(size=200) < np.repeat(p, 5)).astype(float)
    ci = bootstrap_ci(correct, groups, seed=1)
    assert ci.low < correct.mean() < ci.high and ci.mean == pytest.approx(correct.mean())
    per_sample = bootstrap_ci(correct, np.arange(200), seed=1)
    assert ci.half_width > 0.8 * per_sample.half_width
    with pytest.raises(ValueError, match="one group per test sample"):
        bootstrap_ci(correct, groups[:-1])
