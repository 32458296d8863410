"""Accuracy against time into the slide: a decision from the first ``T`` seconds of each
recording, for several ``T``, on held-out recordings.

Every recording counts once (its opening sample, :meth:`MultiChannelSet.openings`). For each
window ``T`` every channel's first ``T`` s are encoded and run through the channel's network
(:mod:`.windows`: the encoders and networks see only those ``T`` s; every channel and window
in one pool of processes), a ridge classifier trains
on the training recordings' features and decides once per held-out recording
(:func:`spll_hw.classify.holdout`; 95 % intervals by a bootstrap over held-out recordings).
Channel scales (:func:`.features.input_levels`) come from the training recordings' whole
samples, so they are the same at every ``T``. Every class set (e.g. the 20 materials and the
thesis's 11) trains its own classifier on the same features.

The ridge's penalty is ``alpha`` at every window, or (``alpha="cv"``, issue 60) chosen for each
window and class set among :data:`CV_ALPHAS` by 5-fold cross-validation grouped by recording on
the training recordings alone (:func:`cv_alpha`): short windows' rates are noisy and want a
stronger penalty (on recordings 1-24 scored on 25-32 it chose 100 at 0.5-2 s and 10 at 4 s,
+17 points at 0.5 and 1 s; docs/notes/2026-12-06-early-windows.md).

The features are every TDE's rate over the window, or (``parts`` > 1, issue 60) its rates in
each of ``parts`` equal stretches of the window's run (:func:`spll_hw.features.spll.part_rates`):
how the rates change within the window tells materials apart that the window's mean does not
(quarters with the CV alpha, chosen by 4-fold CV on recordings 1-32: +7 points at 0.5 and 1 s;
docs/notes/2026-12-08-window-parts.md).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..classify import HoldoutResult, cross_validate, holdout
from ..datasets.multichannel import MultiChannelSet
from .config import MultichannelConfig
from .features import FeatureCache, input_levels
from .windows import features_over_windows

#: Windows [s] of the issue: decisions after this much of the slide.
WINDOWS = (0.25, 0.5, 1.0, 2.0, 4.0)

#: The ridge penalties ``alpha="cv"`` chooses among.
CV_ALPHAS = (0.1, 1.0, 10.0, 100.0, 1000.0)


@dataclass(frozen=True)
class Point:
    """One network's held-out accuracy on one class set after ``window`` seconds."""

    network: str
    classes: str
    window: float
    result: HoldoutResult
    alpha: float | None = None

    def to_dict(self) -> dict:
        return {
            "network": self.network,
            "classes": self.classes,
            "window_s": self.window,
            "alpha": self.alpha,
            **self.result.accuracy_fields(),
            "test_recordings": int(np.unique(self.result.recordings).size),
            "confusion": self.result.confusion.tolist(),
        }


def accuracy_over_time(
    train: MultiChannelSet,
    test: MultiChannelSet,
    networks: Mapping[str, MultichannelConfig],
    class_sets: Mapping[str, Sequence[str]],
    windows: Sequence[float] = WINDOWS,
    alpha: float | str = 1.0,
    seed: int = 0,
    backend: str = "golden",
    jobs: int = 1,
    progress: bool = False,
    parts: int = 1,
) -> list[Point]:
    """Held-out accuracy of every network × class set × window (module docstring).

    Args:
        train, test: opening samples of the training and held-out recordings, every channel
            the networks use, all classes of ``class_sets``, at least ``max(windows)`` long.
        networks: label → multichannel network (a single-channel one for the baseline).
        class_sets: label → class names (of ``train.class_names``) to decide among.
        windows: decision times [s] into the slide.
        alpha: ridge L2 penalty, or ``"cv"``: chosen per window and class set
            (:func:`cv_alpha`, module docstring). seed: bootstrap seed.
        backend, jobs, progress: simulator spec, engine threads and encoder processes, bars.
        parts: the features are every TDE's rates in this many equal stretches of the window
            (1: over the whole window; module docstring).
    """
    if alpha != "cv" and not (isinstance(alpha, float | int) and alpha > 0):
        raise ValueError(f"ridge alpha must be a number > 0 or 'cv', got {alpha!r}")
    levels = {label: input_levels(config, train) for label, config in networks.items()}
    both = _joined(train, test)
    features = network_features(both, networks, levels, windows, backend, jobs, progress, parts)
    n_train = len(train)
    points = []
    for window in sorted(windows):
        for label in networks:
            x = features[label, window]
            for classes, names in class_sets.items():
                chosen = alpha
                if alpha == "cv":
                    tr, _, relabel = class_subset(train, test, names)
                    chosen = cv_alpha(x[:n_train][tr], relabel[train.labels[tr]],
                                      train.recordings[tr], seed)  # fmt: skip
                result = _decide(x, n_train, train, test, names, chosen, seed)
                points.append(Point(label, classes, window, result, float(chosen)))
    return points


