"""The spiking readout in the golden engine (spll_hw/multichannel/decisions.py,
engine/src/readout.rs): the same decisions as the Python reference, exactly, on golden runs and on
constructed edge cases; bad input is a ValueError."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import Network, network_frequencies, simulate_batch
from spll_hw.multichannel.anytime import fit_readouts, scored_decisions
from spll_hw.multichannel.decisions import engine_decisions
from spll_hw.multichannel.readout import CHUNK, START, Readout, decide

from .test_chip_resources import BASE

NAMES = ("a", "b", "c")
THRESHOLDS = (0.05, 0.2, 0.5, 1.0, 2.0, 5.0, np.inf)


def reference(readout, runs, duration, thresholds, not_before):
    """The Python decisions of every run at every threshold."""
    out = []
    for run in runs:
        path = readout.membrane_path(run, duration)
        out.append([decide(path, t, not_before) for t in thresholds])
    return out


def assert_same(readout, runs, duration, thresholds=THRESHOLDS, not_before=0.0):
    """Engine and Python decide every run alike: labels, times and flags equal (not close)."""
    got = engine_decisions(readout, runs, duration, thresholds, not_before)
    want = reference(readout, runs, duration, thresholds, not_before)
    assert got.labels.shape == (len(runs), len(thresholds))
    for r, row in enumerate(want):
        assert [got.at(r, m) for m in range(len(thresholds))] == row, r
    return got


def test_golden_runs_decide_alike_in_the_engine_and_in_python():
    # three classes of input frequency (jittered periodic trains) through a 6-sPLL network; a
    # readout trained on their TDE rates decides held-out runs at every threshold, before and
    # after switch-on
    network = Network.vary_offset(BASE, network_frequencies(80.0, 400.0, 6))
    rng = np.random.default_rng(4)
    trains = []
    for f in np.repeat([300.0, 400.0, 500.0], 8):
        t = np.arange(0, 1.0, 1 / f)
        trains.append(np.sort(np.clip(t + rng.normal(0, 3e-4, t.size), 0, None)))
    runs = simulate_batch(network, trains, 1.0, record_spikes=True, threads=1)
    counts = np.array([r.tde_counts for r in runs], float)
    labels = np.repeat(np.arange(3), 8)
    train = np.arange(24) % 4 != 0
    readout = Readout.from_ridge(counts[train], labels[train], NAMES, alpha=1.0)
    held = [r.tde_spikes for r, keep in zip(runs, train, strict=True) if not keep]
    assert min(sum(len(t) for t in run) for run in held) > 100
    for not_before in (0.0, 0.1, 0.5):
        got = assert_same(readout, held, 1.0, not_before=not_before)
        assert got.fired.any() and not got.fired[:, -1].any()
    # the integer readout too
    assert_same(readout.quantized(8, rates=counts[train]), held, 1.0, not_before=0.1)


def edge_readout() -> Readout:
    # class 0: +1 per spike of TDE 0; class 1: +0.5 per spike of TDE 0 or 1 and 1/s;
    # class 2: +1 per spike of TDE 1, -0.5/s
    weights = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])
    return Readout(weights, np.array([0.0, 1.0, -0.5]), NAMES)


@pytest.mark.parametrize(
    ("trains", "duration", "thresholds", "not_before", "expect"),
    [
        # both jump past 0.5 at 0.3; class 0 is higher then (1 > 0.8)
        ([[0.3], []], 1.0, [0.5], 0.0, [(0, 0.3, True)]),
        # classes 0 and 1 pass 1 by the spikes of one instant; class 1 is higher then (1.2 > 1)
        ([[0.2], [0.2]], 0.3, [1.0], 0.0, [(1, 0.2, True)]),
        # classes 0 and 1 reach 1 at 0.5, both at 1 exactly: the lower class wins the tie
        ([[0.5], []], 1.0, [1.0], 0.0, [(0, 0.5, True)]),
        # nobody reaches 10: the largest at the end; no spike at all: the bias lines only
        (
            [[], []],
            2.0,
            [10.0, 1.5, np.inf],
            0.0,
            [(1, 2.0, False), (1, 1.5, True), (1, 2.0, False)],
        ),
        # switch-on: classes 0 and 1 are above 0.5 before 0.6; the larger at 0.6 (2 > 1.6)
        # decides then
        ([[0.1, 0.2], []], 1.0, [0.5], 0.6, [(0, 0.6, True)]),
        # a spike at the run's end counts (class 1 jumps from 1 to 1.5 then), one after it
        # does not
        ([[1.0], [1.5]], 1.0, [1.4, np.inf], 0.0, [(1, 1.0, True), (1, 1.0, False)]),
        # the crossing falls exactly on the switch-on
        ([[], []], 1.0, [0.4], 0.4, [(1, 0.4, True)]),
    ],  # fmt: skip
)
def test_constructed_edge_cases_decide_as_written_in_both(
    trains, duration, thresholds, not_before, expect
):
    runs = [[np.array(t, float) for t in trains]]
    got = assert_same(edge_readout(), runs, duration, thresholds, not_before)
    assert [tuple(d) for d in zip(got.labels[0], got.times[0], got.fired[0], strict=True)] == [
        pytest.approx(e) for e in expect
    ]


def test_random_readouts_on_a_coarse_time_grid_decide_alike():
    # spike times on a 10 ms grid: many TDEs spike at one instant, many crossings tie
    rng = np.random.default_rng(11)
    for _ in range(25):
        k, d = rng.integers(2, 6), rng.integers(1, 8)
        weights = rng.choice([-0.5, 0.0, 0.25, 0.5, 1.0], size=(k, d))
        bias = rng.choice([-1.0, 0.0, 0.5, 1.0], size=k)
        readout = Readout(weights, bias, tuple(map(str, range(k))))
        runs = [
            [np.sort(rng.integers(0, 101, rng.integers(0, 30)) / 100.0) for _ in range(d)]
            for _ in range(3)
        ]
        assert_same(readout, runs, 1.0, (0.25, 0.5, 1.0, 1.5, 3.0, np.inf), rng.choice([0, 0.3]))


def test_bad_readout_input_is_a_value_error_naming_it():
    readout = edge_readout()
    run = [np.array([0.1]), np.array([0.2])]
    nan = Readout(np.array([[1.0, np.nan], [0, 0], [0, 0]]), readout.bias, NAMES)
    with pytest.raises(ValueError, match="weight of class 0 from TDE 1 is NaN"):
        engine_decisions(nan, [run], 1.0, [1.0])
    inf = Readout(readout.weights, np.array([0.0, np.inf, 0.0]), NAMES)
    with pytest.raises(ValueError, match="bias of class 1 is inf"):
        engine_decisions(inf, [run], 1.0, [1.0])
    rows = Readout(readout.weights, readout.bias[:2], NAMES)
    with pytest.raises(ValueError, match=r"one row per bias, got \[3, 2\] for 2 classes"):
        engine_decisions(rows, [run], 1.0, [1.0])
    with pytest.raises(ValueError, match="run 0: 1 TDE spike trains, the readout takes 2"):
        engine_decisions(readout, [run[:1]], 1.0, [1.0])
    with pytest.raises(ValueError, match="thresholds must be > 0"):
        engine_decisions(readout, [run], 1.0, [0.0])
    bad = [run] * (CHUNK + 3)
    bad[CHUNK + 1] = [np.array([0.1]), np.array([np.nan])]
    with pytest.raises(ValueError, match=f"run {CHUNK + 1}: TDE 1 has a spike at NaN s"):
        engine_decisions(readout, bad, 1.0, [1.0])
    with pytest.raises(ValueError, match="duration must be finite"):
        engine_decisions(readout, [run], np.inf, [1.0])
    empty = engine_decisions(readout, [], 1.0, [1.0, 2.0])
    assert empty.labels.shape == (0, 2) and empty.fired.dtype == bool


def test_fitted_readouts_decide_as_the_reference_scored():
    rng = np.random.default_rng(2)
    centres = rng.uniform(5, 60, size=(3, 4))
    labels = np.repeat(np.arange(3), 10)
    rates = centres[labels] + rng.normal(0, 4, size=(30, 4))
    test_labels = np.repeat(np.arange(3), 3)
    runs = [[np.sort(rng.uniform(0, 2.0, rng.poisson(2.0 * r))) for r in centres[c]]
            for c in test_labels]  # fmt: skip
    thresholds = (0.5, 2.0, np.inf)
    readouts = fit_readouts(rates, labels, NAMES, bits=(None, 6))
    points = scored_decisions(readouts, runs, test_labels, np.arange(9), NAMES, 2.0, thresholds)
    assert [(p.readout, p.threshold) for p in points] == [
        (r, t) for r in ("float", "6-bit") for t in thresholds
    ]
    float_readout = Readout.from_ridge(rates, labels, NAMES)
    for width, readout in ((None, float_readout), (6, float_readout.quantized(6, rates=rates))):
        want = reference(readout, runs, 2.0, thresholds, START)
        for m, point in enumerate(points[:3] if width is None else points[3:]):
            made = [row[m] for row in want]
            correct = np.mean([d.label == y for d, y in zip(made, test_labels, strict=True)])
            assert point.result.accuracy == pytest.approx(correct)
            assert point.mean_time == pytest.approx(np.mean([d.time for d in made]))
            assert point.fired == pytest.approx(np.mean([d.fired for d in made]))
