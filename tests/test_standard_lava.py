"""The standard sPLL on Lava's own processes (mappings/lava/standard.py): the exported folder
runs on lava-nc alone and matches the project's bit-accurate reference (mappings/lava/loihi.py);
bad networks are refused."""

from __future__ import annotations

import ast
import importlib.util
import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mappings.lava.exporter import export_standard
from mappings.lava.loihi import simulate_fixed
from mappings.lava.standard import lava_standard
from mappings.nir.executor import input_steps
from mappings.standard.backend import LavaStandard, StandardFixedPoint
from spll_hw import Network, network_frequencies, simulate_batch
from spll_hw.config import NetworkConfig
from spll_hw.harness.metrics import rate_error

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

ROOT = Path(__file__).resolve().parents[1]
HAS_LAVA = importlib.util.find_spec("lava") is not None
DT = 5e-5
#: Runs run.py as a user would, with the project's packages unimportable.
RUNNER = (
    "import runpy, sys\n"
    "for m in ('spll_hw', 'mappings', 'quantize'): sys.modules[m] = None\n"
    "sys.argv = ['run.py', 'spikes.npy', sys.argv[1]]\n"
    "runpy.run_path('run.py', run_name='__main__')\n"
)


@pytest.fixture(scope="module")
def net():
    return Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))


def _outside_env() -> dict:
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def test_export_writes_without_lava_and_run_py_imports_no_project_code(net, tmp_path):
    code = (
        "import sys; sys.modules['lava'] = None\n"  # as if lava-nc were not installed
        "from tests.test_standard_lava import _export\n"
        f"_export({str(tmp_path)!r})\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        "README.md", "check_counts.py", "lava_compat.py", "params.npz", "run.py", "spll_grid.py",
        "standard.json",
    ]  # fmt: skip
    for script in ("run.py", "lava_compat.py", "spll_grid.py", "check_counts.py"):
        tree = ast.parse((tmp_path / script).read_text())
        imported = {
            (n.module if isinstance(n, ast.ImportFrom) else a.name).split(".")[0]
            for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)
            for a in (n.names if isinstance(n, ast.Import) else [None])
        }  # fmt: skip
        assert imported <= {
            "__future__",
            "json",
            "math",
            "sys",
            "pathlib",
            "numpy",
            "lava",
            "lava_compat",
            "spll_grid",
            "check_counts",
            "typing",
            "ast",
            "importlib",
            "multiprocessing",
        }, imported
    info = json.loads((tmp_path / "standard.json").read_text())
    assert info["gate_levels"] == 8 and info["populations"]["gate"]["du"] == 4095


def _export(out: str) -> None:
    """Export the test network (called in a subprocess without lava-nc)."""
    n = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))
    export_standard(n, out, dt=DT)


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
@pytest.mark.parametrize("layout", ["vary-offset", "grouped:3"])
def test_run_py_on_lava_matches_the_bit_accurate_reference_spike_for_spike(net, tmp_path, layout):
    """run.py on lava-nc, with spll-hw unimportable, counts exactly what simulate_fixed does;
    a grouped layout runs one level/TDE/CCO process per group of time constants."""
    if layout != "vary-offset":
        net = NetworkConfig.preset("vibtac-time-scaled-lif").with_layout(layout).build()
    duration = 0.1
    x = poisson_train(300.0, duration, seed=3)
    export_standard(net, tmp_path, dt=DT)
    np.save(tmp_path / "spikes.npy", x)
    done = subprocess.run([sys.executable, "-c", RUNNER, repr(duration)], cwd=tmp_path,
                          env=_outside_env(), capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    lava = json.loads(done.stdout.strip().splitlines()[-1])
    params = lava_standard(net, dt=DT)
    assert len(params.lif) == (4 if layout == "vary-offset" else 10)
    ref = simulate_fixed(params, input_steps(x, duration, DT)[:, None])
    assert lava["steps"] == 2000 and lava["dt"] == DT
    assert lava["tde_counts"] == ref["tde_counts"][0].tolist()
    assert lava["cco_counts"] == ref["cco_counts"][0].tolist()
    assert sum(lava["tde_counts"]) > 20 and min(lava["cco_counts"]) > 0


def test_reference_counts_against_golden(net):
    duration = 0.5
    trains = [poisson_train(300.0, duration, seed) for seed in (0, 1)]
    golden = simulate_batch(net, trains, duration)
    results = StandardFixedPoint(dt=DT).simulate_batch(net, trains, duration)
    errors = [rate_error(r, g) for r, g in zip(results, golden, strict=True)]
    assert max(errors) < 0.12, errors
    for r, g in zip(results, golden, strict=True):
        assert abs(r.cco_counts.sum() / g.cco_counts.sum() - 1) < 0.05


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_lava_standard_backend_equals_the_reference_backend(net):
    x = [poisson_train(300.0, 0.05, seed=7)]
    lava = LavaStandard(dt=DT).simulate_batch(net, x, 0.05)[0]
    ref = StandardFixedPoint(dt=DT).simulate_batch(net, x, 0.05)[0]
    np.testing.assert_array_equal(lava.tde_counts, ref.tde_counts)
    np.testing.assert_array_equal(lava.cco_counts, ref.cco_counts)
    assert lava.backend == "lava-standard:dt=5e-05"


def test_networks_lava_standard_cannot_represent_are_refused_by_name(net):
    scaled = Network.time_scaled(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 30))
    with pytest.raises(ValueError, match="30 sets of 12-bit decays .* lava-standard .* at most 16"):
        lava_standard(scaled, dt=DT)
    with pytest.raises(ValueError, match="tau_tde_fac = .* lava-standard needs 1..4095"):
        lava_standard(net, dt=1e-7)  # a decay below Loihi's 12-bit resolution
    strong = Network(tuple(replace(p, g_tde_trg=1e4) for p in net.spll))
    with pytest.raises(ValueError, match="lava-standard: g_tde_trg = 10000 .* 16-bit"):
        lava_standard(strong, dt=DT)  # one trigger beyond Loihi's synaptic input
    with pytest.raises(ValueError, match="drop --profile"):
        export_standard(net, "unused", profile="loihi2")
