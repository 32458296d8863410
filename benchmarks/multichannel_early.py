"""Early windows (issue 60): can the multichannel network's fixed-window decision at 0.5, 1 and
2 s get better without losing 4 s? Every candidate is measured with the same per-window ridge
as :func:`spll_hw.multichannel.timecourse.accuracy_over_time` (one classifier trained per
window, features standardised per feature before the ridge), 20 materials, one decision per
recording (its opening sample).

Stages:

- ``choose``: recordings 1-32 only. Train on 1-24, score on 25-32, every candidate at 0.5, 1,
  2 and 4 s; tables of accuracy and of the change against the preset (paired bootstrap over
  the scored recordings). Recordings 33-40 are not loaded.
- ``test``: once, with the chosen candidate: train on 1-32, score on 33-40, beside the preset.

Candidates (all spike-derived features):

- ``preset``: ``biotac-multichannel-lif``, ridge alpha 1 (what ``spll-hw slide`` runs).
- ``alpha-cv``: the preset's features, the ridge's alpha chosen per window among 0.1-1000
  by 5-fold CV grouped by recording on the training recordings alone
  (:func:`spll_hw.multichannel.timecourse.cv_alpha`, what ``spll-hw slide --alpha-cv`` runs).
- ``+counts``: the preset's TDE rates plus every channel's encoder spike rate (23 features).
- ``rows-5-45``: the row channels' 16 sPLLs over 5-45 Hz instead of 2-45 Hz (pac unchanged).
- ``rows-tau20``: the row channels' LIF encoder with tau 20 ms instead of 50 ms.
- ``alpha-cv X``: candidate ``X``'s features with the alpha chosen by CV (round 2).

Round ``split`` (2026-12-08; what the 2026-12-06 note left untried): the preset's network and
encoders, one run per window as before, but every TDE's spikes counted in parts of the window:

- ``alpha-cv halves``: the rates in the window's first and second half (804 features);
- ``alpha-cv late``: the rates in its second half alone (402; the sPLLs' lock-in left out);
- ``alpha-cv quarters``: the rates in each quarter (1608).

Its rule, fixed before any of it was scored: on 4-fold CV over recordings 1-32 (folds 1-8,
9-16, 17-24, 25-32, the alpha chosen inside each training fold; 640 decisions per window) a
candidate is eligible when its mean accuracy over the four windows is at least 1 point above
``alpha-cv``'s and at no window more than 1 point below it; the eligible one with the largest
mean is chosen, else ``alpha-cv`` stays. The split 1-24 / 25-32 is printed beside it, as in
round 1, and decides nothing.

Run from the repository root (each stage some minutes on 2 shared cores; features are cached
under ``reports/early/``)::

    SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50 \\
        nice -n 10 python3 benchmarks/multichannel_early.py choose --jobs 2
    SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50 \\
        nice -n 10 python3 benchmarks/multichannel_early.py test --choice alpha-cv --jobs 2
    # round split: choose on 1-32, then test the choice once
    SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50 \\
        nice -n 10 python3 benchmarks/multichannel_early.py choose --round split --jobs 2
"""

from __future__ import annotations

import argparse
import os
import pickle
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from spll_hw.classify import HoldoutResult, holdout
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.datasets.multichannel import MultiChannelSet
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import channel_trains, input_levels
from spll_hw.multichannel.report import change_table, markdown_table
from spll_hw.multichannel.timecourse import Point, cv_alpha, network_features

WINDOWS = (0.5, 1.0, 2.0, 4.0)
CLASSES = "all 20"
#: Round ``split``: candidate -> the window's quarters each of its rates counts (module
#: docstring).
SPLITS = {"halves": ((0, 1), (2, 3)), "late": ((2, 3),), "quarters": ((0,), (1,), (2,), (3,))}
#: Round ``split``'s folds: recordings ``lo``-``hi`` of each.
FOLDS = ((1, 8), (9, 16), (17, 24), (25, 32))


def networks() -> dict[str, MultichannelConfig]:
    """Label -> network of every candidate that needs its own simulation."""
    preset = MultichannelConfig.load("biotac-multichannel-lif")
    pac, rows = preset.groups
    faster = replace(rows, network=replace(rows.network, f_start=5.0))
    tau20 = replace(rows, encoder=("lif", rows.encoder[1] | {"tau": 0.02}))
    return {
        "preset": preset,
        "rows-5-45": replace(preset, groups=(pac, faster)),
        "rows-tau20": replace(preset, groups=(pac, tau20)),
    }


