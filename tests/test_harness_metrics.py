"""Error metrics against the golden model, and the error-against-run-time timings and figure."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.container import ErrorbarContainer

from spll_hw.harness import workprecision
from spll_hw.harness.metrics import count_error, rate_error, spike_time_error
from spll_hw.harness.workprecision import WorkPrecisionRow
from spll_hw.result import SimulationResult

from .figure_checks import (
    capture_figures,
    clipped_texts,
    colliding_labels,
    crossing_leaders,
    label_boxes,
    labelled_ticks,
    legend_over_axes,
)


def result(spikes: list[list[float]], duration: float = 1.0) -> SimulationResult:
    arrays = [np.array(s) for s in spikes]
    counts = np.array([len(s) for s in spikes])
    return SimulationResult(counts, counts, duration, tde_spikes=arrays, cco_spikes=arrays)


def test_identical_results_have_zero_error():
    a = result([[0.1, 0.2], [0.5]])
    assert rate_error(a, a) == 0.0 and count_error(a, a) == 0.0
    errs, matched = spike_time_error(a, a)
    assert matched == 1.0 and np.all(errs == 0)


def test_errors_measure_shifts_misses_and_extras():
    ref = result([[0.1, 0.2, 0.3], [0.5]])
    shifted = result([[0.1001, 0.2, 0.9], [0.5, 0.6]])
    assert rate_error(shifted, ref) == pytest.approx(1 / 4)  # one extra spike in sPLL 1
    assert count_error(shifted, ref) == pytest.approx(1 / 4)
    errs, matched = spike_time_error(shifted, ref)
    assert matched == pytest.approx(3 / 4)  # 0.3 has no partner within 0.5 ms
    np.testing.assert_allclose(np.sort(errs), [0.0, 0.0, 1e-4], atol=1e-12)
    assert np.isnan(rate_error(ref, result([[], []])))


def _row(spec, ms, error, spread=0.1, load=(3.5, 3.0, 2.5)):
    return WorkPrecisionRow(
        spec=spec, seconds_per_sample=ms * 1e-3, rate_error=error, count_error=0.0,
        spike_time_median=0.0, spike_time_p95=0.0, matched_fraction=1.0,
        seconds_min=(ms - spread) * 1e-3, seconds_max=(ms + spread) * 1e-3, timing_repeats=3,
        load_average=load, cpus=2,
    )  # fmt: skip


def test_work_precision_shows_the_spread_the_load_and_labels_that_do_not_collide(
    tmp_path, monkeypatch
):
    figures = capture_figures(monkeypatch)
    rows = [_row("golden", 3.0, 0.0, spread=1.5)]
    # Four dt settings with nearly the same time and error: their labels would pile up.
    rows += [_row(f"golden-fixed-point:dt={dt}", 2.0 + 0.01 * k, 0.06 + 0.001 * k)
             for k, dt in enumerate(("1e-4", "3e-5", "1e-5", "3e-6"))]  # fmt: skip
    rows.append(_row("brian2-numpy:dt=1e-4", 40.0, 0.2, spread=8.0, load=(4.5, 3.0, 2.5)))
    workprecision.plot(rows, tmp_path / "wp.png")
    ax = figures["wp.png"].axes[0]
    assert colliding_labels(ax) == []
    assert legend_over_axes(ax) == 0
    assert "1-min load average 3.5-4.5 on 2 CPUs" in ax.get_title()
    assert "median of 3 runs" in ax.get_xlabel()
    bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    assert len(bars) == 2 and all(c.has_xerr for c in bars)
    # The curve follows its dt sweep from coarse to fine, whatever the timings say.
    curve = next(c for c in bars if c.get_label() == "golden-fixed-point")
    assert list(curve.lines[0].get_ydata()) == pytest.approx([6.0, 6.1, 6.2, 6.3])
    assert len(labelled_ticks(ax.xaxis)) >= 3 and len(labelled_ticks(ax.yaxis)) >= 3
    assert "while timing" in workprecision.markdown_table(rows)


def test_work_precision_names_a_curve_with_its_options_and_its_points_by_their_dt(
    tmp_path, monkeypatch
):
    """Rows and curves name the backend with its chip profile and dt (issue 62: a bare
    `golden-fixed-point`); the dt sweep still reads its points' dt from the spec as given."""
    from spll_hw import backends

    assert workprecision.row_name("golden-fixed-point:dt=1e-4",
                                  backends.get("golden-fixed-point:dt=1e-4")) == (
        "golden-fixed-point:profile=loihi2:dt=0.0001"
    )  # fmt: skip
    assert workprecision.row_name("nir-numpy:dt=1e-4", backends.get("nir-numpy:dt=1e-4")) == (
        "nir-numpy:dt=1e-4"  # the backend's default dt, which its label leaves out
    )
    figures = capture_figures(monkeypatch)
    rows = [_row("golden", 3.0, 0.0)]
    for k, dt in enumerate(("1e-4", "1e-5")):
        row = _row(f"golden-fixed-point:dt={dt}", 2.0 + k, 0.06 + 0.01 * k)
        rows.append(replace(row, name=f"golden-fixed-point:profile=loihi2:dt={dt}"))
    rows.append(replace(_row("nir-numpy:dt=1e-4", 40.0, 0.2), name="nir-numpy:dt=1e-4"))
    workprecision.plot(rows, tmp_path / "wp.png")
    ax = figures["wp.png"].axes[0]
    bars = [c for c in ax.containers if isinstance(c, ErrorbarContainer)]
    assert sorted(c.get_label() for c in bars) == ["golden-fixed-point:profile=loihi2",
                                                   "nir-numpy"]  # fmt: skip
    assert {"dt 1e-4", "dt 1e-5"} <= {t.get_text() for t in ax.texts}
    table = workprecision.markdown_table(rows)
    assert "| `golden-fixed-point:profile=loihi2:dt=1e-5` |" in table
    assert "| `nir-numpy:dt=1e-4` |" in table


