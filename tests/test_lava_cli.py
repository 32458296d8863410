"""``spll-hw export --to lava|nir``: folders that load back, clear errors."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

ROOT = Path(__file__).resolve().parents[1]
needs_lava = pytest.mark.skipif(
    importlib.util.find_spec("lava") is None,
    reason="lava-nc is not installed (pip install --ignore-requires-python -e '.[lava]')",
)


@needs_lava
def test_export_to_lava_writes_a_loadable_folder(tmp_path, capsys):
    from mappings.lava import load_export
    from mappings.lava.run import make_spec

    out = tmp_path / "lava"
    assert main(["export", "--to", "lava", "--network", "biotac-vary-offset-lif",
                 "--layouts", "grouped:4", "--dt", "2e-5", "--out", str(out)]) == 0  # fmt: skip
    assert "50 sPLLs (grouped:4) exported to lava" in capsys.readouterr().out
    network = NetworkConfig.load(out / "params.toml").build()
    assert network.layout == "grouped"
    spec = load_export(out, "fixed_pt")
    direct = make_spec(network, "fixed_pt", 2e-5)
    assert spec.dt == 2e-5 and spec.formats == direct.formats
    for key in direct.cco:
        np.testing.assert_array_equal(spec.cco[key], direct.cco[key])
    assert "| tau_cco_syn |" in (out / "quantization.md").read_text()


def test_export_to_nir_round_trips(tmp_path):
    pytest.importorskip("nir", reason="the [nir] extra is missing")
    from mappings.nir import read_nir

    out = tmp_path / "nir"
    assert main(["export", "--to", "nir", "--network", "vibtac-time-scaled-lif",
                 "--out", str(out)]) == 0  # fmt: skip
    network = NetworkConfig.preset("vibtac-time-scaled-lif").build()
    np.testing.assert_array_equal(read_nir(out / "network.nir").matrix(), network.matrix())


def test_unknown_target_is_refused(tmp_path, capsys):
    assert main(["export", "--to", "loihi", "--out", str(tmp_path)]) == 2
    assert (
        "invalid choice: 'loihi' (choose from 'lava', 'lava-standard', 'nir', 'nir-standard')"
        in capsys.readouterr().err
    )


@needs_lava
def test_network_that_does_not_fit_the_profile_names_the_parameter(tmp_path, capsys):
    params = tmp_path / "tiny.toml"
    config = NetworkConfig.preset("vibtac-vary-offset-lif")
    params.write_text(config.to_toml().replace("g_tde_trg = 0.271", "g_tde_trg = 1e-12"))
    assert main(["export", "--to", "lava", "--network", str(params), "--out",
                 str(tmp_path / "out")]) == 2  # fmt: skip
    assert "g_tde_trg" in capsys.readouterr().err


def test_export_writes_without_lava_and_running_names_the_extra(tmp_path):
    """Writing the parameters needs no lava-nc; running them does, and says how to install it."""
    code = (
        "import sys; sys.modules['lava'] = None\n"  # as if lava-nc were not installed
        "from spll_hw.cli.main import main\n"
        f"assert main(['export', '--to', 'lava', '--out', {str(tmp_path)!r}]) == 0\n"
        "from mappings.lava import simulate_lava\n"
        "from spll_hw import Network, SpllParams\n"
        "net = Network.single(SpllParams(0.0075, 0.314, 0.00125, 0.00959, 0.00452, 9.84, "
        "0.271, 615.0), 100.0)\n"
        "simulate_lava(net, [0.01], 0.02)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         timeout=120)  # fmt: skip
    assert (tmp_path / "lava.json").is_file() and (tmp_path / "lava_fixed_pt.npz").is_file()
    assert out.returncode != 0
    assert "pip install --ignore-requires-python -e '.[lava]'" in out.stderr
