"""``spll-hw report``: accuracy per layout x profile and the work-precision table."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from spll_hw import chips
from spll_hw.cli.main import main

from .figure_checks import (
    capture_figures,
    clipped_texts,
    colliding_labels,
    crossing_leaders,
    labelled_ticks,
    legend_over_axes,
)
from .pipeline_data import BIOTAC_DIR, needs_biotac

#: Three synthetic classes of six samples, 0.5 s each: the small data set most reports here run.
SMALL = ("--synthetic-classes", "3", "--synthetic-samples", "6", "--duration", "0.5")


def report(out, *args: str) -> dict:
    """``spll-hw report`` with ``args``, compared with golden alone, quietly on one job, writing
    its report to ``out``: it must succeed; its ``results.json``."""
    code = main(["report", *args, "--compare-backends", "golden", "--quiet", "--jobs", "1",
                 "--out", str(out)])  # fmt: skip
    assert code == 0
    return json.loads((Path(out) / "results.json").read_text())


def test_report_on_synthetic_data(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    results = report(tmp_path, "--synthetic-classes", "4", "--synthetic-samples", "8",
                     "--duration", "1", "--layouts", "time-scaled,vary-offset,grouped:2",
                     "--profiles", "none", "--folds", "2")  # fmt: skip
    acc = results["accuracy"]
    assert set(acc) == {"time-scaled", "vary-offset", "grouped:2"}
    reference = acc["time-scaled"]["none"]
    # change: this cell minus the reference, negative = worse
    assert reference["change"] == 0.0 and reference["change_ci"] == {
        "mean": 0.0,
        "low": 0.0,
        "high": 0.0,
        "distinct": False,
    }  # a cell against itself: every fold difference is 0
    assert results["cv"]["repeats"] == 10 and reference["n_folds"] == 20
    for cells in acc.values():
        cell = cells["none"]
        assert 0.0 <= cell["mean"] <= 1.0
        assert abs(cell["change"] - (cell["mean"] - reference["mean"])) < 1e-6
        assert len(cell["fold_accuracies"]) == 20  # 1 noise draw x 10 repeats x 2 folds
        ci = cell["change_ci"]
        assert ci["low"] <= cell["change"] <= ci["high"]
        assert ci["distinct"] == (ci["low"] > 0 or ci["high"] < 0)
    summary = (tmp_path / "summary.md").read_text()
    # the answer in one line above the pictures: the layout that loses least
    answer = summary.splitlines()[2]
    assert answer.startswith("**Least accuracy lost against the exact time-scaled network**")
    best = max(("vary-offset", "grouped:2"), key=lambda layout: acc[layout]["none"]["change"])
    assert f"none: {best}, {100 * acc[best]['none']['change']:+.1f} points" in answer
    assert summary.index(answer) < summary.index("![accuracy.png]")
    assert results["provenance"]["version"] and "utc_time" in results["provenance"]
    assert summary.index("![accuracy.png]") < summary.index("| layout |")
    assert summary.index("| layout |") < summary.index("Appendix: confusion matrices")
    for png in ("accuracy.png", "change.png"):
        assert (tmp_path / png).stat().st_size > 5000
    assert "| grouped:2 |" in summary and "confusion_grouped2_none.png" in summary
    assert (tmp_path / "confusion_vary-offset_none.png").stat().st_size > 0
    golden = results["work_precision"][0]
    assert golden["rate_error"] == 0.0
    # Timed several times, with the spread and the machine's load beside the timings.
    assert golden["timing_repeats"] == 3 and golden["cpus"] >= 1
    assert golden["seconds_min"] <= golden["seconds_per_sample"] <= golden["seconds_max"]
    assert golden["load_average"] is None or len(golden["load_average"]) == 3
    assert "load average" in summary
    # Golden alone: the figure says there is nothing to compare against.
    precision = figures["work_precision.png"].axes[0]
    assert any("nothing to compare against" in t.get_text() for t in precision.texts)
    # The legend of the accuracy bars is beside them, not over the last layout's bars.
    assert legend_over_axes(figures["accuracy.png"].axes[0]) == 0


def test_report_encodes_with_the_params_files_encoder_table(tmp_path):
    from spll_hw.config import NetworkConfig, read_encoder_table
    from spll_hw.encoders import make_encoder, settings_table

    params = tmp_path / "best.toml"
    network = NetworkConfig.preset("biotac-time-scaled-lif").with_n(8).to_toml()
    params.write_text(network + settings_table(make_encoder("lif", gain=3000.0)))
    out = tmp_path / "report"
    results = report(out, *SMALL, "--network", str(params), "--layouts", "time-scaled",
                     "--profiles", "none", "--folds", "2")  # fmt: skip
    assert results["encoder_params"]["gain"] == 3000.0
    assert read_encoder_table(out / "params.toml") == ("lif", results["encoder_params"])
    assert "gain=3000.0" in (out / "summary.md").read_text()


def test_report_marks_layouts_that_do_not_fit_a_profile_and_runs_the_chip(tmp_path):
    acc = report(tmp_path, *SMALL, "--layouts", "time-scaled,grouped:2",
                 "--profiles", "analog,fixed16", "--chip-draws", "2", "--steps", "none",
                 "--folds", "2")["accuracy"]  # fmt: skip
    # The analog chip has at most 8 time-scale groups: 50 individually scaled sPLLs do not fit.
    assert acc["time-scaled"]["analog"]["fits"] is False
    assert "at most 8" in acc["time-scaled"]["analog"]["why"]
    assert acc["grouped:2"]["analog"]["fits"] is True
    # A digital profile is reported twice: quantized parameters, and the fixed-point chip.
    assert {"fixed16", "fixed16 (chip)"} <= set(acc["grouped:2"])
    assert acc["grouped:2"]["fixed16"]["backend"] == "golden:profile=fixed16"
    assert acc["grouped:2"]["fixed16 (chip)"]["backend"] == "golden-fixed-point:profile=fixed16"
    summary = (tmp_path / "summary.md").read_text()
    assert (
        "does not fit" in summary
        and "- fixed16 (chip): `golden-fixed-point:profile=fixed16`" in summary
    )


def test_report_on_the_chips_own_arithmetic(tmp_path):
    """--backend golden-fixed-point computes every chip column with the chip's integers; the
    exact reference column stays golden."""
    results = report(tmp_path, *SMALL, "--layouts", "time-scaled,grouped:2",
                     "--profiles", "none,fixed16,analog", "--steps", "none", "--backend",
                     "golden-fixed-point", "--folds", "2", "--chip-draws", "2")  # fmt: skip
    assert results["columns"] == {
        "none": ["golden"],
        "fixed16": ["golden-fixed-point:profile=fixed16"],
        "analog": ["golden:profile=analog:chip_seed=0", "golden:profile=analog:chip_seed=1"],
    }
    assert results["accuracy"]["grouped:2"]["fixed16"]["fits"] is True


def test_report_prices_a_construction_against_the_exact_cells(tmp_path):
    """--constructions scores every layout x profile again on the construction's backend and
    pairs it with the exact cell: a 1-level gate costs accuracy a 64-level one does not."""
    results = report(tmp_path, "--synthetic-classes", "4", "--synthetic-samples", "10",
                     "--duration", "1", "--layouts", "vary-offset", "--profiles", "none,loihi2",
                     "--steps", "none",
                     "--constructions", "standard-exact:levels=1,standard-exact:levels=64",
                     "--folds", "2", "--cv-repeats", "2")  # fmt: skip
    rows = {(r["construction"], r["profile"]): r for r in results["constructions"]}
    assert set(rows) == {(f"standard-exact:levels={k}", p) for k in (1, 64)
                         for p in ("none", "loihi2")}  # fmt: skip
    for (_, profile), row in rows.items():
        exact = results["accuracy"]["vary-offset"][profile]
        assert row["exact_mean"] == exact["mean"]
        assert abs(row["change"]["mean"] - (row["mean"] - exact["mean"])) < 1e-9
        assert row["change"]["low"] <= row["change"]["mean"] <= row["change"]["high"]
    assert rows[("standard-exact:levels=64", "loihi2")]["backend"] == (
        "standard-exact:profile=loihi2:levels=64"
    )
    fine, coarse = (
        rows[("standard-exact:levels=64", "none")],
        rows[("standard-exact:levels=1", "none")],
    )
    assert abs(fine["change"]["mean"]) < abs(coarse["change"]["mean"])
    summary = (tmp_path / "summary.md").read_text()
    assert "## What the construction costs" in summary
    assert "| vary-offset | loihi2 |" in summary
    assert (tmp_path / "construction.png").stat().st_size > 5000


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--profiles", "none,loihi3"], "unknown profile 'loihi3'"),
        (["--backend", "golden-fixed-point:profile=loihi3"], "unknown profile 'loihi3'"),
        (["--backend", "nest"], "unknown backend 'nest'"),
        (["--constructions", "standard-exact:levels=0"], "option levels"),
        (["--network", "biotac-vary-offset-cochlea"], "unknown sPLL network preset"),
    ],
)
def test_report_refuses_unknown_names_before_any_work(tmp_path, capsys, args, message):
    assert main(["report", *args, "--quiet", "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_report_rejects_bad_layout_before_running(tmp_path, capsys):
    assert main(["report", "--layouts", "grouped:x", "--out", str(tmp_path)]) == 2
    assert "unknown network layout" in capsys.readouterr().err


def test_stability_command_judges_against_golden(tmp_path):
    from spll_hw.harness.stability import CASES, check

    assert main(["stability", "--backends", "golden", "--out", str(tmp_path)]) == 0
    outcomes = json.loads((tmp_path / "results.json").read_text())["outcomes"]
    assert len(outcomes) == len(CASES)
    assert all(o["verdict"] == "ok" for o in outcomes)  # golden against itself
    # Most cases must actually exercise the TDE, or they test nothing about the phase detector.
    assert sum("TDE 0 vs 0" not in o["detail"] for o in outcomes) == len(CASES)
    # A backend that fails on a case is reported as broken, not raised.
    broken = check(["golden:max_events=10"], cases=CASES[:1])
    assert broken[0].verdict == "breaks" and "max" not in broken[0].case
    assert "more than 10 events" in broken[0].detail


def test_stability_is_scoped_shows_progress_and_forgives_one_spike(tmp_path, capsys):
    from spll_hw.harness.stability import diverges

    # one spike off is the grid, not a divergence; more than both slack and tolerance is
    assert not diverges([41], [40], 0.02, 1) and diverges([43], [40], 0.02, 1)
    assert not diverges([1010, 5], [1000, 5], 0.02, 1) and diverges([0, 5], [3, 5], 0.02, 1)
    code = main([
        "stability", "--backends", "golden", "--cases", "reference,huge", "--duration", "0.2",
        "--network", "vibtac-vary-offset-lif", "--rate", "200", "--out", str(tmp_path),
    ])  # fmt: skip
    assert code == 0
    out = capsys.readouterr().out
    assert "3 cases x 1 backends" in out and "huge gains / golden: ok" in out
    outcomes = json.loads((tmp_path / "results.json").read_text())["outcomes"]
    assert [o["case"] for o in outcomes] == [
        "reference (thesis-like)", "huge gains", "network vibtac-vary-offset-lif"
    ]  # fmt: skip
    assert "sum" in outcomes[2]["detail"]  # the whole network's counts
    assert main(["stability", "--cases", "nosuchcase", "--out", str(tmp_path)]) == 2
    assert "no case has that in its name" in capsys.readouterr().err


@needs_biotac
def test_report_on_held_out_recordings(tmp_path):
    """Every cell trains on recordings 1-3 and is tested once on 4-5; changes are paired
    sample by sample and bootstrapped over the six test recordings."""
    results = report(tmp_path, "--dataset", "biotac", "--data", str(BIOTAC_DIR),
                     "--classes", "1,2,3", "--recordings", "1-5", "--holdout-recordings", "4-5",
                     "--layouts", "time-scaled,vary-offset", "--profiles", "none")  # fmt: skip
    assert results["cv"]["test_recordings"] == "4-5"
    reference = results["accuracy"]["time-scaled"]["none"]
    vary = results["accuracy"]["vary-offset"]["none"]
    assert len(reference["correct"][0]) == len(vary["correct"][0]) > 0
    assert reference["mean"] == np.mean(reference["correct"])
    assert vary["change_ci"]["low"] <= vary["change"] <= vary["change_ci"]["high"]
    assert "tested once on" in (tmp_path / "summary.md").read_text()


def test_report_costs_every_layout_on_chips_with_tables(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    every = report(tmp_path, *SMALL, "--layouts", "vary-offset,grouped:2",
                   "--profiles", "none,loihi2,fixed16", "--steps", "none",
                   "--folds", "2")["costs"]  # fmt: skip
    # Every layout x column has NeuroBench's metrics; loihi2 has chip tables (both its columns
    # are costed on the chip), fixed16 and none have none.
    assert {(c["layout"], c["column"]) for c in every} == {
        (layout, column) for layout in ("vary-offset", "grouped:2")
        for column in ("none", "loihi2", "loihi2 (chip)", "fixed16", "fixed16 (chip)")
    }  # fmt: skip
    costs = [c for c in every if c["fits"] is not None]
    assert {c["column"] for c in costs} == {"loihi2", "loihi2 (chip)"}
    for c in costs:
        energy = c["energy_J"]
        assert c["fits"] and c["cores"] >= 1 and 0 < energy["dynamic"] and energy["static"] > 0
        # loihi2's per-event costs are Loihi 1's, marked assumed; its per-step energy is
        # measured on a board: the rest
        assert 0 < energy["dynamic_assumed"] < energy["dynamic"]
        low, high = energy["dynamic_range"]
        assert low < energy["dynamic"] < high
        # What it is spent on: the parts sum to the dynamic total, static apart.
        parts = c["breakdown"]["parts"]
        assert sum(p["value_J"] for p in parts.values()) == pytest.approx(energy["dynamic"])
        assert sum(p["range_J"][0] for p in parts.values()) == pytest.approx(low)
        assert c["breakdown"]["static_J"]["value"] == pytest.approx(energy["static"])
    bench = {(c["layout"], c["column"]): c["neurobench"] for c in every}
    assert bench["vary-offset", "none"]["widths"] == "float32"
    assert bench["vary-offset", "none"]["dt_source"] == "reference"
    assert bench["vary-offset", "loihi2"]["widths"] == "loihi2"
    assert bench["vary-offset", "fixed16 (chip)"]["dt"] == 1e-4
    assert all(0 < b["activation_sparsity"] < 1 for b in bench.values())
    summary = (tmp_path / "summary.md").read_text()
    assert "## Chips: fit, cores, energy and latency" in summary
    assert "## NeuroBench metrics" in summary and "| grouped:2 | fixed16 (chip) |" in summary
    assert "![accuracy_energy.png](accuracy_energy.png)" in summary
    assert "![energy breakdown](energy_breakdown.png)" in summary
    assert "| vary-offset | loihi2 (chip) |" in summary.partition("### What the energy")[2]
    assert (tmp_path / "energy_breakdown.png").stat().st_size > 0
    assert clipped_texts(figures["energy_breakdown.png"]) == []
    # Four cells, two of them on the same energy: every point labelled, no label on another,
    # the legend off the data, and enough ticks on the narrow log energy axis to read it.
    ax = figures["accuracy_energy.png"].axes[0]
    assert len(ax.texts) == len(costs) and colliding_labels(ax) == []
    assert crossing_leaders(ax) == []
    assert legend_over_axes(ax) == 0
    assert "cheaper at both ends" in ax.get_legend().get_texts()[0].get_text()
    assert len(labelled_ticks(ax.xaxis)) >= 3
    # Its long energy label (and title) broken to fit the figure, not cut at its edges.
    assert clipped_texts(figures["accuracy_energy.png"]) == []


def test_report_ladders_the_step_refuses_what_a_step_cannot_write_and_names_the_cheapest(
    tmp_path,
):
    """--steps puts loihi2 at each step: 10 us cannot write the tuned network's slow CCO decays
    (refused by name, with the steps that can), 40 and 80 us can, the coarser step costs less
    at every figure, and the summary names it as the cheapest cell that ties the exact one."""
    results = report(tmp_path, *SMALL, "--network", "biotac-tuned-time-scaled-lif",
                     "--layouts", "time-scaled", "--profiles", "none,loihi2",
                     "--steps", "10,40,80us", "--folds", "2", "--cv-repeats", "2")  # fmt: skip
    acc = results["accuracy"]["time-scaled"]
    assert set(acc) == {"none", *(f"loihi2@{s}{c}" for s in ("10us", "40us", "80us")
                                  for c in ("", " (chip)"))}  # fmt: skip
    refused = acc["loihi2@10us"]
    assert refused["fits"] is False and "rounds to no decay" in refused["why"]
    assert "Steps that can: 40us, 80us" in refused["why"]
    costs = {c["column"]: c["energy_J"] for c in results["costs"] if c["energy_J"]}
    fine, coarse = costs["loihi2@40us"], costs["loihi2@80us"]
    # The ranges overlap, yet the coarser step is cheaper wherever the figures lie: it pays
    # fewer of every count.
    ranges = {k: tuple(v) for k, v in fine["ranges"].items()}
    assert chips.cheaper(coarse["counts"], fine["counts"], ranges) is True
    assert coarse["dynamic_range"][1] > fine["dynamic_range"][0]
    assert fine["counts"]["step"] == 2 * coarse["counts"]["step"] == 12_500
    summary = (tmp_path / "summary.md").read_text()
    line = next(x for x in summary.splitlines() if x.startswith("**Least dynamic energy"))
    # Per chip, one answer; the refused step is never it.
    assert "loihi2: " in line and "loihi2 (chip): " in line and "@10us" not in line
    assert "| time-scaled | loihi2@40us | yes |" in summary and "[" in summary


def test_report_costs_a_layout_an_analog_chip_cannot_hold_as_not_fitting(tmp_path):
    # dynapse2 holds at most 4 time-scale groups: time-scaled (one circuit per sPLL) cannot
    # be realised there. Its accuracy cell says so, and so must its cost cell: the report
    # used to end in that error after all the accuracy work.
    every = report(tmp_path, *SMALL, "--layouts", "time-scaled,grouped:2",
                   "--profiles", "none,dynapse2", "--chip-draws", "1", "--folds", "2",
                   "--cv-repeats", "1")["costs"]  # fmt: skip
    costs = {c["layout"]: c for c in every if c["column"] == "dynapse2"}
    unheld = costs["time-scaled"]
    assert not unheld["fits"] and unheld["energy_J"] is None and unheld["neurobench"] is None
    assert [w for w in unheld["why"] if "distinct sPLL circuits" in w] == unheld["why"][:1]
    assert costs["grouped:2"]["energy_J"] is not None


def test_report_says_what_each_chip_clamps_on_stderr(tmp_path, capsys):
    """loihi2 cannot hold the slowest tau_cco of biotac-time-scaled-lif: said before the run,
    one line per clamped parameter, not only in the Markdown's quantization report."""
    report(tmp_path, *SMALL, "--network", "biotac-time-scaled-lif",
           "--layouts", "time-scaled", "--profiles", "none,loihi2", "--steps", "none",
           "--folds", "2", "--cv-repeats", "1")  # fmt: skip
    err = capsys.readouterr().err
    assert "note: loihi2, time-scaled: tau_cco clamped in 3/50 sPLLs (worst -59 %" in err
    assert "note: loihi2, time-scaled: tau_cco_syn clamped in 1/50 sPLLs" in err
    summary = (tmp_path / "summary.md").read_text()
    assert summary.splitlines()[2].startswith("**Least accuracy lost")
    assert "| tau_cco |" in summary  # the Markdown keeps the full quantization report
