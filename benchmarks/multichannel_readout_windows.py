"""Readouts on count windows (issue 60), stages of benchmarks/multichannel_readout.py on its
cache (``--cache``): each TDE's causal count split at given times, so a readout neuron weighs a
spike by the window it came in (its weights switch at the edges, its membrane keeps its charge).

- ``pieces``: the decision at 4 s on the rates per window, by 4-fold CV over recordings 1-32,
  the best once on 33-40.
- ``windows``: the staged readout on the windows (:func:`split_counts`) in every stage.
- ``mixes``: staged readouts whose stages read windows or counts from the start
  (:data:`MIXES`), one chosen by a rule fixed before their CV (:func:`chosen_mix`), tested
  once on 33-40.

Run from the repository root (see benchmarks/multichannel_readout.py for the cache)::

    export SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50
    nice -n 10 python3 benchmarks/multichannel_readout.py mixes  # 16 min, 2 shared cores, load 7-24
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.multichannel_readout import (
    DURATION,
    at,
    cached,
    channel_groups,
    fixed_windows,
    load,
    print_cv,
    staged_cv,
)
from spll_hw.classify import holdout
from spll_hw.multichannel.anytime import THRESHOLDS, fit_staged, scored_decisions, training
from spll_hw.multichannel.readout import Readout, StagedReadout, stages

#: ``pieces``: the count windows [s] of each feature set (a rate per TDE and window).
PIECES = {
    "0-4 (the end stage's)": ((0.0, 4.0),),
    "0-4, 2-4": ((0.0, 4.0), (2.0, 4.0)),
    "0-4, 0-2": ((0.0, 4.0), (0.0, 2.0)),
    "0-1, 1-2, 2-4": ((0.0, 1.0), (1.0, 2.0), (2.0, 4.0)),
    "0-0.5, 0.5-1, 1-2, 2-3, 3-4": ((0.0, 0.5), (0.5, 1.0), (1.0, 2.0), (2.0, 3.0), (3.0, 4.0)),
}
#: ``pieces``: the ridge penalties compared.
PIECE_ALPHAS = (1.0, 10.0, 100.0)


def piece_rates(counts: np.ndarray, windows) -> np.ndarray:
    """Every TDE's rate [Hz] in each window ``(a, b)`` [s] of the grid counts ``(n, grid, d)``,
    shape ``(n, len(windows) x d)``: linear in the counts, so a readout neuron integrates it
    with a weight per TDE that switches at the windows' edges."""

    def n(t):
        return at(counts, [t])[:, 0] if t > 0 else np.zeros(counts[:, 0].shape)

    return np.hstack([(n(b) - n(a)) / (b - a) for a, b in windows])


