"""The Brian2 mapping against the golden model: convergence in dt, gating, spike ordering,
flags for time steps that cannot resolve the network, and the C++ standalone target.

Needs the ``[brian2]`` extra. The C++ standalone test compiles a project (about 20 s on two
cores); deselect it with ``-k "not cpp_standalone"``.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from spll_hw import Network, simulate
from tests.conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

pytest.importorskip("brian2", reason="Brian2 is an optional extra: pip install -e .[brian2]")
# Brian2 2.9 calls pyparsing's camel-case API, deprecated since pyparsing 3.3.
pytestmark = pytest.mark.filterwarnings("ignore:'\\w+' (argument is )?deprecated")

from mappings.brian2 import DtResolutionWarning, dt_warnings, simulate_brian2  # noqa: E402
from mappings.brian2.run import import_brian2  # noqa: E402

DURATION = 0.1
#: Three vary-offset sPLLs on Table 6 "VibTac vary offset LIF" parameters.
NETWORK = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [250.0, 400.0, 600.0])
INPUT = poisson_train(400.0, DURATION, seed=1)


def nearest_spike_error(golden: list[np.ndarray], other: list[np.ndarray]) -> float:
    """Mean distance [s] from each golden spike to the nearest spike of the same sPLL in
    ``other`` (a missing spike train counts as the run length)."""
    errors = []
    for g, o in zip(golden, other, strict=True):
        if o.size == 0:
            errors.append(np.full(g.size, DURATION))
            continue
        k = np.clip(np.searchsorted(o, g), 1, max(o.size - 1, 1))
        errors.append(np.minimum(np.abs(g - o[k - 1]), np.abs(g - o[np.minimum(k, o.size - 1)])))
    return float(np.concatenate(errors).mean())


def count_error(golden: np.ndarray, other: np.ndarray) -> float:
    """Relative spike-count error summed over sPLLs, ``sum |n - n_golden| / sum n_golden``."""
    return float(np.abs(other - golden).sum() / golden.sum())


@pytest.fixture(scope="module")
def golden():
    return simulate(NETWORK, INPUT, DURATION)


@pytest.fixture(scope="module")
def sweep():
    """Brian2 (numpy target, exact integration) at a step ``dt`` [s], each step run once a
    module and only when a test asks for it (1 us takes about a minute: the slow tier's)."""
    return cache(lambda dt: simulate_brian2(NETWORK, INPUT, DURATION, dt=dt))


def test_result_type_and_info(sweep):
    result = sweep(10e-6)
    assert result.backend == "brian2-numpy"
    assert result.tde_counts.shape == (3,) and result.tde_counts.dtype == np.int64
    assert [s.size for s in result.tde_spikes] == list(result.tde_counts)
    assert [s.size for s in result.cco_spikes] == list(result.cco_counts)
    assert all(np.all(np.diff(s) >= 0) and np.all(s < DURATION) for s in result.tde_spikes)
    assert result.info["dt"] == 10e-6 and result.info["n_steps"] == 10_000
    assert result.info["n_input_spikes"] == INPUT.size
    assert result.info["warnings"] == []
    assert result.wall_time > 0 and result.info["timing"]["setup_and_codegen"] > 0


def test_error_shrinks_with_dt(golden, sweep):
    coarse, mid, fine = (sweep(dt) for dt in (100e-6, 10e-6, 1e-6))
    tde_time = [nearest_spike_error(golden.tde_spikes, r.tde_spikes) for r in (coarse, mid, fine)]
    cco_time = [nearest_spike_error(golden.cco_spikes, r.cco_spikes) for r in (coarse, mid, fine)]
    # Spike-time errors fall about in proportion to dt (a free-running CCO loses up to one step
    # per period, so they grow along the run: ~20 us for TDE spikes after 0.1 s at 1 us).
    for errors in (tde_time, cco_time):
        assert errors[0] > 2 * errors[1] > 10 * errors[2], errors
    assert tde_time[2] < 30e-6 and cco_time[2] < 20e-6
    counts = [count_error(golden.tde_counts, r.tde_counts) for r in (coarse, mid, fine)]
    assert counts[0] > 0.02 and counts[0] >= counts[1] >= counts[2], counts
    np.testing.assert_array_equal(fine.tde_counts, golden.tde_counts)
    np.testing.assert_array_equal(fine.cco_counts, golden.cco_counts)


def test_no_input_no_tde_spikes_and_cco_free_runs_at_eq6():
    dt = 10e-6
    result = simulate_brian2(NETWORK, [], DURATION, dt=dt)
    assert result.tde_counts.sum() == 0
    for spikes, params in zip(result.cco_spikes, NETWORK.spll, strict=True):
        period = 1.0 / params.free_frequency()
        # Brian2 stamps a spike with the start of the step it fell in and counts the refractory
        # period from there, so each free-running period is up to one step short (a crossing
        # exactly on a step edge, as at 250 Hz here, belongs to the step before).
        isi = np.diff(spikes)
        assert isi.size >= 20
        tol = 1e-9 * period
        assert np.all(isi <= period + tol) and np.all(isi >= period - dt - tol), (period, isi)
        charge = period - params.t_cco_refr  # from rest at t = 0 there is no refractory period
        assert charge - dt - tol <= spikes[0] <= charge + tol


def test_cco_spike_meets_facilitation_from_before_a_simultaneous_input():
    """A CCO spike and an input in the same step: the trigger sees I_fac without that input."""
    params = replace(
        VIBTAC_VARY_OFFSET_LIF, tau_tde_fac=2e-4, g_tde_fac=1e3, g_tde_trg=1e3, g_cco=0.0
    ).with_free_frequency(93.0)  # its first spike falls inside a step, not on its edge
    dt = 10e-6
    first_cco = simulate(params, [], 0.05).cco_spikes[0][0]
    together = simulate_brian2(params, [first_cco], 0.02, dt=dt)
    assert together.cco_spikes[0][0] == pytest.approx(np.floor(first_cco / dt) * dt)
    assert together.tde_counts[0] == 0
    assert simulate(params, [first_cco], 0.02).tde_counts[0] == 0
    # One step earlier the input is there before the CCO spike, and the TDE fires at once.
    earlier = simulate_brian2(params, [first_cco - dt], 0.02, dt=dt)
    assert earlier.tde_counts[0] >= 1
    assert earlier.tde_spikes[0][0] - first_cco < 5 * dt


def test_dense_input_several_spikes_per_step():
    """Three inputs inside one step all reach the facilitatory synapse in that step (Brian2
    lets a generator neuron fire once per step, so they go through three)."""
    dt = 10e-6
    centres = (np.floor(INPUT / dt) + 0.5) * dt
    burst = np.sort(np.r_[centres, centres + 1e-7, centres + 2e-7])
    triple_gain = Network(tuple(replace(p, g_tde_fac=3 * p.g_tde_fac) for p in NETWORK.spll))
    a = simulate_brian2(NETWORK, burst, DURATION, dt=dt)
    b = simulate_brian2(triple_gain, centres, DURATION, dt=dt)
    np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
    assert a.info["n_input_spikes"] == burst.size


def test_unresolved_time_step_is_flagged():
    dt = 3e-4  # tau_tde_trg = 1.25 ms is ~4 steps, the 1 ms refractory periods 3.33 steps
    with pytest.warns(DtResolutionWarning) as caught:
        result = simulate_brian2(NETWORK, INPUT, DURATION, dt=dt)
    messages = result.info["warnings"]
    assert {str(w.message) for w in caught} >= set(messages)
    text = " ".join(messages)
    for name in ("tau_tde_trg =", "t_cco_refr =", "t_tde_refr =", "duration"):
        assert name in text
    assert "not a multiple of dt" in text and "becomes 0.0009 s" in text
    for name in ("tau_cco =", "tau_cco_syn =", "tau_tde_fac =", "tau_tde ="):
        assert name not in text  # all longer than 10 dt = 3 ms
    assert dt_warnings(NETWORK.matrix(), 10e-6, DURATION) == []


def test_equal_time_constants_are_flagged_not_silently_wrong():
    params = replace(VIBTAC_VARY_OFFSET_LIF, tau_cco_syn=VIBTAC_VARY_OFFSET_LIF.tau_cco)
    net = Network.vary_offset(params, [300.0])
    with pytest.warns(DtResolutionWarning):
        result = simulate_brian2(net, INPUT, DURATION, dt=10e-6)
    text = " ".join(result.info["warnings"])
    assert "tau_cco and tau_cco_syn are equal" in text
    assert "NaN or infinite" in text
    assert simulate(net, INPUT, DURATION).cco_counts[0] > 0  # the golden model copes


def test_bad_arguments():
    with pytest.raises(ValueError, match="unknown Brian2 target"):
        simulate_brian2(NETWORK, INPUT, DURATION, target="cuda")
    with pytest.raises(ValueError, match="sorted"):
        simulate_brian2(NETWORK, INPUT[::-1], DURATION)
    with pytest.raises(ValueError, match="dt"):
        simulate_brian2(NETWORK, INPUT, DURATION, dt=0.0)


def test_missing_brian2_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "brian2", None)
    with pytest.raises(ImportError, match=r"pip install -e \.\[brian2\]"):
        import_brian2()


