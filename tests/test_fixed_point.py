"""The discrete-time fixed-point reference: quantize report, bit-exact semantics, convergence.

``reference`` below re-implements the integer model from its specification (module docs of
``engine/src/fixed_point.rs``) in plain Python integers, independently of the Rust code.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import quantize
from mappings.fixed_point.backend import FixedPointBackend
from quantize import FIXED_PARAM_NAMES, generic_fixed_point
from spll_hw import Network, SpllParams, _engine, network_frequencies, periodic_spikes, simulate

from .conftest import BIOTAC_TIME_SCALED_TOUCHSIM, VIBTAC_VARY_OFFSET_LIF, poisson_train


def simulate_fixed_point(network, x, duration, profile="loihi2", dt=None, **kwargs):
    """One train through the ``golden-fixed-point`` backend of ``profile``."""
    return FixedPointBackend(profile=profile, dt=dt).simulate(network, x, duration, **kwargs)


def reference(fixed: quantize.FixedPointNetwork, inputs, duration: float):
    """Per sPLL: TDE spike steps, CCO spike steps, final state (9 ints), saturations (5)."""
    top = 2 ** (fixed.state_bits - 1) - 1
    unity = 2**fixed.decay_bits
    n_steps = round(duration / fixed.dt)
    arrivals: dict[int, int] = {}
    for t in inputs:
        k = max(1, math.ceil(t / fixed.dt))
        arrivals[k] = arrivals.get(k, 0) + 1
    out = []
    for row in fixed.matrix.tolist():
        p = dict(zip(FIXED_PARAM_NAMES, row, strict=True))
        sat = [0] * 5

        def clip(x, k, _sat=sat):
            if x > top:
                _sat[k] += 1
                return top
            return x

        def decay(x, delta):
            return x * (unity - delta) // unity

        f = g = vt = rt = u = vc = rc = 0
        tde_prev = cco_prev = False
        tde, cco = [], []
        for k in range(1, n_steps + 1):
            gate = (f * p["trg_mantissa"]) >> p["trg_shift"] if cco_prev else 0
            f = clip(decay(f, p["fac_decay"]) + arrivals.get(k, 0) * p["fac_weight"], 0)
            g = clip(decay(g, p["trg_decay"]) + gate, 1)
            tde_spike = False
            if rt > 0:
                rt -= 1
            else:
                vt = clip(decay(vt, p["tde_decay"]) + (g >> p["tde_current_shift"]), 2)
                if vt > p["tde_threshold"]:
                    vt, rt, tde_spike = 0, p["tde_refr"], True
            u = clip(decay(u, p["cco_syn_decay"]) + (p["cco_weight"] if tde_prev else 0), 3)
            cco_spike = False
            if rc > 0:
                rc -= 1
            else:
                drive = (u + p["cco_bias"]) >> p["cco_current_shift"]
                vc = clip(decay(vc, p["cco_decay"]) + drive, 4)
                if vc > p["cco_threshold"]:
                    vc, rc, cco_spike = 0, p["cco_refr"], True
            tde_prev, cco_prev = tde_spike, cco_spike
            if tde_spike:
                tde.append(k)
            if cco_spike:
                cco.append(k)
        state = [f, g, vt, rt, u, vc, rc, int(tde_prev), int(cco_prev)]
        out.append((tde, cco, state, sat))
    return out


def vary_offset(n: int, base: SpllParams = VIBTAC_VARY_OFFSET_LIF) -> Network:
    return Network.vary_offset(base, network_frequencies(56.2, 668.0, n))


def steps(times: np.ndarray, dt: float) -> list[int]:
    return [round(t / dt) for t in times]


@pytest.mark.parametrize(
    ("network", "profile", "rate", "duration"),
    [
        (vary_offset(3), "loihi2", 600.0, 0.08),
        (vary_offset(2), generic_fixed_point(20, 3e-5), 400.0, 0.15),
        (vary_offset(2, BIOTAC_TIME_SCALED_TOUCHSIM), "fixed16", 500.0, 0.2),
    ],
)
def test_rust_matches_the_pure_python_reference_bit_for_bit(network, profile, rate, duration):
    q = quantize.quantize(network, profile)
    x = poisson_train(rate, duration, seed=4)
    result = simulate_fixed_point(network, x, duration, profile)
    expected = reference(q.fixed, x, duration)
    for i, (tde, cco, state, sat) in enumerate(expected):
        assert steps(result.tde_spikes[i], q.fixed.dt) == tde
        assert steps(result.cco_spikes[i], q.fixed.dt) == cco
        assert result.info["state"][i].tolist() == state
        assert result.info["saturations"][i].tolist() == sat
    assert sum(len(t) for t, *_ in expected) > 0, "the TDE must fire for the check to bite"
    if profile == "fixed16":
        assert sum(sum(s) for *_, s in expected) > 0, "this case exercises saturation"
    if isinstance(profile, quantize.FixedPointProfile):
        assert q.fixed["tde_current_shift"].max() > 0, "this case exercises current shifts"


def test_deterministic_and_batch_equals_single_runs():
    net, backend = vary_offset(6), FixedPointBackend()
    trains = [poisson_train(300.0, 0.3, seed=s) for s in range(3)]
    single = [simulate_fixed_point(net, x, 0.3) for x in trains]
    again = simulate_fixed_point(net, trains[0], 0.3, threads=1)
    batch = backend.simulate_batch(net, trains, 0.3, record_spikes=True, threads=2)
    for a, b in zip(single, batch, strict=True):
        np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
        np.testing.assert_array_equal(a.info["state"], b.info["state"])
        for s, t in zip(a.tde_spikes, b.tde_spikes, strict=True):
            np.testing.assert_array_equal(s, t)
    np.testing.assert_array_equal(again.info["state"], single[0].info["state"])
    assert single[0].backend == "golden-fixed-point" and single[0].info["n_steps"] == 30_000
    noisy = backend.simulate_batch(net, trains, 0.3, noise_sigma=1e-4, seed=7)
    noisy_again = backend.simulate_batch(net, trains, 0.3, noise_sigma=1e-4, seed=7)
    assert [r.tde_counts.tolist() for r in noisy] == [r.tde_counts.tolist() for r in noisy_again]


def test_inputs_arrive_in_the_step_they_happen_in():
    dt = 1e-5
    np.testing.assert_array_equal(
        quantize.spike_steps([0.0, 0.5 * dt, dt, 1.5 * dt, 3.2 * dt], dt), [1, 1, 1, 2, 4]
    )


def test_report_values_are_what_the_integers_represent():
    profile = quantize.load_profile("loihi2")
    net = vary_offset(50)
    q = quantize.quantize(net, profile)
    fx, dt = q.fixed, profile.dt
    assert fx.matrix.shape == (50, 16) and fx.matrix.dtype == np.int64
    for tau, column in [("tau_cco_syn", "cco_syn_decay"), ("tau_cco", "cco_decay"),
                        ("tau_tde_fac", "fac_decay"), ("tau_tde_trg", "trg_decay"),
                        ("tau_tde", "tde_decay")]:  # fmt: skip
        delta = fx[column]
        assert np.all((delta >= 1) & (delta <= 4095))
        realised = np.array([getattr(p, tau) for p in q.network.spll])
        np.testing.assert_array_equal(realised, -dt / np.log1p(-delta / 4096))
        for r, d in zip(q.report.of(tau), delta, strict=True):
            exact = 4096 * -math.expm1(-dt / r.requested)
            assert r.saturated or abs(d - exact) <= 0.5
            assert r.saturated == (abs(d - exact) > 0.5)
    for name, column in [("t_cco_refr", "cco_refr"), ("t_tde_refr", "tde_refr")]:
        assert np.all(fx[column] <= 255)
        for r, k in zip(q.report.of(name), fx[column], strict=True):
            assert r.realised == k * dt and abs(k - r.requested / dt) <= 0.5

    def holds(value, mantissa_bits, exp_max):
        return any(
            value % 2**e == 0 and (value >> e) < 2 ** (mantissa_bits - 1)
            for e in range(exp_max + 1)
        )

    assert all(holds(w, 8, 13) for w in fx["cco_weight"])
    assert all(holds(b, 13, 7) for b in fx["cco_bias"])
    assert np.all(fx["trg_mantissa"] < 128) and np.all(fx["trg_shift"] <= 24)
    assert np.all(fx["cco_threshold"] == 2**22) and np.all(fx["tde_threshold"] == 2**22)
    assert np.all(fx["cco_current_shift"] == 0) and np.all(fx["tde_current_shift"] == 0)
    # Rounding errors within the formats' resolution: an 8-bit mantissa is normalised to
    # [64, 127], so a weight is off by at most half an LSB in 64.
    for name in ("g_cco", "g_tde_trg"):
        assert np.all(np.abs(q.report.rel_errors(name)) <= 1 / 128)
    for name in ("g_tde_fac", "c_cco", "c_tde", "v_cco_thr", "v_tde_thr"):
        assert np.all(q.report.rel_errors(name) == 0)
    # The calibrated CCO free-runs within one step of the requested period.
    for r in q.report.of("free_frequency"):
        assert abs(1 / r.realised - 1 / r.requested) <= dt * (1 + 1e-9)
    periods = round(0.05 / dt)
    free = simulate_fixed_point(net, [], periods * dt)
    for i, r in enumerate(q.report.of("free_frequency")):
        gaps = np.diff(free.cco_spikes[i])
        assert np.allclose(gaps, 1 / r.realised)
    # The realised offset is the continuous one with the integer CCO's period (eq. 6).
    np.testing.assert_allclose(
        q.network.free_frequencies(), [r.realised for r in q.report.of("free_frequency")],
        rtol=1e-9,
    )  # fmt: skip
    table = q.report_markdown()
    assert "| tau_cco |" in table and "clamped to the slowest decay" in table
    rows = [line for line in q.report.table(per_spll=True).splitlines() if line.startswith("| 4 |")]
    assert len(rows) == 16 and rows[0].startswith("| 4 | tau_cco_syn |")


def test_saturation_and_stiffness_are_flagged():
    params = dataclasses.replace(
        VIBTAC_VARY_OFFSET_LIF, tau_cco=10.0, tau_tde_trg=5e-7, t_tde_refr=0.01, g_cco=1e5
    )
    q = quantize.quantize(Network.single(params, free_frequency=100.0), "loihi2")
    by_name = {r.name: r for r in q.report.rows}
    assert by_name["tau_cco"].saturated and "slowest" in by_name["tau_cco"].note
    assert by_name["tau_tde_trg"].saturated and "fastest" in by_name["tau_tde_trg"].note
    assert by_name["t_tde_refr"].saturated and by_name["t_tde_refr"].realised == 255e-5
    assert by_name["g_cco"].saturated and by_name["g_cco"].realised < 1e5
    assert not by_name["tau_tde"].saturated
    assert {r.name for r in q.report.saturated()} == {"tau_cco", "tau_tde_trg", "t_tde_refr",
                                                      "g_cco"}  # fmt: skip
    assert any("not small against tau_tde_trg" in w for w in q.report.warnings)
    # A burst of 100 coincident input spikes overflows the facilitatory word (headroom 64).
    burst = np.full(100, 0.0101)
    result = simulate_fixed_point(q.requested, burst, 0.02)
    assert result.info["saturations"][0, 0] == 1
    assert any("state fac saturated 1 times" in w for w in result.info["warnings"])


def test_unrepresentable_parameters_are_errors_naming_them():
    base = VIBTAC_VARY_OFFSET_LIF
    for change, name in [({"g_cco": 1e-9}, "g_cco"), ({"g_tde_trg": 1e-12}, "g_tde_trg")]:
        net = Network.single(dataclasses.replace(base, **change), free_frequency=100.0)
        with pytest.raises(ValueError, match=f"sPLL 0: {name} = .* cannot be represented"):
            quantize.quantize(net, "loihi2")
    # An offset a hair above rheobase: the continuous CCO oscillates, the truncating integer
    # one settles just below its threshold.
    tau = 1e-3
    slow = dataclasses.replace(base, tau_cco=tau, i_cco_offset=(1 + 1e-7) / tau)
    with pytest.raises(ValueError, match="sPLL 0: i_cco_offset .* does not oscillate"):
        quantize.quantize(Network.single(slow), "loihi2", retune_offset=False)
    # An offset 1e-13 above rheobase: 30 membrane time constants to threshold, a frequency no
    # offset current can hold once tau_cco is rounded.
    rheobase = dataclasses.replace(base, tau_cco=1e-4, i_cco_offset=1e4 * (1 + 1e-13))
    with pytest.raises(ValueError, match="sPLL 0: i_cco_offset cannot hold the free-running"):
        quantize.quantize(Network.single(rheobase), "loihi2")
    with pytest.raises(ValueError, match="sPLL 0: i_cco_offset .* does not oscillate"):
        quantize.quantize(Network.single(rheobase), "loihi2", retune_offset=False)


def test_bad_calls_are_value_errors_never_panics():
    net = vary_offset(2)
    q = quantize.quantize(net, "loihi2")
    with pytest.raises(ValueError, match="analog, not fixed point"):
        simulate_fixed_point(net, [0.1], 0.2, profile="analog")
    with pytest.raises(ValueError, match="sorted"):
        simulate_fixed_point(net, [0.2, 0.1], 0.3)
    with pytest.raises(ValueError, match="1-D"):
        simulate_fixed_point(net, [[0.1]], 0.3)
    with pytest.raises(ValueError, match="noise_sigma"):
        simulate_fixed_point(net, [0.1], 0.3, noise_sigma=-1.0)
    with pytest.raises(ValueError, match="shorter than half a time step"):
        simulate_fixed_point(net, [], 1e-6)
    with pytest.raises(ValueError, match="more than the limit"):
        _engine.simulate_fixed_point(q.fixed.matrix, [np.empty(0)], 1e-5, 1.0, 24, 12, False,
                                     None, 1000)  # fmt: skip
    matrix = q.fixed.matrix.copy()
    args = ([np.empty(0)], 1e-5, 0.01, 24, 12, False)
    with pytest.raises(ValueError, match="16 columns"):
        _engine.simulate_fixed_point(matrix[:, :15].copy(), *args)
    matrix[1, FIXED_PARAM_NAMES.index("trg_shift")] = 99
    with pytest.raises(ValueError, match="sPLL 1: fixed-point parameter trg_shift = 99"):
        _engine.simulate_fixed_point(matrix, *args)
    with pytest.raises(ValueError, match="state_bits"):
        _engine.simulate_fixed_point(q.fixed.matrix, [np.empty(0)], 1e-5, 0.01, 64, 12, False)


def _run_in_pieces(fixed, x, duration, ends):
    """Steps 1 .. ``round(duration / dt)`` of ``fixed`` as one resumed call per piece ending at
    each step of ``ends``: joined TDE and CCO spike times, summed saturations, final state."""
    steps = round(duration / fixed.dt)
    tde, cco = [[] for _ in range(len(fixed.matrix))], [[] for _ in range(len(fixed.matrix))]
    saturations, state, begin = 0, None, 0
    for end in [*ends, steps]:
        arrive = np.maximum(1, np.ceil(x / fixed.dt))
        piece = x[(arrive > begin) & (arrive <= end)]
        out = _engine.simulate_fixed_point(
            fixed.matrix, [piece], fixed.dt, end * fixed.dt, fixed.state_bits, fixed.decay_bits,
            True, state=state, start_step=begin,
        )  # fmt: skip
        for i in range(len(fixed.matrix)):
            tde[i].extend(out["tde_spikes"][0][i])
            cco[i].extend(out["cco_spikes"][0][i])
        saturations = saturations + out["saturations"]
        state, begin = out["state"], end
    return tde, cco, saturations, state


@pytest.mark.parametrize("profile", ["loihi2", "fixed16"])
def test_a_run_resumed_in_pieces_is_the_whole_run_bit_for_bit(profile):
    """The state after any step continues the run exactly (the USB emulator resumes from it
    packet by packet), also when a piece holds no input or ends where inputs pile up."""
    fixed = quantize.quantize(vary_offset(20), profile).fixed
    x = np.sort(np.r_[poisson_train(800, 0.3, seed=11), np.full(5, 0.1)])
    whole = _engine.simulate_fixed_point(
        fixed.matrix, [x], fixed.dt, 0.3, fixed.state_bits, fixed.decay_bits, True
    )
    at_pile = math.ceil(0.1 / fixed.dt)
    ends = sorted({1, 2, 17, at_pile - 1, at_pile, 2 * at_pile, round(0.3 / fixed.dt) - 1})
    tde, cco, saturations, state = _run_in_pieces(fixed, x, 0.3, ends)
    assert whole["tde_counts"].sum() > 100 and whole["cco_counts"].sum() > 100
    for i in range(len(fixed.matrix)):
        np.testing.assert_array_equal(tde[i], whole["tde_spikes"][0][i])
        np.testing.assert_array_equal(cco[i], whole["cco_spikes"][0][i])
    np.testing.assert_array_equal(saturations, whole["saturations"])
    np.testing.assert_array_equal(state, whole["state"])


def test_a_resumed_run_refuses_states_and_inputs_it_cannot_continue():
    fixed = quantize.quantize(vary_offset(2), "loihi2").fixed
    args = (fixed.matrix, [np.empty(0)], fixed.dt, 0.01, fixed.state_bits, fixed.decay_bits, True)
    first = _engine.simulate_fixed_point(*args[:3], 0.005, *args[4:])
    state, step = first["state"], first["n_steps"]
    with pytest.raises(ValueError, match=r"must have shape \(samples, n_spll, 9\) = \[1, 2, 9\]"):
        _engine.simulate_fixed_point(*args, state=state[:, :1].copy(), start_step=step)
    bad = state.copy()
    bad[0, 1, 2] = fixed.matrix[1, FIXED_PARAM_NAMES.index("tde_threshold")] + 1
    with pytest.raises(ValueError, match="sample 0, sPLL 1: v_tde = .* out of range"):
        _engine.simulate_fixed_point(*args, state=bad, start_step=step)
    bad = state.copy()
    bad[0, 0, 7] = 2
    with pytest.raises(ValueError, match="sPLL 0: tde_fired = 2 is out of range"):
        _engine.simulate_fixed_point(*args, state=bad, start_step=step)
    with pytest.raises(ValueError, match="input spike 0 at 0.001 s arrives at step 100, not after"):
        _engine.simulate_fixed_point(fixed.matrix, [np.array([0.001])], *args[2:], state=state,
                                     start_step=step)  # fmt: skip
    with pytest.raises(ValueError, match="ends at step 500, not after the resumed state's step"):
        _engine.simulate_fixed_point(*args[:3], 0.005, *args[4:], state=state, start_step=step)


def test_harness_call_with_a_plain_network():
    net = vary_offset(4)
    x = poisson_train(300.0, 0.2, seed=2)
    result = simulate_fixed_point(net, x, 0.2, profile="fixed16", dt=5e-5)
    assert result.info["dt"] == 5e-5 and result.info["profile"] == "fixed16"
    assert result.tde_spikes is not None and np.isfinite(result.wall_time)
    default = simulate_fixed_point(net, x, 0.2)
    assert default.info["profile"] == "loihi2"
    q = quantize.quantize(net, "loihi2")
    direct = _engine.simulate_fixed_point(q.fixed.matrix, [x], 1e-5, 0.2, 24, 12, False)
    np.testing.assert_array_equal(default.tde_counts, direct["tde_counts"][0])


#: (state bits, dt [s]) from a coarse to a fine chip, generic fixed-point profile.
LADDER = [(16, 1e-4), (20, 3e-5), (24, 1e-5), (28, 3e-6), (32, 1e-6)]


@pytest.mark.parametrize("input_frequency", [210.0, 260.0, 300.0])
def test_converges_to_the_golden_model_on_a_locked_spll(input_frequency):
    """One sPLL locked to a periodic input (g_trg raised so single triggers fire the TDE):
    tolerance at the finest rung (32 bits, 1 µs): identical TDE count, CCO spikes within
    100 µs over 0.3 s (60 periods); the CCO's largest timing error shrinks rung by rung."""
    params = dataclasses.replace(VIBTAC_VARY_OFFSET_LIF, g_tde_trg=2.0)
    net = Network.single(params, free_frequency=200.0)
    duration = 0.3
    x = periodic_spikes(input_frequency, duration, phase=0.0013)
    golden = simulate(net, x, duration)
    worst = []
    for bits, dt in LADDER:
        fixed = simulate_fixed_point(net, x, duration, generic_fixed_point(bits, dt))
        a, b = fixed.cco_spikes[0], golden.cco_spikes[0]
        n = min(len(a), len(b))
        worst.append(np.max(np.abs(a[:n] - b[:n])))
    assert np.all(np.diff(worst) < 0), worst
    assert worst[-1] < 100e-6
    assert fixed.tde_counts[0] == golden.tde_counts[0] > 0


def test_network_tde_counts_approach_the_golden_model():
    """Ten sPLLs of the reference workload, 1 s of 300 Hz Poisson input: the total TDE count
    is within 3 % of the golden model's at 32 bits / 1 µs, and within 6 % at 16 bits / 100 µs
    (documented tolerance; TDE spikes sit on thresholds, so counts do not converge faster)."""
    net = vary_offset(10)
    x = poisson_train(300.0, 1.0, seed=0)
    golden = simulate(net, x, 1.0).tde_counts.sum()
    errors = {}
    for bits, dt in (LADDER[0], LADDER[-1]):
        fixed = simulate_fixed_point(net, x, 1.0, generic_fixed_point(bits, dt))
        errors[bits] = abs(fixed.tde_counts.sum() - golden) / golden
    assert errors[32] < 0.03 and errors[16] < 0.06, errors