def pieces(cache: Path, root: str) -> None:
    """The decision at 4 s on causal counts per window instead of one count from the start:
    every feature set of :data:`PIECES` and penalty of :data:`PIECE_ALPHAS` by 4-fold CV over
    recordings 1-32 (folds 1-8, ..., 25-32), beside the fixed-window ridge on the same folds;
    then the set and penalty best in CV trained on 1-32 and scored once on 33-40, paired
    against the end stage's (``0-4``, alpha 100, what the staged readout decides at 4 s)."""
    import pickle

    from spll_hw.classify import HoldoutResult

    counts, labels, recs, names, _ = cached(cache, 1, 32)

    def cv(x, y, numbers, alpha):
        """Whether each row is decided right when its fold is held out (``numbers``: the
        rows' recording numbers)."""
        correct = np.zeros(len(y), bool)
        for fold in range(4):
            held = (numbers > 8 * fold) & (numbers <= 8 * fold + 8)
            r = holdout(x[~held], y[~held], x[held], y[held], numbers[held], names, alpha)
            correct[held] = r.correct[0] > 0.5
        return correct

    train = load(root, range(1, 33))
    fixed_recs = np.array([int(str(r).rsplit("/", 1)[-1].split("_")[1])
                           for r in train.recordings])  # fmt: skip
    feats = pickle.loads(Path("reports/early/test-preset.pkl").read_bytes())
    fixed = feats["preset", 4.0]
    print("4-fold CV over recordings 1-32, accuracy % at 4 s (change against 0-4, alpha 1)")
    for alpha in PIECE_ALPHAS:
        ok = cv(fixed[: len(train)], np.asarray(train.labels), fixed_recs, alpha)
        print(f"| fixed window 0-4 s (window mean) | {alpha:g} | {100 * ok.mean():.1f} |")
    base = None  # the first set at the first penalty: 0-4 s, alpha 1
    best = (0.0, "", 0.0)
    for label, windows in PIECES.items():
        x = piece_rates(counts, windows)
        for alpha in PIECE_ALPHAS:
            ok = cv(x, labels, recs, alpha)
            base = ok if base is None else base
            if ok.mean() > best[0]:  # a tie keeps the first: the simpler set, the smaller penalty
                best = (ok.mean(), label, alpha)
            print(f"| {label} | {alpha:g} | {100 * ok.mean():.1f} "
                  f"({100 * (ok.mean() - base.mean()):+.1f}) |", flush=True)  # fmt: skip
    _, label, alpha = best
    counts_te, labels_te, recs_te, _, _ = cached(cache, 33, 40)
    test_ids = np.array([f"{y}-{r}" for y, r in zip(labels_te, recs_te, strict=True)])

    def scored(windows, a):
        return holdout(piece_rates(counts, windows), labels, piece_rates(counts_te, windows),
                       labels_te, test_ids, names, a)  # fmt: skip

    chosen, end = scored(PIECES[label], alpha), scored(PIECES["0-4 (the end stage's)"], 100.0)
    c, ci = chosen.change_against(end), chosen.accuracy_ci()
    print(f"\nonce on 33-40, trained on 1-32: {label}, alpha {alpha:g}: "
          f"{100 * chosen.accuracy:.1f} % [{100 * ci.low:.1f}, {100 * ci.high:.1f}]; the end "
          f"stage (0-4, alpha 100) {100 * end.accuracy:.1f} %; change {100 * c.mean:+.1f} "
          f"[{100 * c.low:+.1f}, {100 * c.high:+.1f}]")  # fmt: skip
    ridge = fixed_windows(feats, root, 32, 40, labels_te, recs_te)[4.0]
    c = chosen.change_against(ridge)
    print(f"the fixed-window ridge at 4 s (alpha by CV) {100 * ridge.accuracy:.1f} %; chosen "
          f"minus it {100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]")  # fmt: skip
    # the same as readout weights: integers of a scale per channel, window and class
    rates = piece_rates(counts, PIECES[label])
    readout = Readout.from_ridge(rates, labels, names, alpha)
    groups = window_groups(len(PIECES[label]))
    for bits in (None, 8, 4):
        r = readout if bits is None else readout.quantized(bits, groups, rates, per_class=True)
        made = r.scores(piece_rates(counts_te, PIECES[label])).argmax(axis=1)
        result = HoldoutResult.of_predictions(made, labels_te, test_ids, names)
        c, ci = result.change_against(chosen), result.accuracy_ci()
        print(
            f"{label} as readout weights, {bits or 'float'}{'-bit' if bits else ''}: "
            f"{100 * result.accuracy:.1f} % [{100 * ci.low:.1f}, {100 * ci.high:.1f}], "
            f"minus the ridge {100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]"
        )


#: ``windows``: where the windowed readout's count windows switch [s], chosen by ``pieces``
#: (the decision at 4 s by CV over recordings 1-32: 0-1, 1-2, 2-4 s).
WINDOW_EDGES = (1.0, 2.0)
#: ``windows``: the penalties compared by CV over recordings 1-32.
WINDOW_ALPHAS = (10.0, 100.0)


def split_counts(counts: np.ndarray, edges=WINDOW_EDGES) -> np.ndarray:
    """Grid counts ``(n, grid, d)`` split into count windows at ``edges`` [s]: shape
    ``(n, grid, w d)``, column ``k d + i`` the spikes of TDE ``i`` so far in window ``k``
    (``(edge_k, edge_k+1]``): a readout on them weighs a spike by the window it came in."""
    index = [0, *(int(round(e / 0.01)) - 1 for e in edges), counts.shape[1] - 1]
    grid = np.arange(counts.shape[1])
    parts = []
    for k, (a, b) in enumerate(zip(index[:-1], index[1:], strict=True)):
        base = counts[:, [a]].astype(np.int64) if k else 0
        parts.append(counts[:, np.clip(grid, a, b)].astype(np.int64) - base)
    return np.concatenate(parts, axis=2)


