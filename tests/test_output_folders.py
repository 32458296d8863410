"""Every command's output folder is written whole or not at all: a full disk while writing ends
with exit status 2 and one line naming the path, and leaves neither a half-written folder nor
its temporary sibling; a run that fails in one backend of ``compare`` still writes the others."""

from __future__ import annotations

import errno
import json

import pytest

from spll_hw.cli.jobs import compare, response, simulate
from spll_hw.cli.main import main


def _full_disk(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize(
    ("module", "argv"),
    [
        (simulate, ["simulate", "--duration", "0.2"]),
        (response, ["response", "--points", "5", "--duration", "0.2"]),
        (compare, ["compare", "--backends", "golden", "--samples", "1", "--duration", "0.2"]),
    ],
    ids=lambda x: x if isinstance(x, str) else None,
)
def test_a_full_disk_leaves_nothing_and_names_the_folder(module, argv, tmp_path, capsys,
                                                         monkeypatch):  # fmt: skip
    out = tmp_path / "deep" / "report"
    monkeypatch.setattr(module, "write_results", _full_disk)
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert f"cannot write {out}" in err and "No space left on device" in err
    assert list(tmp_path.iterdir()) == []  # no folder, no temporary sibling, no parents made


def test_a_full_disk_keeps_an_existing_folder_as_it_was(tmp_path, capsys, monkeypatch):
    out = tmp_path / "report"
    assert main(["simulate", "--duration", "0.2", "--out", str(out)]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    monkeypatch.setattr(simulate, "write_results", _full_disk)
    assert main(["simulate", "--duration", "0.3", "--out", str(out)]) == 2
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert [p.name for p in tmp_path.iterdir()] == ["report"]


def test_a_write_that_names_no_file_is_blamed_on_the_out_folder(tmp_path, capsys, monkeypatch):
    from spll_hw.cli.jobs import chips

    out = tmp_path / "chips"
    monkeypatch.setattr(chips, "report", _full_disk)  # fails outside any atomic folder
    assert main(["chips", "--network", "vibtac-vary-offset-lif", "--out", str(out)]) == 2
    assert f"cannot write in {out}: No space left on device" in capsys.readouterr().err


def test_compare_checks_every_backend_before_any_work(tmp_path, capsys, monkeypatch):
    from spll_hw import backends

    def cannot(self, network):
        raise ValueError("tau_cco below one step")

    # the last backend cannot run this network: it fails before the first one runs
    monkeypatch.setattr(backends.backend_class("golden-fixed-point"), "prepare", cannot)
    out = tmp_path / "cmp"
    code = main(["compare", "--backends", "golden,golden-fixed-point", "--dt", "1e-4",
                 "--samples", "1", "--duration", "0.2", "--out", str(out)])  # fmt: skip
    assert code == 2
    captured = capsys.readouterr()
    assert "cannot run the network (nothing was run)" in captured.err
    assert "golden-fixed-point:dt=0.0001: tau_cco below one step" in captured.err
    assert "ms/sample" not in captured.out and not out.exists()  # nothing ran, nothing written


def test_compare_writes_what_finished_when_a_backend_fails_while_running(
    tmp_path, capsys, monkeypatch
):
    from spll_hw import backends
    from spll_hw.harness import workprecision

    measure = workprecision.measure

    def failing(spec, *args, **kwargs):
        if spec.startswith("golden-fixed-point"):
            raise RuntimeError("the device went away")
        return measure(spec, *args, **kwargs)

    monkeypatch.setattr(workprecision, "measure", failing)
    out = tmp_path / "cmp"
    code = main(["compare", "--backends", "golden-fixed-point,golden", "--dt", "1e-4",
                 "--samples", "1", "--duration", "0.2", "--out", str(out)])  # fmt: skip
    assert code == 2
    err = capsys.readouterr().err
    assert "1 backend(s) failed while running" in err and "the device went away" in err
    results = json.loads((out / "results.json").read_text())
    assert [row["spec"] for row in results["rows"]] == ["golden"]
    assert results["failed"][0]["spec"].startswith("golden-fixed-point")
    summary = (out / "summary.md").read_text()
    assert "Failed while running" in summary and "the device went away" in summary
    assert backends.get("golden")  # the registry is untouched
