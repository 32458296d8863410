"""Bad input to the Python API: every refusal names the argument and its range, never a bare
OverflowError, TypeError or empty MemoryError; runs that are almost surely a mistake warn."""

from __future__ import annotations

import pickle
import subprocess
import sys
import warnings
from dataclasses import replace

import numpy as np
import pytest

from spll_hw import (
    EngineState,
    Network,
    SilentNetworkWarning,
    SpllParams,
    UnverifiedStateWarning,
    backends,
    limits,
    network_frequencies,
    simulate,
    simulate_batch,
)

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

P = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(100.0)
#: The README's Python API example: parameters tuned for a vary-offset network.
README_BASE = SpllParams(
    tau_cco_syn=7.5e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=615.0,
)  # fmt: skip
README_FREQS = network_frequencies(56.2, 668.0, n=50, beta=np.inf)
README_SPIKES = np.sort(np.random.default_rng(0).uniform(0, 2.0, 600))


# ------------------------------------------------------------------------ network and layout
@pytest.mark.parametrize("scale", [np.nan, -1.0, 0.0, np.inf])
def test_a_network_refuses_a_scale_that_is_not_finite_and_positive(scale):
    with pytest.raises(ValueError, match=rf"Network scales\[1\] = {scale!r}: a time scale must"):
        Network((P, P), scales=[1.0, scale])


@pytest.mark.parametrize("n", [2.5, 3.0, "3", True, None])
def test_network_frequencies_refuses_a_non_integer_count(n):
    message = f"number of sPLLs n must be a whole number >= 1, got {n!r}"
    with pytest.raises(ValueError, match=message):
        network_frequencies(56.2, 668.0, n=n)