def split_spikes(runs, edges=WINDOW_EDGES) -> list[list[np.ndarray]]:
    """Every run's ``d`` spike trains [s] split at ``edges`` into ``w d`` trains in the
    column order of :func:`split_counts`."""
    bounds = (-np.inf, *edges, np.inf)
    return [[t[(t > a) & (t <= b)] for a, b in zip(bounds[:-1], bounds[1:], strict=True)
             for t in run] for run in runs]  # fmt: skip


def window_groups(windows: int = len(WINDOW_EDGES) + 1) -> np.ndarray:
    """A weight-scale group per column of ``windows`` count windows of every TDE, window-major
    (:func:`split_counts`, :func:`piece_rates`): its channel and window."""
    per = channel_groups()
    return np.concatenate([per + k * (per.max() + 1) for k in range(windows)])


def windows(cache: Path, root: str) -> None:
    """The staged readout on count windows (:func:`split_counts`): its penalty chosen by
    :func:`staged_cv` over recordings 1-32 (the larger mean accuracy over the thresholds from
    0.3), then trained on 1-32 and decided once on 33-40 in the golden engine (exact
    crossings), float, 8-bit and 4-bit, paired against the staged readout of ``test``
    (``test-points.pkl``) and the fixed-window ridge."""
    counts, labels, recs, names, _ = cached(cache, 1, 32)
    split, groups = split_counts(counts), window_groups()
    times, offset = training("staged", DURATION)
    results = {"staged, counts from the start": staged_cv(counts, labels, recs, names)}
    for alpha in WINDOW_ALPHAS:

        def fit(c, y, alpha=alpha):
            return fit_staged(at(c, times), times, y, names, DURATION, (None,), alpha, groups,
                              offset)["float"]  # fmt: skip

        results[f"staged, windows, alpha {alpha:g}"] = staged_cv(split, labels, recs, names, fit)
    print("4-fold CV over recordings 1-32 on the grid, accuracy % @ mean time [s] "
          "(paired change against the first row), thresholds " + ", ".join(
              f"{t:g}" for t in THRESHOLDS))  # fmt: skip
    print_cv(results)
    alpha = max(
        WINDOW_ALPHAS, key=lambda a: mean_accuracy(results[f"staged, windows, alpha {a:g}"])
    )
    print(f"chosen: alpha {alpha:g}")
    readouts = fit_staged(at(split, times), times, labels, names, DURATION, (None, 8, 4), alpha,
                          groups, offset)  # fmt: skip
    held_out(readouts, cache, root, "windows-points.pkl")


def mean_accuracy(by: dict) -> float:
    """Mean accuracy over the thresholds from 0.3 (and the end) of a :func:`staged_cv` result."""
    return float(np.mean([r.accuracy for theta, (r, _) in by.items() if theta >= 0.3]))


def held_out(readouts: dict[str, StagedReadout], cache: Path, root: str, name: str) -> None:
    """Once on 33-40: ``readouts`` (width -> readout on :func:`split_counts`'s columns,
    trained on 1-32) decided in the golden engine (exact crossings) on the split spike
    trains, saved as ``name`` in ``cache``; every threshold's accuracy [95 % CI] at its mean
    time, paired against the staged readout of ``test`` (``test-points.pkl``) of the same
    width, 8-bit against float, and against the fixed-window ridge."""
    import pickle

    _, labels_te, recs_te, names, spikes = cached(cache, 33, 40, spikes=True)
    ids = np.array([f"{y}-{r}" for y, r in zip(labels_te, recs_te, strict=True)])
    points = {(p.readout, p.threshold): p for p in scored_decisions(
        readouts, split_spikes(spikes), labels_te, ids, names, DURATION, THRESHOLDS)}  # fmt: skip
    (cache / name).write_bytes(pickle.dumps(points))
    staged = pickle.loads((cache / "test-points.pkl").read_bytes())

    def change(p, q):
        c = p.change_against(q)
        return f"{100 * c.mean:+.1f} [{100 * c.low:+.1f}, {100 * c.high:+.1f}]"

    print("\nonce on 33-40, trained on 1-32: accuracy % [95 % CI] @ mean time; paired change "
          "against the staged readout of the same width at the same threshold")  # fmt: skip
    for theta in THRESHOLDS:
        cells = []
        for width in readouts:
            p, q = points[width, theta], staged["staged", width, theta]
            ci = p.result.accuracy_ci()
            cells.append(f"{100 * p.result.accuracy:.1f} [{100 * ci.low:.1f}, "
                         f"{100 * ci.high:.1f}] @ {p.mean_time:.2f} s "
                         f"({change(p.result, q.result)})")  # fmt: skip
        print(f"| {theta:g} | " + " | ".join(cells) + " |", flush=True)
    print("8-bit minus float, paired: " + "; ".join(
        f"θ {t:g} {change(points['8-bit', t].result, points['float', t].result)}"
        for t in THRESHOLDS))  # fmt: skip
    feats = pickle.loads(Path("reports/early/test-preset.pkl").read_bytes())
    fixed = fixed_windows(feats, root, 32, 40, labels_te, recs_te)
    print("\nagainst the fixed windows: the largest threshold whose mean time is at most T")
    for w, ridge in fixed.items():
        for width in ("float", "8-bit"):
            by = [p for (x, _), p in points.items() if x == width and p.mean_time <= w + 1e-9]
            p = max(by, key=lambda q: q.mean_time)
            print(f"{w:g} s, {width} (θ {p.threshold:g}, {100 * p.result.accuracy:.1f} % "
                  f"at {p.mean_time:.2f} s) - ridge {100 * ridge.accuracy:.1f} %: "
                  f"{change(p.result, ridge)}")  # fmt: skip


