"""The standard-sPLL targets through the registries and the command line, as users see them:
the installed entry points (tests/test_backends.py checks they are pyproject.toml's)."""

from __future__ import annotations

import pytest

from spll_hw import backends, exporters
from spll_hw.backends.base import Backend
from spll_hw.cli.main import main

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

NEW_BACKENDS = {"nir-numpy", "nir-snntorch", "nir-norse", "standard-fixed-point", "lava-standard"}
NEW_EXPORTERS = {"nir-standard", "lava-standard"}


def test_declared_backends_and_exporters_load():
    assert NEW_BACKENDS <= set(backends.names())
    for name in NEW_BACKENDS:
        cls = backends.backend_class(name)
        assert issubclass(cls, Backend) and cls.name == name and cls.description
    assert NEW_EXPORTERS <= set(exporters.names())
    for name in NEW_EXPORTERS:
        assert exporters.describe(name)
    assert backends.get("nir-numpy:levels=4").spec == "nir-numpy:levels=4"


@pytest.mark.parametrize(
    ("target", "expected"),
    [("nir-standard", "network.nir"), ("lava-standard", "run.py")],
)
def test_export_command_writes_the_standard_targets(tmp_path, capsys, target, expected):
    out = tmp_path / target
    # --allow-error: this tests the command, not the check (tests/test_export_check.py does);
    # at 50 us both targets pass their check here, within their declared tolerances.
    args = ["export", "--to", target, "--network", "vibtac-vary-offset-lif", "--out", str(out),
            "--allow-error", "--dt", "5e-5"]  # fmt: skip
    assert main(args) == 0
    assert (out / expected).is_file() and (out / "params.toml").is_file()
    assert (out / "check.json").is_file()
    assert f"exported to {target}" in capsys.readouterr().out
    assert main([*args[:-2], "--profiles", "loihi2"]) == 2
    assert "drop --profile" in capsys.readouterr().err


def test_compare_includes_the_standard_backends(tmp_path):
    args = ["compare", "--backends", "golden,nir-numpy:dt=1e-4,standard-fixed-point:dt=5e-5",
            "--samples", "1", "--duration", "0.2", "--out", str(tmp_path)]  # fmt: skip
    assert main(args) == 0
    text = (tmp_path / "summary.md").read_text()
    assert "| `nir-numpy:dt=1e-4` |" in text and "| `standard-fixed-point:dt=5e-5` |" in text
