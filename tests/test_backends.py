"""The backend registry: one call for every simulator."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import backends, simulate
from spll_hw.config import NetworkConfig

from .conftest import poisson_train


def test_golden_through_the_registry_equals_the_api():
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_layout("vary-offset").build()
    x = poisson_train(300, 0.5, seed=3)
    a = backends.run("golden", net, x, 0.5)
    b = simulate(net, x, 0.5)
    np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
    assert a.backend == "golden"


def test_spec_parsing():
    assert backends.parse_spec("brian2-cpp_standalone:dt=1e-5:method=exact") == (
        "brian2-cpp_standalone", {"target": "cpp_standalone", "dt": 1e-5, "method": "exact"},
    )  # fmt: skip
    assert backends.parse_spec("golden") == ("golden", {})
    assert backends.parse_specs("golden, lava-fixed") == ["golden", "lava-fixed"]
    with pytest.raises(ValueError, match="unknown backend 'nest'"):
        backends.parse_specs("golden,nest")
    with pytest.raises(ValueError, match="key=value"):
        backends.parse_spec("brian2-numpy:dt")


def test_compare_command_reports_golden_as_exact(tmp_path):
    from spll_hw.cli.compare import expand_specs
    from spll_hw.cli.main import main

    assert expand_specs(["golden", "brian2-numpy", "brian2-numpy:dt=1e-6"], [1e-4, 1e-5]) == [
        "golden", "brian2-numpy:dt=0.0001", "brian2-numpy:dt=1e-05", "brian2-numpy:dt=1e-6",
    ]  # fmt: skip
    assert main(["compare", "--samples", "2", "--duration", "0.5", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "summary.md").read_text()
    assert "| `golden` |" in text and "0.000 %" in text
    assert (tmp_path / "work_precision.png").stat().st_size > 0
    assert main(["compare", "--backends", "golden,nest", "--out", str(tmp_path)]) == 2
