"""``_engine.cco_free_periods``: the free-running period of each integer CCO without running
the whole network, checked against the full fixed-point reference with an empty input train
(how ``quantize`` measured it before) on the pinned parameter matrices of
``tests/data/fixed_point_pinned.npz``."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import _engine

from .test_fixed_point_pinned import CASES

REFR = list(_engine.FIXED_PARAM_NAMES).index("cco_refr")


def _periods_of_a_run(case: dict[str, np.ndarray], steps: int) -> np.ndarray:
    """First CCO spike step of an empty-input run of ``steps`` steps, plus the refractory
    period; 0 without a spike."""
    state_bits, decay_bits, _ = (int(x) for x in case["meta"])
    dt = float(case["timing"][0])
    out = _engine.simulate_fixed_point(
        case["matrix"], [np.empty(0)], dt, steps * dt, state_bits, decay_bits, True, 1
    )
    return np.array(
        [
            round(s[0] / dt) + int(case["matrix"][i, REFR]) if len(s) else 0
            for i, s in enumerate(out["cco_spikes"][0])
        ],
        dtype=np.int64,
    )


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("steps", [1, 37, 2000])
def test_periods_equal_the_first_spike_of_an_empty_run(name: str, steps: int) -> None:
    case = CASES[name]
    state_bits, decay_bits, _ = (int(x) for x in case["meta"])
    periods = _engine.cco_free_periods(case["matrix"], state_bits, decay_bits, steps)
    assert periods.dtype == np.int64 and periods.shape == (case["matrix"].shape[0],)
    np.testing.assert_array_equal(periods, _periods_of_a_run(case, steps))


def test_the_reference_network_oscillates_at_its_calibrated_periods() -> None:
    case = CASES["loihi2_ref50"]
    periods = _engine.cco_free_periods(case["matrix"], 24, 12, 10_000)
    # 56.2 ... 668 Hz at dt = 10 us: about 1780 ... 150 steps.
    assert periods[0] == pytest.approx(1 / (56.2 * 1e-5), rel=0.01)
    assert periods[-1] == pytest.approx(1 / (668.0 * 1e-5), rel=0.01)
    assert np.all(np.diff(periods) <= 0)


def test_bad_arguments_are_value_errors() -> None:
    matrix = CASES["loihi2_one"]["matrix"]
    with pytest.raises(ValueError, match="16 columns"):
        _engine.cco_free_periods(matrix[:, :15].copy(), 24, 12, 100)
    with pytest.raises(ValueError, match="state_bits"):
        _engine.cco_free_periods(matrix, 40, 12, 100)
    with pytest.raises(ValueError, match="cco_bias"):
        bad = matrix.copy()
        bad[0, list(_engine.FIXED_PARAM_NAMES).index("cco_bias")] = -1
        _engine.cco_free_periods(bad, 24, 12, 100)
    with pytest.raises(ValueError, match="max_steps"):
        _engine.cco_free_periods(matrix, 24, 12, 10**10)