def test_network_frequencies_takes_numpy_integers():
    np.testing.assert_array_equal(network_frequencies(1.0, 3.0, n=np.int64(3)), [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="n must be >= 1, got 0"):
        network_frequencies(1.0, 3.0, n=np.int32(0))


# --------------------------------------------------------------------------------- parameters
def test_params_take_any_real_number_and_name_what_is_not_one():
    p = SpllParams(**(VIBTAC_VARY_OFFSET_LIF.to_dict() | {"tau_cco": np.float32(0.3)}))
    assert p.tau_cco == float(np.float32(0.3)) and type(p.tau_cco) is float
    assert SpllParams(**(p.to_dict() | {"g_cco": np.int64(9)})).g_cco == 9.0
    with pytest.raises(ValueError, match=r"SpllParams.tau_cco must be a real number, got '0.3'"):
        SpllParams(**(p.to_dict() | {"tau_cco": "0.3"}))
    with pytest.raises(ValueError, match="SpllParams.g_cco must be finite"):
        SpllParams(**(p.to_dict() | {"g_cco": 10**400}))


# ----------------------------------------------------------------------- simulate's arguments
@pytest.mark.parametrize("max_events", [-1, 0, 2**64, None, 1.5, True])
def test_max_events_out_of_range_or_not_an_integer_is_named_with_its_range(max_events):
    for run in (lambda: simulate(P, [0.1], 1.0, max_events=max_events),
                lambda: simulate_batch(P, [[0.1]], 1.0, max_events=max_events)):  # fmt: skip
        with pytest.raises(ValueError, match=r"max_events must be .*1 \.\. 2\*\*64 - 1"):
            run()
    assert simulate(P, [0.1], 1.0, max_events=np.uint64(2**64 - 1)).cco_counts[0] > 0


@pytest.mark.parametrize("seed", [-1, 1.5, "0"])
def test_a_bad_seed_is_named_with_its_range(seed):
    message = rf"seed must be None or an integer >= 0 \(a numpy.random seed\), got {seed!r}"
    with pytest.raises(ValueError, match=message):
        simulate(P, [0.1], 1.0, noise_sigma=1e-3, seed=seed)
    with pytest.raises(ValueError, match=message):
        simulate(P, [0.1], 1.0, seed=seed)  # refused even when no noise uses it
    with pytest.raises(ValueError, match=message):
        simulate_batch(P, [[0.1]], 1.0, noise_sigma=1e-3, seed=seed)
    with pytest.raises(ValueError, match=message):
        backends.get("golden-fixed-point").simulate_batch(P, [[0.1]], 1.0, seed=seed)


# -------------------------------------------------------------------------------- saved state
@pytest.mark.parametrize(
    "values,got", [(None, "None"), (np.zeros((2, 3)), r"shape \(2, 3\)"), ("x", "'x'")]
)
def test_an_engine_state_says_what_it_expects(values, got):
    with pytest.raises(ValueError, match=rf"EngineState.values must be a float array of shape "
                       rf"\(n_spll, 13\), a result's final_state.values; got {got}"):  # fmt: skip
        EngineState(values)


def test_a_state_time_that_is_not_a_time_is_named_before_any_estimate():
    """t = -1e300 made the run look 1e300 s long: the recording estimate refused it first."""
    net = Network.vary_offset(P, network_frequencies(56.2, 668.0, 50))
    first = simulate(net, [0.1], 0.5)
    values = first.final_state.values.copy()
    values[:, 0] = -1e300
    with pytest.raises(ValueError, match=r"saved state of sPLL 0: t = -1e\+300 must be a finite"):
        simulate(net, [0.6], 1.0, state=replace(first.final_state, values=values))


def _two_halves(net: Network, other: Network):
    x = poisson_train(300, 1.0, seed=3)
    first = simulate(net, x[x <= 0.5], 0.5)
    return x, first, lambda state, on=other: simulate(on, x[x > 0.5], 1.0, state=state)


def test_a_state_resumed_on_another_network_is_refused():
    """A network that differs only in g_tde_fac: the state names the network it belongs to."""
    net = Network.vary_offset(P, [80.0, 300.0])
    other = Network(tuple(replace(p, g_tde_fac=p.g_tde_fac * 1.01) for p in net.spll))
    x, first, resume = _two_halves(net, other)
    fingerprint = first.final_state.network
    assert isinstance(fingerprint, str) and len(fingerprint) == 16
    with pytest.raises(ValueError, match=f"belongs to another network \\(fingerprint "
                       f"{fingerprint}\\) than this one .*parameters or gate differ"):  # fmt: skip
        resume(first.final_state)
    # The state survives a pickle with its fingerprint, and resumes its own network silently.
    state = pickle.loads(pickle.dumps(first.final_state))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rest = resume(state, on=net)
    np.testing.assert_array_equal(rest.final_state.values, simulate(net, x, 1.0).final_state.values)
    assert rest.final_state.network == fingerprint


def test_a_state_without_a_fingerprint_resumes_with_a_warning():
    """A state pickled before fingerprints (no ``network`` attribute) or built from values:
    accepted, with an UnverifiedStateWarning, and still resumed bit for bit."""
    net = Network.vary_offset(P, [80.0, 300.0])
    x, first, resume = _two_halves(net, net)
    old = object.__new__(EngineState)
    object.__setattr__(old, "values", first.final_state.values)  # what an old pickle restores
    for state in (pickle.loads(pickle.dumps(old)), EngineState(first.final_state.values)):
        with pytest.warns(UnverifiedStateWarning, match="carries no network fingerprint"):
            rest = resume(state)
        np.testing.assert_array_equal(rest.tde_counts + first.tde_counts,
                                      simulate(net, x, 1.0).tde_counts)  # fmt: skip


def test_the_gate_is_part_of_the_fingerprint():
    net = Network.vary_offset(P, [80.0, 300.0])
    gate = (np.full((2, 1), 1e-9), np.full((2, 1), 1.0))
    first = simulate(net, [0.1], 0.5, gate=gate)
    assert first.final_state.network != simulate(net, [0.1], 0.5).final_state.network
    with pytest.raises(ValueError, match="belongs to another network"):
        simulate(net, [0.6], 1.0, state=first.final_state)  # without the gate


# ------------------------------------------------------------------------------------- memory
def test_a_memory_error_says_what_ran_out_and_what_to_do(monkeypatch):
    def exhausted(self):
        raise MemoryError

    monkeypatch.setattr(Network, "matrix", exhausted)
    for run in (lambda: simulate(P, [0.1], 1.0), lambda: simulate_batch(P, [[0.1]], 1.0)):
        message = (
            r"out of memory building the parameter matrix of 1 sPLLs: it needs about 600 B, and "
            r".* is available; use fewer"
        )
        with pytest.raises(MemoryError, match=message):
            run()


def test_an_address_space_limit_is_the_memory_available():
    """Under ``ulimit -v`` the estimates measure against the address space left, so a run the
    engine could not allocate (a Rust allocation failure aborts the process) is refused up
    front, naming what it needs, and the process lives on."""
    code = (
        "import resource, numpy as np\n"
        "from spll_hw import Network, limits, network_frequencies, simulate\n"
        "from tests.conftest import VIBTAC_VARY_OFFSET_LIF as P\n"
        "net = Network.vary_offset(P, network_frequencies(56.2, 668.0, 50))\n"
        "left = limits.address_space_left()\n"
        "mapped = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (mapped + 2**30, resource.RLIM_INFINITY))\n"
        "print(left is None, 2**29 < limits.address_space_left() <= 2**30)\n"
        "print(limits.available_memory() <= 2**30)\n"
        "try:\n"
        "    simulate(net, [], 7000.0)\n"
        "except ValueError as exc:\n"
        "    print(exc)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[:2] == ["True True", "True"], done.stdout
    assert lines[2].startswith("recording the spikes of 50 sPLLs for 7000 s"), done.stdout
    assert "record counts only" in lines[2]
    assert limits.address_space_left() is None  # this process has no limit


# ------------------------------------------------------------------------------ silent runs
def test_the_readme_grouped_network_warns_that_no_tde_fires():
    net = Network.grouped(README_BASE, README_FREQS, 4)
    with pytest.warns(SilentNetworkWarning) as record:
        result = simulate(net, README_SPIKES, 2.0)
    assert not result.tde_counts.any()
    (message,) = [str(w.message) for w in record]
    assert message.startswith("50 of 50 sPLLs gave no TDE spike from 600 input spikes")
    assert "time-scaled and grouped layouts divide each sPLL's time constants" in message


def test_a_network_whose_ccos_never_fire_warns():
    """``SpllParams`` alone has offset current 0: its CCO never fires, nor then its TDE."""
    with pytest.warns(SilentNetworkWarning, match=r"1 of 1 sPLLs gave no CCO spike in 2 s.*"
                      r"i_cco_offset = 0") as record:  # fmt: skip
        simulate(README_BASE, README_SPIKES, 2.0)
    assert "TDE" not in str(record[0].message)


def test_a_network_at_its_refractory_limit_warns():
    fast = Network.vary_offset(README_BASE, [200.0, 300.0])
    fast = Network(tuple(replace(p, i_cco_offset=1e6) for p in fast.spll))
    with pytest.warns(SilentNetworkWarning, match="2 of 2 sPLLs fired at their refractory limit"):
        simulate(fast, README_SPIKES, 2.0)


def test_sound_or_sparse_runs_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(Network.vary_offset(README_BASE, README_FREQS), README_SPIKES, 2.0)
        sparse = poisson_train(50, 1.0, seed=0)  # slower than every sPLL: silence is no mistake
        simulate(Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668, 8)),
                 sparse, 1.0)  # fmt: skip
        simulate(README_BASE.with_free_frequency(100.0), [], 0.01)  # shorter than two periods
