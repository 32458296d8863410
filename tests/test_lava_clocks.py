"""A clock per set of sPLLs on Loihi's integers (mappings/lava/clocks.py): each sPLL's step
holds its refractory period in exactly R + 1/2 steps, a time-scaled network's sPLLs get its
base sPLL's integers, one refractory period is one part, and what Loihi cannot hold is refused
by name."""

from __future__ import annotations

import numpy as np
import pytest

from mappings.lava.clocks import clocked_standard, run_clocked, spll_steps
from mappings.lava.loihi import run_trains
from mappings.lava.standard import lava_standard
from mappings.standard.construction import compensated_hold
from spll_hw import Network, network_frequencies
from spll_hw.backends import get
from spll_hw.config import NetworkConfig
from spll_hw.harness.metrics import rate_error
from spll_hw.params import PARAM_NAMES

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train


@pytest.fixture(scope="module")
def scaled():
    return NetworkConfig.preset("biotac-time-scaled-pacinian").with_n(5).build()


def _refractory(network: Network) -> np.ndarray:
    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    return np.minimum(p["t_tde_refr"], p["t_cco_refr"])


def test_each_time_scaled_spll_gets_its_own_step_and_the_base_splls_integers(scaled):
    clocked = clocked_standard(scaled, 4)
    assert [part.spll.tolist() for part in clocked.parts] == [[0], [1], [2], [3], [4]]
    steps = clocked.steps
    assert np.allclose(steps, spll_steps(scaled, 4)) and np.all(np.diff(steps) < 0)
    assert np.all(compensated_hold(_refractory(scaled), steps) == 4)
    # Scaled time constants at a step scaled alike: the same decays and CCO threshold (the
    # TDE's follows each sPLL's rows of the network's gate).
    same = {
        tuple((pop, int(lif["du"]), int(lif["dv"])) for pop, lif in sorted(part.params.lif.items()))
        + (int(part.params.lif["cco"]["vth"]),)
        for part in clocked.parts
    }
    assert len(same) == 1


def test_a_clock_per_spll_runs_close_to_golden(scaled):
    """Measured 3.8 % and 1.7 % (docs/backends.md: 4.2 % on the whole preset's check)."""
    trains = [poisson_train(150.0, 1.0, 0), poisson_train(400.0, 1.0, 1)]
    results = run_clocked(clocked_standard(scaled, 4), trains, 1.0)
    golden = get("golden").simulate_batch(scaled, trains, 1.0)
    errors = [rate_error(r, g) for r, g in zip(results, golden, strict=True)]
    assert max(errors) < 0.06, errors
    assert results[0].info["dt"] == pytest.approx(spll_steps(scaled, 4).tolist())


def test_one_refractory_period_is_one_part_at_one_step():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))
    clocked = clocked_standard(net, 4)
    (part,) = clocked.parts
    assert part.spll.tolist() == list(range(12))
    dt = float(_refractory(net)[0] / 4.5)
    alone = lava_standard(net, dt=dt, gate=clocked.gate)
    assert part.params.difference(alone) is None
    train = [poisson_train(300.0, 0.5, 2)]
    (mine,), (theirs,) = run_clocked(clocked, train, 0.5), run_trains(alone, train, 0.5, "x")
    assert np.array_equal(mine.tde_counts, theirs.tde_counts)
    assert np.array_equal(mine.cco_counts, theirs.cco_counts)


def test_what_loihi_cannot_hold_is_refused_by_name(scaled):
    with pytest.raises(ValueError, match=r"holds = 1: the refractory unit holds 2 or more"):
        spll_steps(scaled, 1)
    # 2000 steps a refractory period: tau_tde_fac needs a 12-bit decay of 0.
    with pytest.raises(ValueError, match=r"the network's sPLLs \[0\] at their step .*tau_tde_fac"):
        clocked_standard(scaled, 2000)
