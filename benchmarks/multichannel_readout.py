"""The spiking readout against the fixed-window ridge (issue 60): why it loses ~11 points on the
same network, and a readout design that keeps the ridge's accuracy.

Stages (run from the repository root; the data in ``SPLL_HW_BIOTAC_DIR``):

- ``simulate``: the preset's causal runs (:func:`spll_hw.multichannel.readout.causal_counts`'s
  encoding) of the opening sample of every recording 1-40, 20 materials, 4 s, cached under
  ``--cache`` a block of recordings at a time: every TDE's count on a 10-ms grid for every run
  (``uint16``), and the spike times of recordings 33-40 for the exact decisions of ``test``.
  Input levels come from recordings 1-32 (the training recordings' median RMS, no labels).
- ``choose``: recordings 1-32 only. Every readout candidate trained on 1-24 and decided on
  25-32 on the 10-ms grid (the membrane at every grid point; a decision at the first grid
  point where one crosses), each threshold's accuracy and mean time to decision, float,
  8-bit and 4-bit; beside, the fixed-window ridge of benchmarks/multichannel_early.py
  ``choose`` (its cache ``reports/early/choose.pkl``).
- ``test``: once, the chosen readout (staged) and the old default (prefixes) trained on 1-32
  and decided on 33-40 by :func:`spll_hw.multichannel.anytime.scored_decisions` (the golden
  engine, exact crossings), float, 8-bit and 4-bit, with paired 95 % intervals against each
  other and against the fixed-window ridge (alpha by CV; ``reports/early/test-preset.pkl`` of
  benchmarks/multichannel_early.py ``test``). The decisions are cached (``test-points.pkl``).
- ``centering``: the staged readout on the runs of other causal centerings (``simulate
  --centering ema1|first --last 32 --cache DIR``) by 4-fold CV over recordings 1-32 on the
  grid, paired against the readout's (the mean so far).
- ``pieces``, ``windows``, ``mixes``: readouts on count windows, in
  benchmarks/multichannel_readout_windows.py (its docstring).

Run from the repository root (simulate: 3 min wall on the idle 2-core machine; choose: 30 s;
test: 6.5 min of decisions at a load of 10-20)::

    export SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50
    # the fixed windows' features (reports/early/choose.pkl, test-preset.pkl), if absent:
    nice -n 10 python3 benchmarks/multichannel_early.py choose --jobs 2
    nice -n 10 python3 benchmarks/multichannel_early.py test --jobs 2
    nice -n 10 python3 benchmarks/multichannel_readout.py simulate --jobs 2
    nice -n 10 python3 benchmarks/multichannel_readout.py choose
    nice -n 10 python3 benchmarks/multichannel_readout.py test
"""

from __future__ import annotations

import argparse
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from spll_hw.classify import holdout
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.multichannel.anytime import (
    THRESHOLDS,
    fit_readouts,
    fit_staged,
    scored_decisions,
    stacked_prefixes,
    training,
)
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels
from spll_hw.multichannel.readout import START, Readout, StagedReadout, _causal_runs
from spll_hw.multichannel.timecourse import cv_alpha

#: Grid [s] of the cached counts: 10 ms to 4 s.
GRID = np.round(np.arange(1, 401) * 0.01, 10)
DURATION = 4.0
BLOCK = 4  # recordings simulated (and cached) at once


def load(root: str, recordings: range):
    return load_biotac_channels(
        root, classes="all", recordings=recordings, duration=DURATION
    ).openings()


def ema_centered(x: np.ndarray, rate: float, tau: float = 1.0) -> np.ndarray:
    """``x`` minus its exponential moving average of time constant ``tau`` [s] (started at the
    first sample): a causal high-pass at ``1 / (2 pi tau)`` Hz, what an analog front end does."""
    from scipy.signal import lfilter

    a = 1.0 - np.exp(-1.0 / (tau * rate))
    x = np.asarray(x, dtype=float)
    zi = (1.0 - a) * x[..., :1]
    return x - lfilter([a], [1.0, a - 1.0], x, axis=-1, zi=zi)[0]


