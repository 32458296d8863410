"""The fine-clocked reference's dithered refractory hold (spll_hw/construction/reference.py):
whole steps whose mean over a neuron's spikes is the mean-correct ``t_refr/dt - 1/2``."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import Network
from spll_hw.config import NetworkConfig
from spll_hw.exporters.dt_ladder import floor_check
from spll_hw.model.holds import DitheredHold, fractional_hold


def test_a_dithered_hold_averages_the_fractional_hold_within_one_over_its_spikes():
    """Each neuron's holds, over its own n spikes (random, different per neuron), are whole
    steps of floor(h) or floor(h) + 1 whose mean is h within 1/n; a whole h is held as is."""
    dt = 1e-4
    t_refr = np.array([0.5, 0.72, 1.0, 1.049, 1.5, 3.3, 10.97, 7.25]) * dt
    mean = fractional_hold(t_refr, dt)  # 0, 0.22, 0.5, 0.549, 1, 2.8, 10.47, 6.75 steps
    hold = DitheredHold(mean, (3, mean.size))
    rng = np.random.default_rng(0)
    total = np.zeros((3, mean.size))
    spikes = np.zeros((3, mean.size), dtype=int)
    for _ in range(2000):
        spiked = rng.random((3, mean.size)) < 0.3
        steps = hold.after(spiked)
        assert steps.dtype == np.int64
        assert np.all((steps == np.floor(mean)) | (steps == np.floor(mean) + 1))
        total += np.where(spiked, steps, 0)
        spikes += spiked
    assert spikes.min() > 400
    assert np.all(np.abs(total / spikes - mean) <= 1.0 / spikes), total / spikes - mean
    whole = mean == np.floor(mean)
    assert np.all(total[:, whole] == spikes[:, whole] * mean[whole])


def test_the_dithered_hold_lowers_the_clocked_floor_of_bursting_tdes():
    """Exact integration at 100 µs, checked as the export is, on 5 sPLLs of a time-scaled
    preset whose TDEs burst at their maximum rate: holding ``t_refr/dt - 1/2`` steps on
    average (dithered) is much closer to golden than always ``round(t_refr/dt - 1/2)``
    (measured 14.5 % and 6.1 %; the whole presets: docs/notes/2026-11-27-dithered-hold.md)."""
    net = NetworkConfig.load("biotac-time-scaled-pacinian").build()
    few = Network(net.spll[::10])
    compensated = floor_check(few, 1e-4, "compensated").error
    dithered = floor_check(few, 1e-4, "dithered").error
    assert dithered < 0.6 * compensated, (dithered, compensated)


def test_the_reference_names_the_dithered_hold_among_its_rules():
    from spll_hw.construction.reference import simulate_reference

    net = Network(NetworkConfig.load("biotac-time-scaled-pacinian").build().spll[:1])
    (res,) = simulate_reference(net, [np.array([0.01])], 0.05, dt=1e-4, hold="dithered")[0]
    assert res.info["hold"] == "dithered"
    with pytest.raises(ValueError, match="'grid', 'compensated', 'dithered'"):
        simulate_reference(net, [np.array([])], 0.05, dt=1e-4, hold="loihi")
