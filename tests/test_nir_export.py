"""NIR export: node mapping, file round trip identical in the golden engine, bad graphs."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import Network, simulate
from spll_hw.config import NetworkConfig

from .conftest import poisson_train

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import from_nir, read_nir, to_nir, write_nir  # noqa: E402


@pytest.mark.parametrize("layout", ["vary-offset", "time-scaled", "grouped:4"])
def test_file_round_trip_simulates_identically(tmp_path, layout):
    net = NetworkConfig.preset("biotac-vary-offset-lif").with_layout(layout).build()
    back = read_nir(write_nir(net, tmp_path / "net.nir"))
    np.testing.assert_array_equal(back.matrix(), net.matrix())
    assert back.layout == net.layout
    np.testing.assert_array_equal(back.scales, net.scales)
    np.testing.assert_array_equal(back.groups, net.groups)
    x = poisson_train(300, 1.0, seed=4)
    a, b = simulate(net, x, 1.0), simulate(back, x, 1.0)
    np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
    for s, t in zip(a.tde_spikes + a.cco_spikes, b.tde_spikes + b.cco_spikes, strict=True):
        np.testing.assert_array_equal(s, t)


def test_cco_is_a_cubalif_with_the_offset_as_bias(base_params):
    p = base_params.time_scaled(3.0).with_free_frequency(150.0)
    graph = to_nir(Network.single(p))
    cco = graph.nodes["cco"]
    assert isinstance(cco, nir.CubaLIF)
    # tau_mem dv/dt = v_leak - v + r I  <=>  dv/dt = (I + I_offset)/C - v/tau
    np.testing.assert_allclose(cco.r, p.tau_cco / p.c_cco)
    np.testing.assert_allclose(cco.v_leak / cco.r, p.i_cco_offset)
    np.testing.assert_allclose(cco.w_in / cco.tau_syn, p.g_cco)  # Dirac input: jump w_in/tau
    np.testing.assert_allclose(graph.nodes["tde_fac"].r / graph.nodes["tde_fac"].tau, p.g_tde_fac)
    gate = graph.nodes["tde_gate"]
    assert gate.metadata["spll_hw_op"] == "gate" and gate.metadata["spll_hw_gated_by"] == "tde_fac"
    np.testing.assert_allclose(gate.scale, p.g_tde_trg)
    np.testing.assert_allclose(graph.nodes["tde"].metadata["t_refr"], p.t_tde_refr)


def test_parameters_come_from_the_nir_fields_not_only_the_metadata(base_params):
    """Without the exact-parameter metadata the fields alone rebuild the network to ~1 ulp, and
    a field edited after export takes effect."""
    net = Network.time_scaled(base_params, [60.0, 200.0, 600.0])
    graph = to_nir(net)
    del graph.metadata["spll_hw_params"]
    np.testing.assert_allclose(from_nir(graph).matrix(), net.matrix(), rtol=4e-16, atol=0)
    graph = to_nir(net)
    graph.nodes["cco"].v_leak = graph.nodes["cco"].v_leak * 1.01
    assert np.all(from_nir(graph).free_frequencies() > net.free_frequencies())


def test_bad_graphs_are_named():
    net = Network.single(NetworkConfig.preset("biotac-vary-offset-lif").spll, 100.0)
    graph = to_nir(net)
    del graph.nodes["tde_gate"]
    with pytest.raises(ValueError, match="no node 'tde_gate'"):
        from_nir(graph)
    graph = to_nir(net)
    graph.metadata["spll_hw_format"] = "something else"
    with pytest.raises(ValueError, match="not an spll-hw NIR graph"):
        from_nir(graph)
    graph = to_nir(net)
    graph.nodes["cco"].v_reset = np.ones(1)
    with pytest.raises(ValueError, match="'cco': v_reset must be 0"):
        from_nir(graph)
    with pytest.raises(ValueError, match="needs a spll_hw Network"):
        to_nir("biotac-vary-offset-lif")


def test_unreadable_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such NIR file"):
        read_nir(tmp_path / "missing.nir")
    junk = tmp_path / "junk.nir"
    junk.write_text("not hdf5")
    with pytest.raises(ValueError, match="not a readable NIR file"):
        read_nir(junk)