def first_centered(x: np.ndarray, rate: float) -> np.ndarray:
    """``x`` minus its first sample (the level at the start of the slide)."""
    x = np.asarray(x, dtype=float)
    return x - x[..., :1]


#: Causal centerings a simulation can use (``--centering``): the readout's, and the study's.
CENTERINGS = {"mean": None, "ema1": ema_centered, "first": first_centered}


def simulate(root: str, cache: Path, jobs: int, centering: str = "mean", last: int = 40) -> None:
    config = MultichannelConfig.load("biotac-multichannel-lif")
    levels = input_levels(config, load(root, range(1, 33)))
    cache.mkdir(parents=True, exist_ok=True)
    np.save(cache / "grid.npy", GRID)
    for first in range(1, last + 1, BLOCK):
        out = cache / f"block-{first:02d}.npz"
        if out.exists():
            continue
        start = time.time()
        samples = load(root, range(first, first + BLOCK))
        keep_spikes = first >= 33 and centering == "mean"

        def keep(run, spikes=keep_spikes):
            counts = np.array([np.searchsorted(s, GRID, side="right") for s in run.tde_spikes])
            return counts, (list(run.tde_spikes) if spikes else None)

        runs = _causal_runs(samples, config, levels, keep, True, jobs, False,
                            CENTERINGS[centering])  # fmt: skip
        counts = np.array([np.concatenate([c for c, _ in row]) for row in runs])
        arrays = {
            "counts": counts.transpose(0, 2, 1).astype(np.uint16),  # (n, grid, d)
            "labels": samples.labels,
            "recordings": samples.recordings,
            "class_names": np.array(samples.class_names),
        }
        if keep_spikes:
            trains = [t for row in runs for _, s in row for t in s]
            arrays["spikes"] = np.concatenate(trains)
            arrays["lengths"] = np.array([t.size for t in trains])
        np.savez(out, **arrays)
        print(f"recordings {first}-{first + BLOCK - 1}: {time.time() - start:.0f} s", flush=True)


def cached(cache: Path, first: int, last: int, spikes: bool = False):
    """Counts ``(n, grid, d)``, labels, recording numbers (and spike trains, per run a list of
    ``d`` arrays) of recordings ``first..last`` from the cache."""
    counts, labels, recs, trains = [], [], [], []
    for block in range(first, last + 1, BLOCK):
        with np.load(cache / f"block-{block:02d}.npz") as z:
            counts.append(z["counts"])
            labels.append(z["labels"])
            recs.append([int(str(r).rsplit("/", 1)[-1].split("_")[1]) for r in z["recordings"]])
            names = tuple(str(c) for c in z["class_names"])
            if spikes:
                flat = np.split(z["spikes"], np.cumsum(z["lengths"])[:-1])
                d = z["counts"].shape[2]
                trains += [flat[i : i + d] for i in range(0, len(flat), d)]
    return np.concatenate(counts), np.concatenate(labels), np.concatenate(recs), names, trains


def channel_groups() -> np.ndarray:
    """Every TDE's channel (its readout weights' scale group)."""
    config = MultichannelConfig.load("biotac-multichannel-lif")
    per = [g.network.n for g in config.groups for _ in g.channels]
    return np.repeat(np.arange(len(per)), per)


def at(counts: np.ndarray, times) -> np.ndarray:
    """Counts at ``times`` [s] from the grid counts ``(n, grid, d)``."""
    return counts[:, [int(round(t / 0.01)) - 1 for t in times]].astype(float)


