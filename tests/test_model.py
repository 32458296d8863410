"""The model stated once (spll_hw.model): the grid rules against exact rational arithmetic, the
discretisations against closed forms, and the targets that derive from the tables."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from quantize.fixed_point import encode_decay
from spll_hw import _engine
from spll_hw.model import CCO, JUMPS, NEURONS, TDE, UNITS
from spll_hw.model.discrete import (
    decay_constant,
    decay_fraction,
    exact_propagator,
    membrane_gain,
    realised_tau,
)
from spll_hw.model.grid import (
    GRID_RTOL,
    arrival_counts,
    mid_step_times,
    n_steps,
    period_steps,
    refractory_steps,
    spike_steps,
)
from spll_hw.model.holds import (
    DITHER_MIN_STEPS,
    HOLDS,
    MAX_DITHER_PERIOD,
    compensated_hold,
    counter_dither,
    fractional_hold,
)
from spll_hw.params import PARAM_NAMES

DTS = (1e-5, 5e-5, 1e-4, 2.5e-6, 1 / 3 * 1e-4)


# ------------------------------------------------------------------------------ grid
@pytest.mark.parametrize("dt", DTS)
def test_a_spike_on_a_step_end_arrives_in_that_step(dt):
    k = np.arange(1, 200_001)
    for t in (k * dt, np.nextafter(k * dt, np.inf), np.nextafter(k * dt, -np.inf)):
        assert np.array_equal(spike_steps(t, dt), k)
    # the naive ceil(t / dt) moves a share of them to the next step: the rule matters
    if dt == 1e-5:
        assert (np.ceil(k * dt / dt) != k).mean() > 0.01


@settings(max_examples=300, deadline=None)
@given(
    t=st.floats(0.0, 1e4, allow_nan=False),
    dt=st.sampled_from(DTS),
)
def test_spike_steps_is_the_first_step_end_not_before_t(t, dt):
    """Exactly ``max(1, ceil(t / dt))`` in rational arithmetic, except that a quotient within
    GRID_RTOL above a whole number is read as that number."""
    (k,) = spike_steps([t], dt)
    exact = Fraction(t) / Fraction(dt)
    want = max(1, math.ceil(exact))
    if want > 1 and exact - (want - 1) <= 2 * GRID_RTOL * exact:
        assert k in (want - 1, want)
    else:
        assert k == want


def test_arrival_counts_drops_spikes_after_the_last_step():
    dt = 1e-4
    counts = arrival_counts([0.0, 1e-4, 1.5e-4, 2e-4, 2e-4, 3e-4, 3.0001e-4, 9.0], 3, dt)
    assert counts.tolist() == [2, 3, 1]


def test_n_steps_rounds_halves_away_from_zero_and_refuses_no_step():
    assert n_steps(0.25, 0.1) == 3  # Python's round() would give 2
    assert n_steps(1.0, 1e-5) == 100_000
    assert n_steps(0.2, 5e-5) == 4000
    with pytest.raises(ValueError, match="shorter than half a time step"):
        n_steps(0.4e-5, 1e-5)


def test_refractory_steps_round_halves_up():
    assert refractory_steps([1e-3, 2.5e-5, 2.4999e-5, 0.0], 1e-5).tolist() == [100, 3, 2, 0]


def test_mid_step_times_stay_in_their_step():
    t = np.array([0.0, 1e-5, 1.5e-5, 0.49e-3, 1.0])
    mid = mid_step_times(t, 1e-5)
    assert np.array_equal(spike_steps(mid, 1e-5), spike_steps(t, 1e-5))
    assert np.allclose(mid, (spike_steps(t, 1e-5) - 0.5) * 1e-5)


def test_the_rust_core_reads_the_grid_with_pythons_tolerance():
    assert _engine.GRID_RTOL == GRID_RTOL


def _half_up(x: Fraction) -> int:
    return math.floor(x + Fraction(1, 2))


def _rounds_to(got: int, x: Fraction) -> bool:
    """``got`` is ``x`` rounded halves up, or either neighbour where ``x`` lies within 1e-12 of
    a half (the rules divide in floating point: ``0.005 / 5e-5`` is 100 there, a hair below
    100 in exact arithmetic)."""
    near_half = abs(x - math.floor(x) - Fraction(1, 2)) <= Fraction(1, 10**12) * max(1, abs(x))
    return got == _half_up(x) or (near_half and got in (math.floor(x), math.floor(x) + 1))


T_REFR = st.floats(0.0, 5e-3, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(t=T_REFR, dt=st.sampled_from(DTS))
def test_each_hold_is_its_rule_in_exact_arithmetic(t, dt):
    h = Fraction(t) / Fraction(dt)
    assert _rounds_to(int(refractory_steps([t], dt)[0]), h)
    compensated = int(compensated_hold([t], dt)[0])
    assert compensated == 0 if h <= Fraction(1, 2) else _rounds_to(compensated, h - Fraction(1, 2))
    assert fractional_hold([t], dt)[0] == pytest.approx(float(max(0, h - Fraction(1, 2))))
    assert {k: f([t], dt)[0] for k, f in HOLDS.items()} == {
        "grid": refractory_steps([t], dt)[0],
        "compensated": compensated_hold([t], dt)[0],
        "dithered": fractional_hold([t], dt)[0],
    }


@settings(max_examples=200, deadline=None)
@given(t=T_REFR, dt=st.sampled_from(DTS))
def test_a_counter_dithers_to_the_nearest_mean_a_counter_can_make(t, dt):
    """Brute force over every hold a counter can make, in exact arithmetic: ``b`` always, or
    ``b + s`` one spike in ``n`` (``s = +-1``, ``n <= 16``, ``b`` at least the counter's
    least base); the chosen one is nearest ``t/dt - 1/2`` (undithered on ties)."""
    d = counter_dither(np.array([t]), dt)
    base, step, period = int(d.base[0]), int(d.step[0]), int(d.period[0])
    mean = base + (Fraction(step, period) if period else 0)
    assert d.mean[0] == pytest.approx(float(mean))
    h = Fraction(float(fractional_hold([t], dt)[0]))
    low = math.floor(h)
    options = [Fraction(low), Fraction(low + 1)]
    for n in range(2, MAX_DITHER_PERIOD + 1):
        if low >= DITHER_MIN_STEPS[1]:
            options.append(low + Fraction(1, n))
        if low + 1 >= DITHER_MIN_STEPS[-1]:
            options.append(low + 1 - Fraction(1, n))
    best = min(abs(o - h) for o in options)
    assert abs(mean - h) <= best + Fraction(1, 10**9)


@settings(max_examples=200, deadline=None)
@given(f=st.floats(1.0, 5e3), dt=st.sampled_from(DTS), hold=st.integers(0, 300))
def test_a_free_running_period_is_the_nearest_whole_step_above_the_hold(f, dt, hold):
    exact = 1 / (Fraction(f) * Fraction(dt))
    want = max(hold + 1, _half_up(exact))
    got = int(period_steps(f, dt, hold))
    assert got == want or (got > hold + 1 and _rounds_to(got, exact))


# ------------------------------------------------------------------------------ discrete
@pytest.mark.parametrize("tau", [1e-4, 1.25e-3, 0.3, 7.0])
def test_decays_and_gains_are_the_closed_forms(tau):
    dt = 1e-5
    assert math.isclose(decay_fraction(tau, dt), 1 - math.exp(-dt / tau), rel_tol=1e-9)
    # a constant current I charges the membrane as in continuous time: v(dt) = I tau/C (1-e^-dt/tau)
    assert math.isclose(membrane_gain(tau, 2.0, dt), tau / 2.0 * -math.expm1(-dt / tau))
    arr = decay_fraction(np.array([tau, tau]), dt)
    assert np.allclose(arr, decay_fraction(tau, dt), rtol=1e-15, atol=0)


@pytest.mark.parametrize("bits", [8, 12, 16])
def test_decay_constants_round_half_up_and_realise_their_time_constant(bits):
    dt = 1e-5
    for tau in (2e-5, 1e-4, 1.25e-3, 0.05, 0.3):
        delta = decay_constant(tau, dt, bits)
        assert delta == math.floor(2**bits * -math.expm1(-dt / tau) + 0.5)
        assert np.array_equal(decay_constant(np.array([tau]), dt, bits), [delta])
        if delta:
            back = realised_tau(delta, dt, bits)
            assert decay_constant(back, dt, bits) == delta
            assert np.isclose(realised_tau(np.array([delta]), dt, bits)[0], back, rtol=1e-15)
    # the profile encoding is this rule, clamped
    assert encode_decay(0.05, dt, 12)[0] == decay_constant(0.05, dt, 12)
    assert encode_decay(1e3, dt, 12)[0] == 1 and encode_decay(1e3, dt, 12)[2]


def test_exact_propagator_matches_the_matrix_exponential():
    from scipy.linalg import expm

    tau_s, tau_m, c, dt = 1.25e-3, 22e-3, 2.0, 1e-4
    e_s, k, e_m = exact_propagator(tau_s, tau_m, c, dt)
    a = np.array([[-1 / tau_s, 0.0], [1 / c, -1 / tau_m]])  # d(I, v)/dt
    m = expm(a * dt)
    assert np.allclose([e_s, k, e_m], [m[0, 0], m[1, 0], m[1, 1]], rtol=1e-10)
    # the singular case tau_syn == tau_mem is the limit
    e_s, k, e_m = exact_propagator(tau_m, tau_m, c, dt)
    m = expm(np.array([[-1 / tau_m, 0.0], [1 / c, -1 / tau_m]]) * dt)
    assert np.allclose([e_s, k, e_m], [m[0, 0], m[1, 0], m[1, 1]], rtol=1e-10)


# ------------------------------------------------------------------------------ equations
def test_every_parameter_belongs_to_one_neuron_and_has_a_unit():
    held = [name for neuron in NEURONS for name in neuron.parameters]
    assert sorted(held) == sorted(PARAM_NAMES) == sorted(UNITS)
    for jump in JUMPS:
        target = CCO if jump.target == "cco" else TDE
        assert jump.gain in target.parameters
        currents = {s.current for s in target.synapses}
        assert jump.current in currents and (jump.factor is None or jump.factor in currents)


def test_a_cco_spike_meets_the_facilitation_from_before_same_instant_inputs():
    order = [(j.source, j.current) for j in JUMPS]
    assert order.index(("cco", "I_trg")) < order.index(("input", "I_fac"))


def test_roles_name_every_parameter_once_from_the_tables(monkeypatch):
    from spll_hw.model import equations
    from spll_hw.model.roles import roles

    r = roles()
    named = [r.gated.gain, r.driven.gain, r.fed.gain, r.offset, *r.time_constants]
    named += [getattr(m, f) for m in (r.tde, r.cco) for f in ("c", "v_thr", "t_refr")]
    assert sorted(named) == sorted(PARAM_NAMES)
    assert (r.fac.tau, r.trg.tau, r.cco_syn.tau) == ("tau_tde_fac", "tau_tde_trg", "tau_cco_syn")
    # a table whose gate is not the input's current is refused, not silently mis-built
    broken = (JUMPS[0], equations.Jump("input", "tde", "I_trg", "g_tde_fac"), JUMPS[2])
    monkeypatch.setattr(equations, "JUMPS", broken)
    roles.cache_clear()
    try:
        with pytest.raises(ValueError, match="gate is not the facilitatory current"):
            roles()
    finally:
        monkeypatch.undo()
        roles.cache_clear()
    assert roles() == r


def test_brian2_equations_are_written_from_the_model():
    from mappings.brian2.model import equations, on_pre

    cco = equations(CCO)
    assert "dI/dt = -I / tau_cco_syn : amp" in cco
    assert "dv/dt = (I + i_cco_offset) / c_cco - v / tau_cco : volt (unless refractory)" in cco
    assert "g_tde_trg : 1 (constant)" in equations(TDE)
    assert [on_pre(j) for j in JUMPS] == [
        "I_trg_post += g_tde_trg_post * I_fac_post",
        "I_fac_post += g_tde_fac_post",
        "I_post += g_cco_post",
    ]