def spike_rates(samples, config, levels, window, jobs) -> np.ndarray:
    """Every channel's encoder spike rate [spikes/s] over the first ``window`` s, shape
    ``(n, channels)``."""
    part = samples.first(window)
    cols = []
    for group in config.groups:
        for channel in group.channels:
            trains, duration = channel_trains(part, channel, group, levels[channel], jobs)
            cols.append([t.size / duration for t in trains])
    return np.array(cols).T


def features(
    samples: MultiChannelSet, n_train: int, jobs: int, cache: Path, wanted: list[str]
) -> dict:
    """``(candidate, window) -> features (n, d)`` of the candidates ``wanted`` (and the
    preset); levels from the first ``n_train`` samples (the training recordings)."""
    if cache.exists():
        return pickle.loads(cache.read_bytes())
    train = samples.subset(np.arange(n_train))
    nets = {k: v for k, v in networks().items() if k == "preset" or k in wanted}
    levels = {label: input_levels(config, train) for label, config in nets.items()}
    start = time.time()
    out = network_features(samples, nets, levels, WINDOWS, "golden", jobs, True)
    print(f"simulated in {time.time() - start:.0f} s wall", flush=True)
    for w in WINDOWS:
        counts = spike_rates(samples, nets["preset"], levels["preset"], w, jobs)
        out["+counts", w] = np.concatenate([out["preset", w], counts], axis=1)
        out["alpha-cv", w] = out["preset", w]
    cache.parent.mkdir(parents=True, exist_ok=True)
    cache.write_bytes(pickle.dumps(out))
    return out


def regrouped(x: np.ndarray, sizes: list[int], parts) -> np.ndarray:
    """The rates ``x`` ``(n, 4 * sum(sizes))`` of every channel's quarters (channel after
    channel, each ``(4, size)`` stretch-major, :func:`spll_hw.features.spll.part_rates`) as
    the mean rate over each group of quarters of ``parts``, channel after channel."""
    out, start = [], 0
    for size in sizes:
        block = x[:, start : start + 4 * size].reshape(len(x), 4, size)
        out += [block[:, list(q)].mean(axis=1) for q in parts]
        start += 4 * size
    return np.concatenate(out, axis=1)


def split_features(samples: MultiChannelSet, n_train: int, jobs: int, cache: Path) -> dict:
    """``(candidate, window) -> features`` of round ``split`` and of the preset; levels from
    the first ``n_train`` samples."""
    if cache.exists():
        return pickle.loads(cache.read_bytes())
    preset = MultichannelConfig.load("biotac-multichannel-lif")
    levels = input_levels(preset, samples.subset(np.arange(n_train)))
    start = time.time()
    quarters = network_features(samples, {"preset": preset}, {"preset": levels}, WINDOWS,
                                "golden", jobs, True, parts=4)  # fmt: skip
    print(f"simulated in {time.time() - start:.0f} s wall", flush=True)
    sizes = [g.network.n for g in preset.groups for _ in g.channels]
    out = {}
    for w in WINDOWS:
        out["preset", w] = out["alpha-cv", w] = regrouped(quarters["preset", w], sizes, [range(4)])
        for label, parts in SPLITS.items():
            out[label, w] = regrouped(quarters["preset", w], sizes, parts)
    cache.parent.mkdir(parents=True, exist_ok=True)
    cache.write_bytes(pickle.dumps(out))
    return out


def fold_cv(feats, candidates, samples: MultiChannelSet) -> list[Point]:
    """Round ``split``'s 4-fold CV over :data:`FOLDS` (alpha by CV inside each training fold),
    every fold's decisions pooled into one result per candidate and window."""
    numbers, labels, recs = samples.numbers, samples.labels, samples.recordings
    points = []
    for label in candidates:
        for w in WINDOWS:
            x, parts = feats[base(label), w], []
            for lo, hi in FOLDS:
                test = (numbers >= lo) & (numbers <= hi)
                tr = ~test
                alpha = cv_alpha(x[tr], labels[tr], recs[tr])
                parts.append(holdout(x[tr], labels[tr], x[test], labels[test], recs[test],
                                     samples.class_names, alpha, 0))  # fmt: skip
            pooled = HoldoutResult(
                np.concatenate([r.correct for r in parts], axis=1),
                np.concatenate([r.recordings for r in parts]),
                sum(r.confusion for r in parts), parts[0].class_names,
            )  # fmt: skip
            points.append(Point(label, CLASSES, w, pooled))
    return points