def candidates(counts, labels, recs, names, bits=(None,)) -> dict:
    """Label -> readouts (width -> readout) of every candidate, trained on ``counts``."""
    groups = channel_groups()
    out = {}
    for train_on, alpha in (("prefixes", 1.0), ("end", 1.0), ("prefixes", 100.0)):
        times, offset = training(train_on, DURATION)
        rates, y = stacked_prefixes(at(counts, times), times, labels)
        out[f"{train_on} a{alpha:g}"] = fit_readouts(rates, y, names, bits, alpha, groups, offset)
    times, offset = training("staged", DURATION)
    for alpha in (10.0, 100.0):
        out[f"staged a{alpha:g}"] = fit_staged(at(counts, times), times, labels, names,
                                               DURATION, bits, alpha, groups, offset)  # fmt: skip
    fine = (0.5, 0.75, 1.0, 1.5, 2.0, 3.0)
    times = sorted({0.25, *fine, DURATION})
    out["staged fine a100"] = fit_staged(at(counts, times), times, labels, names, DURATION,
                                         bits, 100.0, groups, offset, fine)  # fmt: skip
    return out


def membranes(readout: Readout | StagedReadout, counts: np.ndarray) -> np.ndarray:
    """Every membrane on the grid ``(n, grid, k)``; a staged readout's is the membrane of the
    stage on at each grid point."""
    if isinstance(readout, Readout):
        return counts.astype(float) @ readout.weights.T + GRID[None, :, None] * readout.bias
    out = np.zeros((*counts.shape[:2], len(readout.class_names)))
    for stage, start, end in zip(readout.stages, readout.starts, readout.ends(DURATION),
                                 strict=True):  # fmt: skip
        on = (GRID >= start - 1e-9) & ((GRID < end - 1e-9) | (end >= DURATION))
        out[:, on] = membranes(stage, counts)[:, on]
    return out


def grid_decisions(v: np.ndarray, thresholds=THRESHOLDS):
    """Winner-take-all on the grid: per threshold, the labels and times of the first grid
    point from :data:`START` where a membrane reaches it (the largest then), else the end."""
    n, g, _ = v.shape
    s = int(round(START / 0.01)) - 1
    top = v.max(axis=2)
    for theta in thresholds:
        hit = top[:, s:] >= theta
        point = np.where(hit.any(axis=1), hit.argmax(axis=1) + s, g - 1)
        yield theta, v[np.arange(n), point].argmax(axis=1), GRID[point]


def fixed_windows(
    feats: dict, root: str, split: int, last: int, labels, recs, key: str = "preset"
) -> dict:
    """The fixed-window ridge at every window as benchmarks/multichannel_early.py scores it
    (``feats``: its cache, rows recordings ``1..split`` then ``split+1..last`` in load order;
    ``key``: which of its feature sets; alpha by CV grouped by recording on the training rows),
    its held-out rows put in this cache's order (``labels``, ``recs``: the held-out runs here)
    so they pair with the readout's."""
    train, test = load(root, range(1, split + 1)), load(root, range(split + 1, last + 1))
    keys = [(int(y), int(str(r).rsplit("/", 1)[-1].split("_")[1]))
            for y, r in zip(test.labels, test.recordings, strict=True)]  # fmt: skip
    row = {key: i for i, key in enumerate(keys)}
    order = [row[int(y), int(r)] for y, r in zip(labels, recs, strict=True)]
    n = len(train)
    out = {}
    for w in (0.5, 1.0, 2.0, 4.0):
        x = feats[key, w]
        alpha = cv_alpha(x[:n], train.labels, train.recordings)
        result = holdout(x[:n], train.labels, x[n:], test.labels, test.recordings,
                         train.class_names, alpha)  # fmt: skip
        ids = np.array([f"{y}-{r}" for y, r in zip(labels, recs, strict=True)])
        out[w] = replace(result, correct=result.correct[:, order], recordings=ids)
    return out


