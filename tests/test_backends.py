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
