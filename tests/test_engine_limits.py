"""What the engine refuses up front, and how: thread counts, memory, parameters whose state would
overflow, tampered resume states, and runs that hit the event limit."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spll_hw import Network, SpllParams, _engine, backends, limits, network_frequencies, simulate
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.simulate import simulate_batch

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

P = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(100.0)
NET = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 50))
GIB = 1 << 30


@pytest.fixture
def sixteen_gib(monkeypatch):
    """Memory estimates measured against 16 GiB available (refused above a quarter of it), so
    what is refused does not depend on the machine."""
    monkeypatch.setattr(limits, "available_memory", lambda: 16 * GIB)


def quick(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``, asserted to return or raise within 2 s (refusals allocate
    nothing and start nothing)."""
    start = time.perf_counter()
    try:
        return fn(*args, **kwargs)
    finally:
        assert time.perf_counter() - start < 2.0


# ------------------------------------------------------------------------------------- threads
@pytest.mark.parametrize("threads", [10_000, limits.max_threads() + 1])
def test_thread_counts_beyond_the_cap_are_refused_before_any_start(threads):
    with pytest.raises(ValueError, match=f"threads = {threads} is more than this machine"):
        quick(simulate_batch, P, [[0.1]], 1.0, threads=threads)
    with pytest.raises(ValueError, match="threads"):
        quick(backends.get("golden-fixed-point").simulate_batch, P, [[0.1]], 1.0, threads=threads)


def test_the_bindings_cap_threads_themselves():
    """The Rust core refuses on its own, when the Python checks are bypassed."""
    matrix = Network.single(P).matrix()
    with pytest.raises(ValueError, match="more than this machine can use"):
        quick(_engine.simulate_batch, matrix, [np.array([0.1])], 1.0, False, 10**6)
    fixed = np.zeros((1, len(_engine.FIXED_PARAM_NAMES)), dtype=np.int64)
    fixed[0, _engine.FIXED_PARAM_NAMES.index("cco_threshold")] = 1000
    fixed[0, _engine.FIXED_PARAM_NAMES.index("tde_threshold")] = 1000
    with pytest.raises(ValueError, match="more than this machine can use"):
        quick(_engine.simulate_fixed_point, fixed, [np.array([0.1])], 1e-4, 1.0, 24, 12, False,
              10**6)  # fmt: skip
    assert simulate_batch(P, [[0.1]], 1.0, threads=np.int64(2))[0].duration == 1.0


# -------------------------------------------------------------------------------------- memory
def test_a_recording_bigger_than_memory_allows_is_refused(sixteen_gib):
    # 50 sPLLs for 10^4 s: up to 2 x 10^7 spikes per sPLL, 7.5 GiB of spike times.
    with pytest.raises(ValueError, match=r"recording the spikes of 50 sPLLs for 10000 s .* would "
                       r"need about 7.\d+ GiB.*record_spikes=False"):  # fmt: skip
        quick(simulate, NET, [], 1e4)
    with pytest.raises(ValueError, match="recording the spikes of 50 sPLLs for 1000 s in 10"):
        quick(simulate_batch, NET, [[]] * 10, 1e3, record_spikes=True)
    # A short recording fits.
    assert len(quick(simulate, NET, [], 0.01).cco_spikes) == 50


def test_probe_traces_bigger_than_memory_allows_are_refused(sixteen_gib):
    wide = Network((P,) * 2000)
    with pytest.raises(ValueError, match=r"probing the state of 2000 sPLLs at 100000 times "
                       r"would need about 14.9 GiB"):  # fmt: skip
        quick(simulate, wide, [], 1.0, probe_times=np.linspace(0, 1, 100_000))


