"""The Rust core's NIR executor (engine/src/nir_graph.rs, what mappings.nir.executor runs)
equals the rules stated in numpy (tests/nir_reference.py) to the bit: on the standard graphs
of presets with every refractory realisation, a tuned one included, on a readout graph, in
chunks that split the run anywhere; bad graphs come back as ValueError."""

from __future__ import annotations

import numpy as np
import pytest

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir.executor import chunks_nir, input_steps, neuron_nodes, run_nir  # noqa: E402
from mappings.nir.readout_graph import to_readout_nir  # noqa: E402
from mappings.nir.standard import REFRACTORY, to_standard_nir  # noqa: E402
from spll_hw.config import NetworkConfig  # noqa: E402
from spll_hw.multichannel.readout import Readout  # noqa: E402

from .conftest import sparse_dense_bursty  # noqa: E402
from .nir_reference import reference_steps  # noqa: E402

DURATION = 0.05


def _inputs(dt: float) -> np.ndarray:
    """Input counts per step of :func:`sparse_dense_bursty`'s three trains, ``(T, 3, 1)``."""
    trains = sparse_dense_bursty(DURATION)
    return np.stack([input_steps(x, DURATION, dt) for x in trains], axis=1)[:, :, None]


def _agree(graph, x: np.ndarray, dt: float, chunk: int) -> np.ndarray:
    mine, theirs = {}, {}
    out = np.concatenate(list(chunks_nir(graph, x, dt, mine, chunk=chunk)))
    expected = np.array(list(reference_steps(graph, x, dt, theirs)))
    np.testing.assert_array_equal(out, expected)
    assert sorted(mine) == sorted(theirs) == neuron_nodes(graph)
    for name in mine:
        np.testing.assert_array_equal(mine[name], theirs[name])
    return out


@pytest.mark.parametrize(("preset", "dt", "refractory"), [
    ("vibtac-vary-offset-lif", 1e-4, REFRACTORY[0]),
    ("biotac-vary-offset-lif", 5e-5, REFRACTORY[1]),
    ("vibtac-time-scaled-lif", 2e-5, REFRACTORY[2]),
    ("biotac-tuned-vary-offset-lif", 5e-5, REFRACTORY[0]),
])  # fmt: skip
def test_the_core_steps_standard_graphs_as_numpy(preset, dt, refractory):
    net = NetworkConfig.preset(preset).build()
    graph = to_standard_nir(net, dt=dt, refractory=refractory).graph
    out = _agree(graph, _inputs(dt), dt, chunk=777)  # chunks that end mid-burst
    assert out.sum(axis=(0, 2)).min() > 100  # every sample drives the network


def test_the_core_steps_a_readout_graph_as_numpy():
    rng = np.random.default_rng(0)
    d, dt, steps = 8, 1e-4, 3000
    readout = Readout(rng.normal(0, 0.004, (4, d)), rng.normal(0.3, 0.6, 4), tuple("abcd"))
    graph = to_readout_nir(readout, 0.3, dt, 0.05)
    x = (rng.random((steps, 2, d)) < 0.02).astype(float)
    out = _agree(graph, x, dt, chunk=1000)
    assert out.any()
    np.testing.assert_array_equal(run_nir(graph, x[:, 0], dt), out[:, 0])


def test_bad_graphs_and_inputs_are_value_errors():
    from spll_hw import _engine

    graph = to_standard_nir(NetworkConfig.preset("vibtac-vary-offset-lif").build()).graph
    with pytest.raises(ValueError, match="dt must be a finite time"):
        next(chunks_nir(graph, np.zeros((10, 1)), 0.0))
    lif = ("LIF", 2, [(0, False)], [np.ones(1)] * 5, None)  # coefficients for 1, input of 2
    with pytest.raises(ValueError, match="node 1"):
        _engine.NirStepper([("Input", 2, [], [], None), lif], 1, 1)
    stepper = _engine.NirStepper([("Input", 1, [], [], None), ("Output", 1, [(0, False)], [],
                                                                None)], 1, 2)  # fmt: skip
    with pytest.raises(ValueError, match=r"shape \(steps, 2, 1\)"):
        stepper.run(np.zeros((3, 1, 1)))
