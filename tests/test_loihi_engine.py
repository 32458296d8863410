"""The Rust core's Loihi executor (engine/src/loihi.rs, what mappings.lava.loihi.simulate_fixed
runs) equals the step stated in numpy (tests/loihi_reference.py) spike for spike, on presets
of every hold and current, tuned ones included, and on inputs from sparse to bursty; bad
networks come back as ValueError."""

from __future__ import annotations

import numpy as np
import pytest

from mappings.lava.loihi import DECAY_BITS, UV_MAX, _Merged, simulate_fixed
from mappings.lava.standard import lava_standard
from mappings.nir.executor import input_steps
from spll_hw import Network, _engine
from spll_hw.config import NetworkConfig

from .conftest import sparse_dense_bursty
from .loihi_reference import loihi_steps

DURATION = 0.04


def _counts(dt: float) -> np.ndarray:
    """Input counts per step of :func:`sparse_dense_bursty`'s three trains, ``(T, 3)``."""
    trains = sparse_dense_bursty(DURATION)
    return np.stack([input_steps(x, DURATION, dt) for x in trains], axis=1).astype(np.int64)


@pytest.mark.parametrize(("preset", "dt", "hold", "current"), [
    ("vibtac-vary-offset-lif", 1e-5, "compensated", "lif"),
    ("biotac-vary-offset-lif", 5e-5, "dithered", "lif"),
    ("biotac-vary-offset-lif", 5e-5, "compensated", "graded"),
    ("biotac-tuned-time-scaled-peak", 1e-5, "dithered", "graded"),
    ("biotac-tuned-vary-offset-lif", 1e-4, "compensated", "lif"),
])  # fmt: skip
def test_the_core_steps_as_numpy_spike_for_spike(preset, dt, hold, current):
    every = NetworkConfig.preset(preset).build()
    net = Network(every.spll[:: max(1, every.n_spll // 12)])  # ~12 sPLLs over the band
    params = lava_standard(net, dt=dt, hold=hold, current=current)
    counts = _counts(dt)
    net = _Merged(params)
    sent, held, raster = loihi_steps(net, counts)
    ran = _engine.simulate_loihi(*net.engine_arrays(), counts, True, threads=1)
    np.testing.assert_array_equal(ran["raster"].transpose(1, 0, 2), raster)
    np.testing.assert_array_equal(ran["sent"], sent)
    np.testing.assert_array_equal(ran["held"], held)
    assert raster.sum(axis=(0, 2)).min() > 50  # every sample drives the network
    if current == "graded":
        assert sent[:, net.graded].sum() > 0
    out = simulate_fixed(params, counts, record_spikes=True)
    np.testing.assert_array_equal(out["tde_raster"].sum(axis=0), out["tde_counts"])
    np.testing.assert_array_equal(out["cco_raster"].sum(axis=0), out["cco_counts"])


def test_bad_arrays_are_value_errors_naming_what_is_wrong():
    params = lava_standard(NetworkConfig.preset("vibtac-vary-offset-lif").build(), dt=1e-5)
    args = list(_Merged(params).engine_arrays())
    counts = np.zeros((10, 2), np.int64)
    bad_pairs = args[-1].copy()
    bad_pairs[1, 0] = 10**6
    with pytest.raises(ValueError, match="held pair"):
        _engine.simulate_loihi(*args[:-1], bad_pairs, counts, False)
    with pytest.raises(ValueError, match="threshold has 3 entries"):
        _engine.simulate_loihi(*args[:2], args[2][:3], *args[3:], counts, False)
    with pytest.raises(ValueError, match="counts must have shape"):
        simulate_fixed(params, np.zeros(10, np.int64))


def test_the_cores_loihi_words_are_pythons():
    """The 24-bit word and the 12-bit decay are the same numbers in the core and in
    mappings/lava/loihi.py (which the construction and the reference use)."""
    assert (_engine.LOIHI_UV_MAX, _engine.LOIHI_DECAY_BITS) == (UV_MAX, DECAY_BITS)