def choose(cache: Path, root: str) -> None:
    """Recordings 1-32 only: trained on 1-24, decided on 25-32 on the 10-ms grid."""
    import pickle

    counts, labels, recs, names, _ = cached(cache, 1, 32)
    tr, te = recs <= 24, recs > 24
    feats = pickle.loads(Path("reports/early/choose.pkl").read_bytes())
    fixed = fixed_windows(feats, root, 24, 32, labels[te], recs[te])
    print("fixed-window ridge, alpha by CV, trained 1-24, scored 25-32 (features of "
          "benchmarks/multichannel_early.py choose): " + ", ".join(
              f"{100 * r.accuracy:.1f} % at {w:g} s" for w, r in fixed.items()))  # fmt: skip
    for label, widths in candidates(counts[tr], labels[tr], recs[tr], names, (None, 8, 4)).items():
        for width, readout in widths.items():
            v = membranes(readout, counts[te])
            cells = [f"{100 * np.mean(y == labels[te]):.1f}@{t.mean():.2f}"
                     for _, y, t in grid_decisions(v)]  # fmt: skip
            print(f"| {label} {width} | " + " | ".join(cells) + " |", flush=True)


def test(cache: Path, root: str) -> None:
    """Once: trained on 1-32, decided on 33-40 in the golden engine (exact crossings)."""
    import pickle

    counts, labels, recs, names, _ = cached(cache, 1, 32)
    counts_te, labels_te, recs_te, _, spikes = cached(cache, 33, 40, spikes=True)
    feats = pickle.loads(Path("reports/early/test-preset.pkl").read_bytes())
    fixed = fixed_windows(feats, root, 32, 40, labels_te, recs_te)
    # each held-out recording once (a material's recording 33 is not another's)
    test_recordings = np.array([f"{y}-{r}" for y, r in zip(labels_te, recs_te, strict=True)])
    groups = channel_groups()
    times, offset = training("prefixes", DURATION)
    rates, y = stacked_prefixes(at(counts, times), times, labels)
    old = fit_readouts(rates, y, names, (None, 8, 4), 1.0, groups, offset)
    times, offset = training("staged", DURATION)
    new = fit_staged(at(counts, times), times, labels, names, DURATION, (None, 8, 4), None,
                     groups, offset)  # fmt: skip
    saved = cache / "test-points.pkl"
    if saved.exists():  # the engine's decisions of an earlier run of this stage
        points = pickle.loads(saved.read_bytes())
    else:
        start = time.time()
        points = {}
        for label, readouts in (("prefixes", old), ("staged", new)):
            for p in scored_decisions(readouts, spikes, labels_te, test_recordings, names,
                                      DURATION, THRESHOLDS):  # fmt: skip
                points[label, p.readout, p.threshold] = p
        print(f"decided in {time.time() - start:.0f} s")
        saved.write_bytes(pickle.dumps(points))
    print("\nfixed windows (alpha by CV):", ", ".join(
        f"{w:g} s {100 * r.accuracy:.1f} [{100 * r.accuracy_ci().low:.1f}, "
        f"{100 * r.accuracy_ci().high:.1f}]" for w, r in fixed.items()))  # fmt: skip
    print("\n| θ | " + " | ".join(f"{a} {b}" for a in ("prefixes", "staged")
                                   for b in ("float", "8-bit", "4-bit")) + " |")  # fmt: skip
    for theta in THRESHOLDS:
        cells = []
        for a in ("prefixes", "staged"):
            for b in ("float", "8-bit", "4-bit"):
                p = points[a, b, theta]
                ci = p.result.accuracy_ci()
                cells.append(f"{100 * p.result.accuracy:.1f} [{100 * ci.low:.1f}, "
                             f"{100 * ci.high:.1f}] @ {p.mean_time:.2f} s")  # fmt: skip
        print(f"| {theta:g} | " + " | ".join(cells) + " |")
    print("\npaired changes, points [95 % CI, bootstrap over recordings]:")
    for theta in THRESHOLDS:
        rows = [
            ("staged float - prefixes float", ("staged", "float"), ("prefixes", "float")),
            ("staged 8-bit - staged float", ("staged", "8-bit"), ("staged", "float")),
            ("staged 4-bit - staged float", ("staged", "4-bit"), ("staged", "float")),
        ]
        cells = []
        for name, a, b in rows:
            c = points[(*a, theta)].result.change_against(points[(*b, theta)].result)
            cells.append(f"{name}: {100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]")
        print(f"θ {theta:g}: " + "; ".join(cells))
    print("\nreadout minus fixed window, points [95 % CI, paired]: the readout at the largest "
          "threshold whose mean time to decision is at most the window")  # fmt: skip
    for w, ridge in fixed.items():
        for a, b in (("staged", "float"), ("staged", "8-bit"), ("prefixes", "float")):
            mine = [p for (x, y, _), p in points.items() if (x, y) == (a, b)]
            by = [p for p in mine if p.mean_time <= w + 1e-9]
            p = max(by, key=lambda q: q.mean_time)
            c = p.result.change_against(ridge)
            print(f"{w:g} s, {a} {b} (θ {p.threshold:g}, {100 * p.result.accuracy:.1f} % at "
                  f"{p.mean_time:.2f} s) - ridge {100 * ridge.accuracy:.1f} %: "
                  f"{100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]")  # fmt: skip
    c = points["staged", "float", float("inf")].result.change_against(fixed[4.0])
    print(f"staged float at 4 s - fixed window 4 s: {100 * c.mean:+.1f} "
          f"[{100 * c.low:+.1f}, {100 * c.high:+.1f}]")  # fmt: skip