#: ``mixes``: the candidates, fixed before their CV (docs/notes, 2026-12-07-readout-windows-
#: hybrid.md): label -> (margin [s], late). A stage reads the edges of :data:`WINDOW_EDGES`
#: that lie at least ``margin`` before its earliest training prefix (:func:`window_plan`; 0:
#: every stage that can, ``inf``: counts from the start); ``late``: the last stage reads counts
#: from the start and the windowed end stage is switched on for the grid's last step only
#: (:data:`LATE`).
MIXES = {
    "counts from the start": (float("inf"), False),
    "windows in every stage": (0.0, False),
    "margin 1 s": (1.0, False),
    "hybrid: windows in the end stage": (2.0, False),
    "counts, windowed end at 3.99 s": (float("inf"), True),
    "windows to 3 s, windowed end at 3.99 s": (0.0, True),
}
#: When the windowed end stage of a ``late`` mix is switched on [s]: the grid's last step.
LATE = DURATION - 0.01


def window_plan(margin: float, late: bool) -> tuple[tuple[float, ...], ...]:
    """The window edges [s] each stage of the staged readout reads (``()``: counts from the
    start), and with ``late`` the windowed end stage's after them (:data:`MIXES`)."""
    plan = [tuple(e for e in WINDOW_EDGES if min(prefixes) >= e + margin - 1e-9)
            for _, prefixes in stages(DURATION)]  # fmt: skip
    return (*plan[:-1], (), WINDOW_EDGES) if late else tuple(plan)


def fitted_where_on(margin: float, late: bool) -> bool:
    """Whether every stage that reads windows was trained at both ends of the stretch it is on
    (within a grid step, 10 ms): its membrane is then fitted wherever it can decide. A
    stage on counts from the start needs none of it (its membrane at ``t`` is ``t`` times its
    score on the rates so far, about steady); one on windows is not (a window partly filled
    holds fewer spikes than its weights were trained on)."""
    spans = stages(DURATION) + (((LATE, (DURATION,)),) if late else ())
    ends = [start for start, _ in spans[1:]] + [DURATION]
    return all(not edges or (min(p) <= start + 0.01 + 1e-9 and max(p) >= end - 1e-9)
               for edges, (start, p), end in zip(window_plan(margin, late), spans, ends,
                                                 strict=True))  # fmt: skip


def widened(readout: Readout, edges: tuple[float, ...]) -> Readout:
    """A readout of the count windows at ``edges`` (a subset of :data:`WINDOW_EDGES`) as one of
    :func:`split_counts`'s columns: each window's weights are those of the window that holds it."""
    d = readout.weights.shape[1] // (len(edges) + 1)
    held = [sum(e <= low + 1e-9 for e in edges) for low in (0.0, *WINDOW_EDGES)]
    weights = np.hstack([readout.weights[:, j * d : (j + 1) * d] for j in held])
    return Readout(weights, readout.bias, readout.class_names, readout.bits)


