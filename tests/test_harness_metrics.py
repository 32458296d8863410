"""Error metrics against the golden model."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw.harness.metrics import count_error, rate_error, spike_time_error
from spll_hw.result import SimulationResult


def result(spikes: list[list[float]], duration: float = 1.0) -> SimulationResult:
    arrays = [np.array(s) for s in spikes]
    counts = np.array([len(s) for s in spikes])
    return SimulationResult(counts, counts, duration, tde_spikes=arrays, cco_spikes=arrays)


def test_identical_results_have_zero_error():
    a = result([[0.1, 0.2], [0.5]])
    assert rate_error(a, a) == 0.0 and count_error(a, a) == 0.0
    errs, matched = spike_time_error(a, a)
    assert matched == 1.0 and np.all(errs == 0)


def test_errors_measure_shifts_misses_and_extras():
    ref = result([[0.1, 0.2, 0.3], [0.5]])
    shifted = result([[0.1001, 0.2, 0.9], [0.5, 0.6]])
    assert rate_error(shifted, ref) == pytest.approx(1 / 4)  # one extra spike in sPLL 1
    assert count_error(shifted, ref) == pytest.approx(1 / 4)
    errs, matched = spike_time_error(shifted, ref)
    assert matched == pytest.approx(3 / 4)  # 0.3 has no partner within 0.5 ms
    np.testing.assert_allclose(np.sort(errs), [0.0, 0.0, 1e-4], atol=1e-12)
    assert np.isnan(rate_error(ref, result([[], []])))