def staged_cv(counts, labels, recs, names, fit=None, decided_on=None) -> dict:
    """A staged readout by 4-fold cross-validation over recordings 1-32 (train on 24, decide
    the other 8 on the grid; folds 1-8, 9-16, 17-24, 25-32), pooled: per threshold the
    :class:`HoldoutResult` and every run's time to decision [s]. ``fit(counts, labels)``
    trains the float readout on training rows of the grid counts ``(n, grid, d)`` (default
    the staged readout at its penalty, a weight scale per channel); it decides the held-out
    rows of ``decided_on`` (default ``counts``; the same runs, e.g. split into windows)."""
    from spll_hw.classify import HoldoutResult

    if fit is None:
        times, offset = training("staged", DURATION)

        def fit(c, y):
            return fit_staged(at(c, times), times, y, names, DURATION, (None,), None,
                              channel_groups(), offset)["float"]  # fmt: skip

    decided_on = counts if decided_on is None else decided_on
    made = {theta: np.zeros(len(labels), int) for theta in THRESHOLDS}
    when = {theta: np.zeros(len(labels)) for theta in THRESHOLDS}
    for fold in range(4):
        held = (recs > 8 * fold) & (recs <= 8 * fold + 8)
        readout = fit(counts[~held], labels[~held])
        for theta, y, t in grid_decisions(membranes(readout, decided_on[held])):
            made[theta][held], when[theta][held] = y, t
    ids = np.array([f"{y}-{r}" for y, r in zip(labels, recs, strict=True)])
    return {
        theta: (HoldoutResult.of_predictions(made[theta], labels, ids, names), when[theta])
        for theta in THRESHOLDS
    }


def print_cv(results: dict) -> None:
    """Rows of :func:`staged_cv` results (label -> its dict), each cell accuracy % at mean
    time to decision and the paired change against the first row."""
    first = next(iter(results.values()))
    for name, by in results.items():
        cells = []
        for theta, (result, t) in by.items():
            c = result.change_against(first[theta][0])
            change = f"{100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]"
            cells.append(f"{100 * result.accuracy:.1f}@{t.mean():.2f} ({change})")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def centering_cv(caches: list[Path]) -> None:
    """The staged readout on the runs of each cache (a causal centering each) by
    :func:`staged_cv`; paired change of each against the first."""
    results = {}
    for cache in caches:
        counts, labels, recs, names, _ = cached(cache, 1, 32)
        results[cache.name] = staged_cv(counts, labels, recs, names)
    print_cv(results)


