"""The time step of ``--to nir-standard`` without ``--dt`` (mappings/nir/dt_choice.py): the
coarsest step whose check passes, or a refusal naming the sPLLs and the clock's own floor."""

from __future__ import annotations

import numpy as np
import pytest

from spll_hw import Network
from spll_hw.config import NetworkConfig

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import dt_choice  # noqa: E402


def test_the_coarsest_step_whose_check_passes_is_chosen(monkeypatch):
    """Each step with the export's placements in order: the first that passes is written."""
    tried = []

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        tried.append((dt, placement, levels))
        passes = dt <= 2e-5 and placement == "band-quantile" and levels is None
        return dt_choice.Trial(dt, 0.05 if passes else 0.2, 0.11, np.zeros(1),
                               placement=placement, levels=levels)  # fmt: skip

    monkeypatch.setattr(dt_choice, "trial", trial)
    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    lines = []
    chosen = dt_choice.choose_dt(one, log=lines.append)
    assert (chosen.dt, chosen.placement) == (2e-5, "band-quantile")
    gates = [("uniform", None), ("band-quantile", None), ("band-quantile", 32)]
    assert tried == [(dt, *g) for dt in (1e-4, 5e-5) for g in gates] + [
        (2e-5, *g) for g in gates[:2]
    ]
    assert lines[0] == (
        "nir-standard: dt 100 µs, uniform gate levels: TDE-rate error 20.0 %, limit 11 %: fails"
    )
    assert lines[-1] == (
        "nir-standard: dt 20 µs, band-quantile gate levels: TDE-rate error 5.0 %, limit 11 %: "
        "passes"
    )
    tried.clear()
    assert dt_choice.choose_placement(one, 1e-4).placement == "uniform"  # none passes: closest
    assert dt_choice.choose_placement(one, 1e-5).placement == "band-quantile"
    assert tried[-2:] == [(1e-5, "uniform", None), (1e-5, "band-quantile", None)]


def test_a_step_the_clock_alone_puts_beyond_the_limit_tries_one_gate(monkeypatch):
    """Where exact integration between steps is itself beyond the limit (sPLL 0 of
    vibtac-time-scaled-peak: 25 % at 100 and 50 µs, 0 % at 20 µs), the step's other gates are
    skipped once its first fails, and the log says why; with --allow-error none is."""
    tried = []

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        tried.append((dt, placement, levels))
        return dt_choice.Trial(dt, 0.05 if dt <= 2e-5 else 0.2, 0.11, np.zeros(1),
                               placement=placement, levels=levels)  # fmt: skip

    monkeypatch.setattr(dt_choice, "trial", trial)
    one = Network(NetworkConfig.preset("vibtac-time-scaled-peak").build().spll[:1])
    lines = []
    assert dt_choice.choose_dt(one, log=lines.append).dt == 2e-5
    assert tried == [(dt, "uniform", None) for dt in (1e-4, 5e-5, 2e-5)]
    assert lines[1] == (
        "nir-standard: dt 100 µs: exact integration between steps is 25 % off, beyond the "
        "limit; the other gates are not tried"
    )
    tried.clear()  # --allow-error keeps the closest of every gate: none is skipped
    assert dt_choice.choose_dt(one, allow_error=True).dt == 2e-5
    assert len(tried) == 7


def test_the_users_limit_judges_each_step(monkeypatch):
    """A step 12 % off fails the declared 11 % but passes a --max-error of 15 %: the ladder
    stops there, judged (and said) by the user's limit, and refuses by the declared one."""

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        return dt_choice.Trial(dt, 0.12, 0.11, np.zeros(1), placement=placement, levels=levels)

    monkeypatch.setattr(dt_choice, "trial", trial)
    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    lines = []
    chosen = dt_choice.choose_dt(one, log=lines.append, max_error=0.15)
    assert chosen.dt == 1e-4 and chosen.limit == 0.15 and chosen.passed
    assert lines == [
        "nir-standard: dt 100 µs, uniform gate levels: TDE-rate error 12.0 %, limit 15 %: passes"
    ]
    monkeypatch.setattr(dt_choice, "LADDER", (1e-4,))
    monkeypatch.setattr(dt_choice, "FLOOR_STEPS", ())
    with pytest.raises(ValueError, match=r"^nir-standard: no time step of 100 µs represents "
                       r"this network within the declared tolerance \(11 %\)"):  # fmt: skip
        dt_choice.choose_dt(one)


def test_a_network_no_step_represents_is_refused_by_name(monkeypatch):
    """The two fastest sPLLs of vibtac-time-scaled-peak (tau_tde_fac 130 and 109 µs, about 15
    TDE spikes a second) at 100 µs: the check fails, and exact integration between steps is
    itself off by more than the tolerance there and at 50 µs."""
    net = NetworkConfig.preset("vibtac-time-scaled-peak").build()
    fast = Network(net.spll[-2:])
    monkeypatch.setattr(dt_choice, "LADDER", (1e-4,))
    monkeypatch.setattr(dt_choice, "FLOOR_STEPS", (5e-5,))
    with pytest.raises(ValueError) as exc:
        dt_choice.choose_dt(fast)
    msg = str(exc.value)
    assert msg.startswith("nir-standard: no time step of 100 µs represents this network"), msg
    assert "tau_tde_fac 109 µs, tau_tde_trg 85 µs" in msg, msg
    assert "Exact integration between steps" in msg and "% at 50 µs" in msg, msg
    assert "no dt >= 50 µs brings it within 11 %" in msg, msg


def test_a_refusal_blames_the_construction_where_the_clock_is_within(monkeypatch):
    """Two sPLLs of the default preset whose check is made to fail at 100 µs: exact integration
    between steps of 100 µs is within the tolerance on them, so the message names the
    construction's gate (and its own error), not the clock."""
    net = NetworkConfig.preset("vibtac-vary-offset-lif").build()
    two = Network(net.spll[:2])

    def failing(network, dt, placement, levels=None, hold=None, duration=1.0):
        return dt_choice.Trial(dt, 0.5, 0.11, np.array([0.5, 0.2]), placement=placement,
                               levels=levels)  # fmt: skip

    monkeypatch.setattr(dt_choice, "trial", failing)
    monkeypatch.setattr(dt_choice, "LADDER", (1e-4,))
    with pytest.raises(ValueError) as exc:
        dt_choice.choose_dt(two)
    msg = str(exc.value)
    assert "within the tolerance: the clock is not the cause" in msg, msg
    assert "32-level gate alone, exact in time (standard-exact), is off on the worst sPLLs by" in (
        msg
    ), msg
    assert "% on the check's inputs (band-quantile levels)" in msg, msg
    assert (
        "100 µs 50.0 % (uniform levels), 100 µs 50.0 % (band-quantile levels), 100 µs 50.0 % "
        "(32 band-quantile levels)"
    ) in msg, msg
    assert "the clock, not the construction" not in msg, msg
