"""A backend's name as reports show it names the chip it ran, also where that chip is the
backend's default profile, which its canonical spec leaves out (issue 62: "backend names always
with their options"; `simulate`'s summary and `report`'s "(chip)" column said a bare
`golden-fixed-point`)."""

from __future__ import annotations

import json

import pytest

from spll_hw import backends
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

LOIHI2 = "golden-fixed-point:profile=loihi2"


@pytest.mark.parametrize(
    ("spec", "label"),
    [
        ("golden-fixed-point", LOIHI2),
        (LOIHI2, LOIHI2),
        ("golden-fixed-point:dt=2e-5", "golden-fixed-point:profile=loihi2:dt=2e-05"),
        ("golden-fixed-point:profile=fixed16", "golden-fixed-point:profile=fixed16"),
        ("golden", "golden"),
        ("golden:profile=loihi2", "golden:profile=loihi2"),
    ],
)
def test_a_label_names_the_default_profile_and_recreates_the_backend(spec, label):
    backend = backends.get(spec)
    assert backend.label == backends.label(spec) == label
    assert backends.get(label).spec == backend.spec  # the same backend
    assert backends.get("golden-fixed-point").spec == "golden-fixed-point"  # spec unchanged


def test_a_label_of_a_backend_that_cannot_run_here_is_its_spec():
    assert backends.label("no-such-backend:profile=loihi2") == "no-such-backend:profile=loihi2"


@pytest.fixture
def small_network(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(4).to_toml())
    return path


def test_simulate_names_the_chip_its_backend_ran(small_network, tmp_path, capsys):
    out = tmp_path / "sim"
    argv = ["simulate", "--network", str(small_network), "--backend", "golden-fixed-point",
            "--duration", "0.2", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert printed.startswith(f"4 sPLLs on `{LOIHI2}`,"), printed
    summary = (out / "summary.md").read_text()
    assert f"backend `{LOIHI2}` in" in summary and f"backend `{LOIHI2}` has no probes" in summary
    assert "`golden-fixed-point`" not in summary
    assert json.loads((out / "results.json").read_text())["backend"] == "golden-fixed-point"


def test_the_reports_chip_column_names_its_chip(small_network, tmp_path):
    out = tmp_path / "report"
    argv = ["report", "--synthetic-classes", "2", "--synthetic-samples", "4", "--duration",
            "0.3", "--network", str(small_network), "--layouts", "time-scaled", "--profiles",
            "loihi2", "--steps", "none", "--folds", "2", "--compare-backends", "golden",
            "--quiet", "--jobs", "1", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    summary = (out / "summary.md").read_text()
    assert f"- loihi2 (chip): `{LOIHI2}`" in summary, summary