def cv_alpha(x: np.ndarray, labels: np.ndarray, recordings: np.ndarray, seed: int = 0) -> float:
    """The penalty of :data:`CV_ALPHAS` whose ridge scores best in stratified cross-validation
    of ``x`` ``(n, d)``, ``labels`` ``(n,)`` with folds by recording (5 folds, fewer where a
    class has fewer recordings; the smaller alpha on a tie); ``ValueError`` when a class has
    a single recording."""
    per_class = min(np.unique(recordings[labels == k]).size for k in np.unique(labels))
    if per_class < 2:
        raise ValueError("alpha 'cv' needs at least 2 training recordings of every class")
    folds = min(5, per_class)
    scores = [
        cross_validate(x, labels, None, folds, a, seed, groups=recordings).accuracy
        for a in CV_ALPHAS
    ]
    return CV_ALPHAS[int(np.argmax(scores))]


def network_features(
    samples: MultiChannelSet,
    networks: Mapping[str, MultichannelConfig],
    levels: Mapping[str, dict[str, float]],
    windows: Sequence[float],
    backend: str = "golden",
    jobs: int = 1,
    progress: bool = False,
    parts: int = 1,
) -> dict[tuple[str, float], np.ndarray]:
    """``(label, window)`` → every channel's features of network ``label`` of ``networks`` over
    the first ``window`` s of ``samples``, shape ``(len(samples), parts * config.n_spll)`` (the
    rates in ``parts`` equal stretches of the window), each channel divided by
    ``levels[label][channel]``; a channel two networks run alike (same group key and level) is
    simulated once, every window in one pool (:func:`.windows.features_over_windows`)."""
    units = {
        (channel, group.key, levels[label][channel]): (channel, group, levels[label][channel])
        for label, config in networks.items()
        for group in config.groups
        for channel in group.channels
    }
    rates = features_over_windows(samples, list(units.values()), windows, backend, jobs, progress,
                                  parts=parts)  # fmt: skip
    out = {}
    for window in windows:
        cache = FeatureCache(lambda c, g, level, w=window: rates[w, c, g.key, level])
        for label, config in networks.items():
            out[label, window] = cache.features(config, levels[label])
    return out


def _joined(train: MultiChannelSet, test: MultiChannelSet) -> MultiChannelSet:
    """Training samples followed by the held-out ones, every channel (one simulation pass)."""
    return MultiChannelSet({n: s.joined(test.channel(n)) for n, s in train.channels.items()})


def _decide(
    x: np.ndarray,
    n_train: int,
    train: MultiChannelSet,
    test: MultiChannelSet,
    names: Sequence[str],
    alpha: float,
    seed: int,
) -> HoldoutResult:
    """Ridge trained on the rows ``[:n_train]`` of ``x`` of classes ``names``, scored on the
    held-out rows of those classes."""
    tr, te, relabel = class_subset(train, test, names)
    return holdout(
        x[:n_train][tr], relabel[train.labels[tr]], x[n_train:][te], relabel[test.labels[te]],
        test.recordings[te], tuple(names), alpha, seed,
    )  # fmt: skip


def class_subset(
    train: MultiChannelSet, test: MultiChannelSet, names: Sequence[str]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The training and held-out samples of classes ``names`` (boolean masks ``(n_train,)``,
    ``(n_test,)``) and the map from loaded class index to index in ``names`` (-1: not kept);
    ``ValueError`` for a class that is not loaded."""
    known = list(train.class_names)
    missing = [n for n in names if n not in known]
    if missing:
        raise ValueError(f"class(es) {missing} are not loaded; loaded: {known}")
    keep = np.array([known.index(n) for n in names])
    relabel = np.full(len(known), -1)
    relabel[keep] = np.arange(keep.size)
    return np.isin(train.labels, keep), np.isin(test.labels, keep), relabel
