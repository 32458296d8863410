"""`spll-hw chips --network` shows a bar over the profiles once it has run PROGRESS_DELAY
seconds: a 2000-sPLL network on every bundled profile ran 13.5 s in silence (issue 62:
progress on every command that can run past ~10 s)."""

from __future__ import annotations

from spll_hw.cli.jobs import chips as job
from spll_hw.cli.main import main

ARGS = ["chips", "--network", "vibtac-time-scaled-lif", "--profiles", "loihi1,loihi2"]


def test_a_long_run_shows_a_bar_over_the_profiles(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(job, "PROGRESS_DELAY", 1e9)
    assert main([*ARGS, "--out", str(tmp_path / "quiet")]) == 0
    assert "sPLLs on each profile" not in capsys.readouterr().err  # shorter than the delay
    monkeypatch.setattr(job, "PROGRESS_DELAY", 0)
    assert main([*ARGS, "--out", str(tmp_path / "shown")]) == 0
    shown = capsys.readouterr()
    assert "chips: 50 sPLLs on each profile" in shown.err and "/2 [" in shown.err, shown.err
    assert (tmp_path / "shown" / "summary.md").read_text() == (
        tmp_path / "quiet" / "summary.md"
    ).read_text()