def split_rule(points: list[Point], candidates: list[str]) -> str:
    """Round ``split``'s choice by its rule (module docstring) on the CV ``points``."""
    acc = {(p.network, p.window): 100 * p.result.accuracy for p in points}
    mean = {c: np.mean([acc[c, w] for w in WINDOWS]) for c in candidates}
    eligible = [
        c for c in candidates[1:]
        if mean[c] >= mean["alpha-cv"] + 1
        and all(acc[c, w] >= acc["alpha-cv", w] - 1 for w in WINDOWS)
    ]  # fmt: skip
    for c in candidates:
        print(f"{c}: mean over the windows {mean[c]:.2f} %")
    return max(eligible, key=mean.get) if eligible else "alpha-cv"


def base(label: str) -> str:
    """The features a candidate uses: its label less a leading ``alpha-cv`` (the preset's for
    ``alpha-cv`` alone)."""
    rest = label.removeprefix("alpha-cv").strip()
    return rest or "preset"


def score(feats, candidates, train, test, n_train) -> list[Point]:
    points = []
    for label in candidates:
        for w in WINDOWS:
            x = feats[base(label), w]
            alpha = 1.0
            if label.startswith("alpha-cv"):
                alpha = cv_alpha(x[:n_train], train.labels, train.recordings)
                print(f"{label} at {w:g} s: alpha {alpha:g} (CV on the training recordings)")
            result = holdout(x[:n_train], train.labels, x[n_train:], test.labels,
                             test.recordings, train.class_names, alpha, 0)  # fmt: skip
            points.append(Point(label, CLASSES, w, result))
    return points


def report(points: list[Point], candidates: list[str]) -> None:
    print(markdown_table(points))
    for label in candidates[1:]:
        reference = "alpha-cv" if label.startswith("alpha-cv ") else "preset"
        print(f"\n{label} minus {reference}, points [95 % CI, paired bootstrap]:\n")
        print(change_table(points, label, reference))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("stage", choices=("choose", "test"))
    parser.add_argument(
        "--round",
        choices=("1", "split"),
        default="1",
        help="choose: the candidates of round 1 (and 2) or of round split",
    )
    parser.add_argument("--choice", default="alpha-cv", help="test: the chosen candidate")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    root = os.environ["SPLL_HW_BIOTAC_DIR"]
    split, last = (24, 32) if args.stage == "choose" else (32, 40)

    def load(recs: range) -> MultiChannelSet:
        return load_biotac_channels(root, classes="all", recordings=recs, duration=4.0).openings()

    train, test = load(range(1, split + 1)), load(range(split + 1, last + 1))
    n_train = len(train)
    samples = MultiChannelSet({n: s.joined(test.channel(n)) for n, s in train.channels.items()})
    print(f"{args.stage}: train recordings 1-{split} ({n_train} samples), score "
          f"{split + 1}-{last} ({len(test)} samples)", flush=True)  # fmt: skip
    if args.stage == "choose" and args.round == "split":
        candidates = ["alpha-cv"] + [f"alpha-cv {c}" for c in SPLITS]
        feats = split_features(samples, n_train, args.jobs, Path("reports/early/choose-split.pkl"))
        report(score(feats, candidates, train, test, n_train), candidates)
        print("\n4-fold CV over recordings 1-32 (the rule's evidence):\n")
        points = fold_cv(feats, candidates, samples)
        report(points, candidates)
        print(f"\nchosen by the rule: {split_rule(points, candidates)}")
        return
    if args.stage == "choose":
        # round 1: one change each; round 2: the CV alpha with each other change
        candidates = ["preset", "alpha-cv", "+counts", "rows-5-45", "rows-tau20"]
        candidates += [f"alpha-cv {c}" for c in candidates[2:]]
        cache = Path("reports/early/choose.pkl")
    else:
        candidates = ["preset", "alpha-cv"] + ([args.choice] if args.choice != "alpha-cv" else [])
        cache = Path(f"reports/early/test-{base(args.choice)}.pkl")
    if base(args.choice) in SPLITS and args.stage == "test":
        feats = split_features(samples, n_train, args.jobs, cache)
    else:
        feats = features(samples, n_train, args.jobs, cache, [base(c) for c in candidates])
    report(score(feats, candidates, train, test, n_train), candidates)


if __name__ == "__main__":
    main()
