"""``spll-hw report``: accuracy per layout x profile and the work-precision table."""

from __future__ import annotations

import json

from spll_hw.cli.main import main


def test_report_on_synthetic_data(tmp_path):
    code = main([
        "report", "--synthetic-classes", "4", "--synthetic-samples", "8", "--duration", "1",
        "--layouts", "time-scaled,vary-offset,grouped:2", "--profiles", "none",
        "--backends", "golden", "--folds", "2", "--quiet", "--jobs", "1", "--out", str(tmp_path),
    ])  # fmt: skip
    assert code == 0
    results = json.loads((tmp_path / "results.json").read_text())
    acc = results["accuracy"]
    assert set(acc) == {"time-scaled", "vary-offset", "grouped:2"}
    assert acc["time-scaled"]["none"]["loss"] == 0.0
    for cells in acc.values():
        cell = cells["none"]
        assert 0.0 <= cell["mean"] <= 1.0
        assert abs(cell["loss"] - (acc["time-scaled"]["none"]["mean"] - cell["mean"])) < 1e-6
    summary = (tmp_path / "summary.md").read_text()
    assert "| grouped:2 |" in summary and "confusion_grouped2_none.png" in summary
    assert (tmp_path / "confusion_vary-offset_none.png").stat().st_size > 0
    assert results["work_precision"][0]["rate_error"] == 0.0


def test_report_rejects_bad_layout_before_running(tmp_path, capsys):
    assert main(["report", "--layouts", "grouped:x", "--out", str(tmp_path)]) == 2
    assert "unknown network layout" in capsys.readouterr().err