def export_power(folder: Path) -> tuple[str, np.ndarray]:
    """The chip profile and the dynamic power [W] of the exported network and its readout on
    it, shape ``(3,)``: at the figures' values, their low and their high ends, from the
    ``cost.json`` of ``spll-hw export --network biotac-multichannel-lif --to nir-standard
    --readout FILE`` in ``folder`` (every channel group's standard neurons and the readout's,
    each clock's steps once, on its decisions check's recordings). A decision at a mean time
    ``t`` [s] costs ``t`` times it: the chip's work up to the decision, as ``cost.json``'s own
    ``per_decision`` prices it."""
    import json

    cost = json.loads((folder / "cost.json").read_text())
    power = cost["dynamic_w"]
    return cost["profile"], np.array([power["value"], *power["range"]])


def figure(cache: Path, root: str, export: Path, path: Path) -> None:
    """Issue 60's picture from the held-out decisions of ``test`` (``test-points.pkl``) and
    the exported network's ``cost.json`` in ``export``: accuracy against mean time to
    decision of the staged readout (float and 8-bit weights, one point per threshold) and of
    the fixed-window ridge (on the window's rates, and on its quarters' from
    ``reports/early/test-quarters.pkl`` of benchmarks/multichannel_early.py ``test --choice
    "alpha-cv quarters"``), with 95 % intervals and the published curves; and the dynamic
    energy per decision on the folder's chip (``[low, high]`` over its figures' ranges) of
    what the export writes, against the same time (:func:`export_power`)."""
    import pickle

    from spll_hw.files import save_figure
    from spll_hw.multichannel.report import PUBLISHED, PUBLISHED_SOURCE
    from spll_hw.report.plots import _pyplot

    points = pickle.loads((cache / "test-points.pkl").read_bytes())
    _, labels_te, recs_te, _, _ = cached(cache, 33, 40)
    feats = pickle.loads(Path("reports/early/test-preset.pkl").read_bytes())
    fixed = fixed_windows(feats, root, 32, 40, labels_te, recs_te)
    feats = pickle.loads(Path("reports/early/test-quarters.pkl").read_bytes())
    quarters = fixed_windows(feats, root, 32, 40, labels_te, recs_te, "quarters")
    chip, power = export_power(export)
    plt = _pyplot()
    fig, (acc, joules) = plt.subplots(1, 2, figsize=(12, 4.6))
    print("| readout | θ | accuracy [95 % CI] | mean time to decision | dynamic energy per "
          f"decision on {chip} [low, high] |\n|---|---|---|---|---|")  # fmt: skip
    for name, colour in (("float", "C0"), ("8-bit", "C1")):
        mine = sorted((p for (a, b, _), p in points.items() if (a, b) == ("staged", name)),
                      key=lambda q: q.mean_time)  # fmt: skip
        t = np.array([p.mean_time for p in mine])
        y = np.array([100 * p.result.accuracy for p in mine])
        ci = np.array([[100 * p.result.accuracy_ci().low, 100 * p.result.accuracy_ci().high]
                       for p in mine])  # fmt: skip
        acc.errorbar(t, y, yerr=[y - ci[:, 0], ci[:, 1] - y], fmt="o-", color=colour,
                     capsize=3, label=f"spiking readout, {name} weights")  # fmt: skip
        e = 1e3 * t[:, None] * power
        joules.plot(t, e[:, 0], "o-", color=colour, label=f"spiking readout, {name} weights")
        joules.fill_between(t, e[:, 1], e[:, 2], color=colour, alpha=0.15)
        for p, (value, low, high) in zip(mine, e, strict=True):
            c = p.result.accuracy_ci()
            print(f"| staged {name} | {p.threshold:g} | {100 * p.result.accuracy:.1f} "
                  f"[{100 * c.low:.1f}, {100 * c.high:.1f}] | {p.mean_time:.2f} s | "
                  f"{value:.2f} mJ [{low:.2f}, {high:.2f}] |")  # fmt: skip
    w = np.array(sorted(fixed))
    for results, label, colour in ((fixed, "the window's rates", "C2"),
                                   (quarters, "each quarter's rates", "C6")):  # fmt: skip
        y = np.array([100 * results[x].accuracy for x in w])
        ci = np.array([[100 * results[x].accuracy_ci().low, 100 * results[x].accuracy_ci().high]
                       for x in w])  # fmt: skip
        acc.plot(w, y, "s-", color=colour, label=f"fixed window, ridge on {label}")
        acc.fill_between(w, ci[:, 0], ci[:, 1], color=colour, alpha=0.15)
    e = 1e3 * w[:, None] * power
    joules.plot(w, e[:, 0], "s-", color="C2", label="fixed window (network + readout)")
    joules.fill_between(w, e[:, 1], e[:, 2], color="C2", alpha=0.15)
    for label, results in (("fixed window", fixed), ("fixed window, quarters", quarters)):
        for x, (value, low, high) in zip(w, e, strict=True):
            c = results[x].accuracy_ci()
            print(f"| {label} | - | {100 * results[x].accuracy:.1f} [{100 * c.low:.1f}, "
                  f"{100 * c.high:.1f}] | {x:g} s | {value:.2f} mJ [{low:.2f}, "
                  f"{high:.2f}] |")  # fmt: skip
    for (label, curve), colour in zip(PUBLISHED.items(), ("C3", "C4", "C5"), strict=True):
        times = sorted(curve)
        acc.plot(times, [100 * curve[x] for x in times], "D--", color=colour,
                 label=f"published {label}")  # fmt: skip
    acc.set(xscale="log", xlabel="mean time to decision [s]", ylim=(0, 100),
            ylabel="accuracy, 20 materials, recordings 33-40 [%]")  # fmt: skip
    joules.set(xscale="log", yscale="log", xlabel="mean time to decision [s]",
               ylabel=f"dynamic energy per decision on {chip} [mJ]")  # fmt: skip
    from matplotlib.ticker import NullFormatter

    for ax in (acc, joules):
        ax.set_xlim(0.1, 4.5)
        ax.set_xticks([0.125, 0.25, 0.5, 1, 2, 4], ["0.125", "0.25", "0.5", "1", "2", "4"])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower right")
    acc.set_title("accuracy (95 % CI, bootstrap over recordings)")
    joules.set_title("the exported network's energy ([low, high] over the chip's figures)")
    fig.text(0.5, 0.005, f"dashed: {PUBLISHED_SOURCE}", ha="center", fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    save_figure(fig, path, dpi=110)
    print(f"\nwrote {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "stage",
        choices=("simulate", "choose", "test", "centering", "pieces", "windows", "mixes", "figure"),
    )
    parser.add_argument("--cache", type=Path, default=Path("/tmp/readout-cache"))
    parser.add_argument(
        "--centering",
        choices=tuple(CENTERINGS),
        default="mean",
        help="simulate: the causal centering (ema1: a 1-s moving average; first: the first sample)",
    )
    parser.add_argument("--last", type=int, default=40, help="simulate: recordings 1..LAST")
    parser.add_argument(
        "--against",
        type=Path,
        nargs="*",
        default=[],
        help="centering: caches of other centerings, compared with --cache",
    )
    parser.add_argument(
        "--export",
        type=Path,
        help="figure: the folder of spll-hw export --network biotac-multichannel-lif "
        "--to nir-standard --readout FILE (its cost.json prices each decision)",
    )
    parser.add_argument("--figure", type=Path, default=Path("docs/readout.png"))
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    root = os.environ["SPLL_HW_BIOTAC_DIR"]
    if args.stage == "simulate":
        simulate(root, args.cache, args.jobs, args.centering, args.last)
    elif args.stage == "centering":
        centering_cv([args.cache, *args.against])
    elif args.stage in ("pieces", "windows", "mixes"):  # count windows, in their own module
        import sys

        sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
        from benchmarks import multichannel_readout_windows as count_windows

        getattr(count_windows, args.stage)(args.cache, root)
    elif args.stage == "figure":
        figure(args.cache, root, args.export, args.figure)
    elif args.stage == "choose":
        choose(args.cache, root)
    else:
        test(args.cache, root)


if __name__ == "__main__":
    main()