def _same_spikes(result, reference):
    np.testing.assert_array_equal(result.tde_counts, reference.tde_counts)
    np.testing.assert_array_equal(result.cco_counts, reference.cco_counts)
    for a, b in zip(result.tde_spikes, reference.tde_spikes, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)


def test_cpp_standalone_matches_numpy(sweep):
    """The compiled C++ target runs the same model: same spikes as the numpy target, also
    when the process's project is rebuilt for another input of the same batch size, which
    rewrites and recompiles no code object (only the files that hold the inputs' sizes)."""
    from mappings.brian2.run import standalone_root

    result = simulate_brian2(NETWORK, INPUT, DURATION, dt=10e-6, target="cpp_standalone")
    assert result.backend == "brian2-cpp_standalone"
    _same_spikes(result, sweep(10e-6))
    timing = result.info["timing"]
    assert 0 < result.wall_time <= timing["binary"] and timing["compile"] > 0

    kept = {p: p.stat().st_mtime_ns for p in standalone_root().glob("*/code_objects/*")}
    kept |= {p: p.stat().st_mtime_ns for p in standalone_root().glob("*/objects.h")}
    assert len(kept) > 10
    short = INPUT[: INPUT.size // 3]
    again = simulate_brian2(NETWORK, short, DURATION, dt=10e-6, target="cpp_standalone")
    _same_spikes(again, simulate_brian2(NETWORK, short, DURATION, dt=10e-6))
    assert again.tde_counts.sum() < result.tde_counts.sum()
    assert {p: p.stat().st_mtime_ns for p in kept} == kept


def test_a_forked_worker_builds_in_its_own_projects(monkeypatch, tmp_path):
    """Projects inherited from a parent process (another root) are neither reused nor deleted:
    the worker gets a project under its own root."""
    from mappings.brian2 import run

    parents = tmp_path / "standalone-parent"
    inherited = {("shape", k): parents / str(k) for k in range(run.KEPT_PROJECTS)}
    for project in inherited.values():
        project.mkdir(parents=True)
    monkeypatch.setattr(run, "_projects", run.OrderedDict(inherited))
    project = run.standalone_project(("shape", 0))
    assert project.parent == run.standalone_root() and project.is_dir()
    assert all(p.is_dir() for p in inherited.values())
    assert list(run._projects.values()) == [project]