def test_work_precision_axes_of_a_narrow_range_across_a_decade_keep_three_tick_labels(
    tmp_path, monkeypatch
):
    # As `spll-hw compare --backends golden,golden-fixed-point` measured them: errors of 9 to
    # 12 % and times of 0.5 to 1.3 ms. The error axis used to show 10 and 12 alone.
    figures = capture_figures(monkeypatch)
    rows = [_row("golden", 1.31, 0.0, spread=0.05)]
    rows += [_row(f"golden-fixed-point:dt={dt}", ms, error, spread=0.05)
             for dt, ms, error in (("1e-4", 0.47, 0.122), ("1e-5", 0.96, 0.1088),
                                   ("1e-6", 0.99, 0.092))]  # fmt: skip
    workprecision.plot(rows, tmp_path / "wp.png")
    fig = figures["wp.png"]
    ax = fig.axes[0]
    for axis in (ax.xaxis, ax.yaxis):
        labels = labelled_ticks(axis)
        assert len(labels) >= 3 and len(set(labels)) == len(labels), labels
    assert labelled_ticks(ax.yaxis) == ["9", "10", "11", "12"]
    assert colliding_labels(ax) == [] and crossing_leaders(ax) == []
    assert clipped_texts(fig) == []
    # Each dt label right beside its point: no leader line needed.
    assert not any(t.arrow_patch.get_visible() for t in ax.texts if hasattr(t, "arrow_patch"))


def test_work_precision_labels_keep_off_the_golden_line(tmp_path, monkeypatch):
    # A fixed-point run as fast as golden: its dt label used to sit on golden's dashed line.
    figures = capture_figures(monkeypatch)
    rows = [_row("golden", 1.85, 0.0, spread=0.9)]
    rows += [_row(f"golden-fixed-point:dt={dt}", ms, error, spread=spread)
             for dt, ms, error, spread in (("1e-4", 2.0, 0.14, 1.0), ("1e-5", 1.92, 0.1088, 0.3),
                                           ("1e-6", 9.96, 0.997, 1.0))]  # fmt: skip
    workprecision.plot(rows, tmp_path / "wp.png")
    ax = figures["wp.png"].axes[0]
    golden = ax.transData.transform((1.85, 1.0))[0]
    assert not any(box.x0 <= golden <= box.x1 for box in label_boxes(ax))
    assert colliding_labels(ax) == [] and crossing_leaders(ax) == []


def test_work_precision_of_golden_alone_says_there_is_nothing_to_compare(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    workprecision.plot([_row("golden", 1.0, 0.0, load=None)], tmp_path / "wp.png")
    ax = figures["wp.png"].axes[0]
    assert any("nothing to compare against" in t.get_text() for t in ax.texts)
    assert "golden (exact: error 0)" in ax.get_legend_handles_labels()[1]
    assert "load average not available" in ax.get_title()


def test_timings_are_repeated_and_the_load_recorded(monkeypatch):
    from spll_hw import backends
    from spll_hw.config import NetworkConfig
    from spll_hw.simulate import simulate

    network = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(3).build()
    rng = np.random.default_rng(0)
    trains = [np.sort(rng.uniform(0, 0.2, 60)) for _ in range(2)]
    golden = [simulate(network, x, 0.2) for x in trains]
    calls = []
    sim = backends.get("golden")
    batch = sim.simulate_batch
    monkeypatch.setattr(sim, "simulate_batch", lambda net, x, *a, **k: calls.append(len(x)) or
                        batch(net, x, *a, **k))  # fmt: skip
    row = workprecision.measure("golden", network, trains, 0.2, golden, repeats=4)
    assert calls == [2] * 4  # the whole batch through one configured backend, four times
    assert row.timing_repeats == 4 and row.rate_error == 0.0
    assert 0 < row.seconds_min <= row.seconds_per_sample <= row.seconds_max
    assert row.cpus == os.cpu_count()
    assert row.load_average is None or len(row.load_average) == 3
    with pytest.raises(ValueError, match="repeats must be >= 1"):
        workprecision.measure("golden", network, trains, 0.2, golden, repeats=0)