def test_inputs_bigger_than_the_engine_can_copy_are_refused(monkeypatch):
    monkeypatch.setattr(limits, "available_memory", lambda: GIB // 2)
    x = np.linspace(0, 1, 10_000_000)
    with pytest.raises(ValueError, match="simulating 10000000 input spikes"):
        quick(simulate, NET, x, 1.0, record_spikes=False)


def test_network_size_must_be_a_positive_integer_and_fit(tmp_path, sixteen_gib):
    base = NetworkConfig.preset("vibtac-vary-offset-lif")
    for n in (0, -3, 2.5, True, "50", float("nan")):
        with pytest.raises(ValueError, match="n must be a whole number of sPLLs >= 1"):
            replace(base, n=n)
    assert replace(base, n=np.int64(3)).n == 3
    path = tmp_path / "net.toml"
    path.write_text(base.to_toml().replace("n = 50", "n = 10.5"))
    with pytest.raises(ValueError, match=r"net.toml \[network\]: n must be a whole number"):
        NetworkConfig.from_toml(path)
    with pytest.raises(ValueError, match=r"building a network of 10000000000 sPLLs would need"):
        quick(replace(base, n=10**10).build)


def test_cli_refuses_what_would_exhaust_memory_before_any_work(tmp_path, sixteen_gib, capsys):
    out = tmp_path / "report"
    # (The first call also imports every sub-command: it is not timed.)
    assert main(["simulate", "--periodic", "1e9", "--out", str(out)]) == 2
    assert "(2e+09 spikes) would need about 14.9 GiB" in capsys.readouterr().err
    assert quick(main, ["simulate", "--rate", "1e12", "--out", str(out)]) == 2
    assert "a Poisson input of 1e+12 Hz for 2 s (2e+12 spikes)" in capsys.readouterr().err
    # Refused before the 10^6 sPLLs are built (which would take a minute).
    path = tmp_path / "big.toml"
    base = NetworkConfig.preset("vibtac-vary-offset-lif")
    path.write_text(base.to_toml().replace("n = 50", "n = 1000000"))
    assert quick(main, ["simulate", "--network", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spll-hw simulate: error: probing the state of 1000000 sPLLs")
    assert "use fewer sPLLs (n in the [network] table)" in err
    assert not out.exists()


# --------------------------------------------------------------------------------- parameters
@pytest.mark.parametrize(
    "changes,name",
    [
        ({"c_tde": 5e-324}, "c_tde"),
        ({"tau_tde_fac": 1e-320}, "tau_tde_fac"),
        ({"tau_cco": 1e-200, "tau_cco_syn": 1e-200}, "tau_cco_syn"),
        ({"g_tde_fac": 1e308}, "g_tde_fac"),
        ({"g_tde_fac": 1e60, "g_tde_trg": 1e60}, "g_tde_trg"),
        ({"i_cco_offset": 1e90, "tau_cco": 1e20}, "i_cco_offset"),
        ({"g_cco": 1e80, "c_cco": 1e-30}, "g_cco"),
    ],
)
def test_parameters_whose_state_would_overflow_are_refused_naming_one(changes, name):
    with pytest.raises(ValueError, match=f"sPLL 0: parameter {name}"):
        simulate(replace(P, **changes), [0.1, 0.2], 0.5)


EXTREME = st.sampled_from([5e-324, 1e-310, 1e-300, 1e-200, 1e-100, 1e-60, 1e-20, 1e20, 1e60,
                           1e100, 1e200, 1e300, 1.7e308])  # fmt: skip
NAMES = list(_engine.PARAM_NAMES)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(st.sampled_from(NAMES), EXTREME, min_size=1, max_size=5))
def test_extreme_parameters_give_an_error_naming_one_or_finite_results(changes):
    """Any mix of extreme values: refused naming a parameter (or the event limit), or every
    spike time, final state value and probe finite."""
    matrix = Network.single(P).matrix()
    for name, value in changes.items():
        matrix[0, NAMES.index(name)] = value
    x = np.sort(np.concatenate([poisson_train(300, 0.2, seed=1), [0.1] * 20]))
    try:
        out = _engine.simulate(matrix, x, 0.2, True, None, np.linspace(0, 0.2, 20), 100_000)
    except ValueError as exc:
        assert any(f"parameter {n}" in str(exc) for n in NAMES) or "events" in str(exc), exc
        return
    for spikes in (out["tde_spikes"][0], out["cco_spikes"][0]):
        assert np.all(np.isfinite(spikes)) and np.all((spikes >= 0) & (spikes <= 0.2))
    state = out["state"][0]
    assert not np.isnan(state).any() and np.isfinite(np.delete(state, [6, 7, 11, 12])).all()
    assert np.isfinite(out["trace"]).all()


# --------------------------------------------------------------------------------- resume state
def first_half() -> tuple[Network, np.ndarray, object]:
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [80.0, 300.0])
    x = poisson_train(300, 1.0, seed=4)
    return net, x, simulate(net, x[x <= 0.5], 0.5)


@pytest.mark.parametrize(
    "field,value",
    [("t", np.nan), ("t", -1.0), ("fac_t", 0.9), ("fac_i", -1.0), ("tde_t0", np.inf),
     ("tde_v0", 5.0), ("tde_i0", 1e300), ("cco_refr_end", np.inf), ("tde_next_spike", -1.0),
     ("cco_next_spike", np.nan), ("cco_next_spike", 0.5), ("tde_refr_end", 100.0)],
)  # fmt: skip
def test_a_tampered_state_is_refused_naming_the_field_and_spll(field, value):
    net, x, first = first_half()
    values = first.final_state.values.copy()
    values[1, _engine.STATE_NAMES.index(field)] = value
    with pytest.raises(ValueError, match=f"saved state of sPLL 1: {field} = "):
        quick(simulate, net, x[x > 0.5], 1.0, state=replace(first.final_state, values=values))


@settings(max_examples=200, deadline=None)
@given(
    st.integers(0, 1),
    st.sampled_from(_engine.STATE_NAMES),
    st.one_of(st.floats(allow_nan=True), st.floats(-1e-6, 1e-6)),
)
def test_no_tampered_state_gives_spikes_outside_the_run(spll, field, delta):
    """Any one value moved (or replaced by an arbitrary float): refused, naming a value of that
    sPLL, or a run whose spikes all lie after the state's time."""
    net, x, first = first_half()
    values = first.final_state.values.copy()
    k = _engine.STATE_NAMES.index(field)
    values[spll, k] = values[spll, k] + delta if abs(delta) <= 1e-6 else delta
    state = replace(first.final_state, values=values)
    try:
        result = quick(simulate, net, x[x > 0.5], 1.0, state=state)
    except ValueError as exc:
        allowed = ("saved state of sPLL", "saved state mixes", "not after the resumed state's",
                   "must end after")  # fmt: skip
        assert any(a in str(exc) for a in allowed), exc
        return
    begin = values[0, 0]
    for spikes in (*result.tde_spikes, *result.cco_spikes):
        assert np.all((spikes > begin) & (spikes <= 1.0))


@settings(max_examples=30, deadline=None)
@given(st.floats(0.01, 0.99), st.booleans())
def test_states_saved_anywhere_are_accepted_and_resume_bit_for_bit(split, at_spike):
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, [60.0, 250.0, 600.0])
    x = poisson_train(400, 1.0, seed=2)
    whole = simulate(net, x, 1.0)
    if at_spike:  # the state of a run that ends exactly at a spike
        spikes = whole.tde_spikes[1]
        assert spikes.size
        split = float(spikes[np.searchsorted(spikes, split) % spikes.size])
    first = simulate(net, x[x <= split], split)
    rest = simulate(net, x[x > split], 1.0, state=first.final_state)
    np.testing.assert_array_equal(rest.final_state.values, whole.final_state.values)
    np.testing.assert_array_equal(first.tde_counts + rest.tde_counts, whole.tde_counts)


# --------------------------------------------------------------------------------- event limit
def test_the_event_limit_says_the_run_is_long():
    message = r"sPLL 0: more than 1000 events by t = .* the run is long, and all of it \(100 s\)"
    with pytest.raises(ValueError, match=message + r" needs about .* raise max_events"):
        simulate(P, poisson_train(300, 100.0, seed=0), 100.0, max_events=1000)


def test_the_event_limit_says_the_parameters_run_away():
    runaway = SpllParams(
        tau_cco_syn=1.0, tau_cco=1.0, tau_tde_trg=10.0, tau_tde_fac=10.0, tau_tde=10.0,
        g_cco=1.0, g_tde_trg=1e6, g_tde_fac=1e6, t_tde_refr=0.0, t_cco_refr=0.0,
    ).with_free_frequency(1000.0)  # fmt: skip
    with pytest.raises(ValueError, match=r"events/s\): a neuron fires faster than the simulation "
                       r"can resolve \(its refractory periods allow 200000 events/s; raise "
                       r"t_tde_refr or t_cco_refr"):  # fmt: skip
        simulate(runaway, [0.001], 0.01, max_events=100_000)