def mixed(counts, labels, names, margin, late, bits=(None,)) -> dict[str, StagedReadout]:
    """The mix of :data:`MIXES` (``margin``, ``late``) trained on grid counts ``(n, grid, d)``
    with ``labels``: each stage as the staged readout on its windows trains it (penalty 100,
    a weight scale per channel, window and class), widths ``bits``; every readout reads
    :func:`split_counts`'s columns ``(3 d)``."""
    times, offset = training("staged", DURATION)
    plan = window_plan(margin, late)
    fits = {
        edges: fit_staged(at(split_counts(counts, edges), times), times, labels, names,
                          DURATION, bits, None, window_groups(len(edges) + 1), offset)
        for edges in set(plan)
    }  # fmt: skip
    n = len(stages(DURATION))
    index = [*range(n), n - 1][: len(plan)]  # a late end stage: the windowed fit's end stage
    starts = tuple(start for start, _ in stages(DURATION)) + ((LATE,) if late else ())
    return {
        width: StagedReadout(tuple(widened(fits[edges][width].stages[k], edges)
                                   for k, edges in zip(index, plan, strict=True)), starts)
        for width in fits[plan[0]]
    }  # fmt: skip


def chosen_mix(results: dict) -> str:
    """The rule fixed before the CV: among the mixes fitted where they are on
    (:func:`fitted_where_on`) whose pooled CV accuracy (``results``: label -> :func:`staged_cv`)
    is at no threshold from 0.3 (and the end) more than 1 point below counts from the start's,
    the largest :func:`mean_accuracy`; within 0.5 point of it, the fewest windowed stages."""
    base = results["counts from the start"]

    def eligible(label):
        return fitted_where_on(*MIXES[label]) and all(
            r.accuracy >= base[theta][0].accuracy - 0.01 - 1e-9
            for theta, (r, _) in results[label].items() if theta >= 0.3)  # fmt: skip

    ok = [label for label in results if eligible(label)]
    best = max(mean_accuracy(results[label]) for label in ok)
    near = [label for label in ok if mean_accuracy(results[label]) >= best - 0.005 - 1e-9]
    return min(near, key=lambda label: sum(map(bool, window_plan(*MIXES[label]))))


def switched(by: dict, switch: float, theta: float) -> str:
    """How many runs of a :func:`staged_cv` result ``by`` were decided at threshold ``theta``
    within 0.1 s after the stage switch at ``switch`` [s], and how many of them right: a stage
    whose membranes are not fitted where it is switched on decides many runs at once there."""
    result, when = by[theta]
    mine = (when >= switch - 1e-9) & (when < switch + 0.1 - 1e-9)
    right = result.correct.mean(axis=0)[mine]
    return f"{mine.sum()} runs, {100 * right.mean():.0f} % right" if mine.any() else "none"


def mixes(cache: Path, root: str) -> None:
    """Every mix of :data:`MIXES` by :func:`staged_cv` over recordings 1-32, the one of
    :func:`chosen_mix` trained on 1-32 and decided once on 33-40 (:func:`held_out`)."""
    counts, labels, recs, names, _ = cached(cache, 1, 32)
    split = split_counts(counts)
    results = {}
    for label, (margin, late) in MIXES.items():

        def fit(c, y, margin=margin, late=late):
            return mixed(c, y, names, margin, late)["float"]

        results[label] = staged_cv(counts, labels, recs, names, fit, split)
    print("4-fold CV over recordings 1-32 on the grid, accuracy % @ mean time [s] "
          "(paired change against the first row), thresholds " + ", ".join(
              f"{t:g}" for t in THRESHOLDS))  # fmt: skip
    print_cv(results)
    for label, by in results.items():
        plan = window_plan(*MIXES[label])
        print(f"{label}: windows {' / '.join(','.join(f'{e:g}' for e in p) or '-' for p in plan)}"
              f"; fitted where on: {fitted_where_on(*MIXES[label])}; mean from θ 0.3 "
              f"{100 * mean_accuracy(by):.1f} %; decided within 0.1 s after the switch at "
              + ", ".join(f"{s:g} s (θ {t:g}): {switched(by, s, t)}"
                          for s in (2.0, 3.0) for t in (2.0, 3.0)))  # fmt: skip
    label = chosen_mix(results)
    print(f"chosen: {label}")
    held_out(
        mixed(counts, labels, names, *MIXES[label], (None, 8, 4)), cache, root, "mixes-points.pkl"
    )
