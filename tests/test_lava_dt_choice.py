"""The time step of ``--to lava-standard`` without ``--dt`` (mappings/lava/dt_choice.py, driven
by spll_hw/exporters/dt_ladder/): the coarsest step the integers represent and whose check
passes, a step the writer refuses or whose check fails moving on to a finer one, and a refusal
naming each step's outcome. Kept short: one- and two-sPLL networks, a ladder cut to two steps
where the refusal's analysis would run the finer ones."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from mappings.lava import dt_choice
from mappings.lava.export import read_standard
from mappings.lava.exporter import export_standard
from spll_hw import Network
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.exporters import dt_ladder


def test_the_ladder_is_tried_coarsest_first_past_refused_and_failing_steps(monkeypatch):
    """At each step every gate with the compensated hold, then every gate with the dithered
    one; a step the writer refuses is refused whatever the gate and hold."""
    tried = []
    outcomes = {
        5e-5: dt_choice.Trial(5e-5, None, float("nan"), reason="sPLL 0: too short; use less"),
        2.5e-5: dt_choice.Trial(2.5e-5, 0.09, 0.07, np.zeros(1)),
        1e-5: dt_choice.Trial(1e-5, 0.05, 0.07, np.zeros(1)),
    }

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        tried.append((dt, placement, levels, hold))
        return replace(outcomes[dt], placement=placement, levels=levels, hold=hold)

    monkeypatch.setattr(dt_choice, "trial", trial)
    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    lines = []
    assert dt_choice.choose_dt(one, log=lines.append).dt == 1e-5
    # a refused step is refused whatever the gate; a failing one tries the next
    gates = [("uniform", None), ("band-quantile", None), ("band-quantile", 32)]
    assert tried == [(5e-5, "uniform", None, None)] + [
        (2.5e-5, *g, hold) for hold in (None, "dithered") for g in gates
    ] + [(1e-5, "uniform", None, None)]
    fails = "TDE-rate error 9.0 %, limit 7 %: fails"
    assert lines == [
        "lava-standard: dt 50 µs, uniform gate levels: refused (sPLL 0: too short)",
        f"lava-standard: dt 25 µs, uniform gate levels: {fails}",
        f"lava-standard: dt 25 µs, band-quantile gate levels: {fails}",
        f"lava-standard: dt 25 µs, 32 band-quantile gate levels: {fails}",
        f"lava-standard: dt 25 µs, uniform gate levels, dithered hold: {fails}",
        f"lava-standard: dt 25 µs, band-quantile gate levels, dithered hold: {fails}",
        f"lava-standard: dt 25 µs, 32 band-quantile gate levels, dithered hold: {fails}",
        "lava-standard: dt 10 µs, uniform gate levels: TDE-rate error 5.0 %, limit 7 %: passes",
    ]


def test_each_holds_other_gates_are_skipped_where_the_clock_alone_is_beyond_the_limit(
    monkeypatch,
):
    """sPLL 0 of vibtac-time-scaled-peak: exact integration is 25 % off at 50 µs, beyond 7 %,
    so each hold tries only its first gate there; the log says which hold's are skipped."""
    tried = []

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        tried.append((dt, placement, levels, hold))
        return dt_choice.Trial(dt, 0.05 if dt < 5e-5 else 0.3, 0.07, np.zeros(1),
                               placement=placement, levels=levels, hold=hold)  # fmt: skip

    monkeypatch.setattr(dt_choice, "trial", trial)
    one = Network(NetworkConfig.preset("vibtac-time-scaled-peak").build().spll[:1])
    lines = []
    assert dt_choice.choose_dt(one, log=lines.append).dt == 2.5e-5
    assert tried == [(5e-5, "uniform", None, hold) for hold in (None, "dithered")] + [
        (2.5e-5, "uniform", None, None)
    ]
    skipped = "lava-standard: dt 50 µs: exact integration between steps is 25 % off, beyond the "
    skipped += "limit"
    assert lines[1] == f"{skipped}; the other gates are not tried"
    assert lines[3] == f"{skipped}; the other gates with the dithered hold are not tried"


def test_allow_error_takes_the_closest_step_not_the_finest(monkeypatch):
    """Where no step passes, --allow-error takes the checked step of the smallest error (25 µs
    here: on Loihi's integers a finer step may be further off), with a note for the README
    naming the limit and each step's outcome; where the writer refuses every step there is
    nothing to write, so it refuses, naming the user's limit."""
    outcomes = {
        5e-5: dt_choice.Trial(5e-5, None, float("nan"), reason="sPLL 0: too short; use less"),
        2.5e-5: dt_choice.Trial(2.5e-5, 0.09, 0.07, np.zeros(1)),
        1e-5: dt_choice.Trial(1e-5, 0.12, 0.07, np.zeros(1)),
    }

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        return replace(outcomes[dt], placement=placement, levels=levels, hold=hold)

    clocked = dt_choice.Trial(float("nan"), 0.1, 0.07, np.zeros(1), placement="band-quantile",
                              levels=32, clock=dt_choice.CLOCK)  # fmt: skip
    monkeypatch.setattr(dt_choice, "trial", trial)
    monkeypatch.setattr(
        dt_choice, "PARTS", replace(dt_choice.PARTS, last=(lambda _, **__: clocked,))
    )
    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    lines = []
    chosen = dt_choice.choose_dt(one, log=lines.append, max_error=0.08, allow_error=True)
    assert chosen.dt == 2.5e-5 and not chosen.passed and chosen.limit == 0.08
    assert lines[-2] == (
        "lava-standard: a clock per sPLL (R = 4), 32 band-quantile gate levels: TDE-rate error "
        "10.0 %, limit 8 %: fails"
    )
    assert lines[-1] == (
        "lava-standard: no step passes; writing dt 25 µs (uniform gate levels), the closest to "
        "golden (--allow-error)"
    )
    steps = ", ".join(
        f"{dt} µs {error} % ({levels}levels{hold})"
        for dt, error in (("25", "9.0"), ("10", "12.0"))
        for hold in ("", ", dithered hold")
        for levels in ("uniform ", "band-quantile ", "32 band-quantile ")
    )
    steps += ", a clock per sPLL (R = 4) 10.0 % (32 band-quantile levels)"
    assert chosen.note == (
        "No time step of 50, 25, 10 µs, nor a clock per sPLL (R = 4), passed the export check "
        f"within the limit of --max-error (8 %): 50 µs refused (sPLL 0: too short), {steps}. "
        "Written at 25 µs with uniform gate "
        "levels, the step whose check came closest to golden, because of `--allow-error`; the "
        "check below is that step's."
    )
    assert chosen.readme("# R\n") == f"# R\n\n## Time step\n\n{chosen.note}\n"
    # a clock per sPLL closer than every step is the one written, and the note says so
    closer = replace(clocked, error=0.085)
    monkeypatch.setattr(
        dt_choice, "PARTS", replace(dt_choice.PARTS, last=(lambda _, **__: closer,))
    )
    chosen = dt_choice.choose_dt(one, log=lines.append, max_error=0.08, allow_error=True)
    assert chosen.clock == dt_choice.CLOCK and chosen.error == 0.085
    assert lines[-1] == (
        "lava-standard: no step passes; writing a clock per sPLL (R = 4) (32 band-quantile gate "
        "levels), the closest to golden (--allow-error)"
    )
    assert "Written with a clock per sPLL (R = 4) and 32 band-quantile gate levels, the " in (
        chosen.note
    )
    refused = {dt: outcomes[5e-5] for dt in outcomes}
    monkeypatch.setattr(
        dt_choice, "trial", lambda network, dt, placement, levels, hold, duration: refused[dt]
    )
    monkeypatch.setattr(
        dt_choice, "PARTS", replace(dt_choice.PARTS, last=(lambda _, **__: refused[1e-5],))
    )
    with pytest.raises(ValueError, match=r"within the limit of --max-error \(8 %\); the export"):
        dt_choice.choose_dt(one, max_error=0.08, allow_error=True)


def test_a_refusal_says_where_golden_varies_as_much_as_the_limit(monkeypatch):
    """A refusal ends with the checks' resolution where golden on the inputs 0.5 ms later is
    more than half the limit off golden (its verdicts cannot tell), with whether 10 s of input
    would resolve it (golden's variation on them, measured where the check did not), and says
    nothing of it where it is within half."""
    from spll_hw.backends import get
    from spll_hw.exporters import FolderRun, MemoryCheck
    from spll_hw.exporters.check import check_run

    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    run = FolderRun.by_backend("golden", get("golden"), one)
    report = check_run(run, "lava-standard", one)
    longer = []
    monkeypatch.setattr(dt_ladder.refusals, "golden_resolution",
                        lambda network, duration: longer.append(duration) or on_10_s)  # fmt: skip

    def refusal(resolution: float, measured: float = float("nan")) -> str:
        checked = MemoryCheck(run, replace(report, resolution=resolution,
                                           longer_resolution=measured))  # fmt: skip
        clocked = dt_choice.Trial(float("nan"), 0.1, 0.07, np.zeros(1), checked=checked,
                                  clock=dt_choice.CLOCK)  # fmt: skip
        return dt_ladder.refusal(one, [clocked], dt_choice.PARTS, max_error=0.07)

    unresolved = ("Golden itself, on every input 0.5 ms later, is 5.0 % off golden, more than "
                  "half the limit: on these inputs golden's own variation is as large as the "
                  "errors the verdict judges, so the verdict is not resolved")  # fmt: skip
    on_10_s = 0.02
    assert refusal(0.05).endswith(
        f"{unresolved}; on 10 s of each input golden is 2.0 % off itself: `--check-duration "
        "10` resolves it"
    )
    assert longer == [10.0]
    assert refusal(0.05, 0.058).endswith(  # the check's own measure, none taken again
        f"{unresolved}, nor on longer ones: on 10 s of each input golden is 5.8 % off itself. "
        "This network's counts hang on the timing of its input; on inputs of 10 s no limit "
        "under 11.6 % can be judged"
    )
    assert longer == [10.0]
    assert refusal(0.035).endswith(dt_choice.PARTS.exact)


def test_every_check_of_the_ladder_runs_on_the_check_duration(monkeypatch):
    """``duration`` (``--check-duration``) reaches every check the ladder runs: each step's,
    each last rung's, and exact integration's in a refusal, whose worst sPLL's error and
    resolution are then those of the longer inputs."""
    from spll_hw.exporters.dt_ladder import floor_check

    seen = []

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        seen.append(("step", duration))
        return dt_choice.Trial(dt, 0.12, 0.07, np.zeros(1), placement=placement, levels=levels,
                               hold=hold)  # fmt: skip

    def rung(network, duration):
        seen.append(("rung", duration))
        return dt_choice.Trial(float("nan"), 0.1, 0.07, np.zeros(1), clock=dt_choice.CLOCK)

    floors = []
    monkeypatch.setattr(dt_choice, "trial", trial)
    monkeypatch.setattr(dt_choice, "LADDER", (5e-5,))
    monkeypatch.setattr(dt_choice, "FLOOR_STEPS", ())
    monkeypatch.setattr(dt_choice, "PARTS", replace(dt_choice.PARTS, last=(rung,)))

    def counted(*args, **kwargs):
        floors.append(kwargs["duration"])
        return floor_check(*args, **kwargs)

    monkeypatch.setattr(dt_ladder.choosing, "floor_check", counted)
    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    with pytest.raises(ValueError, match="no time step of 50 µs, nor a clock per sPLL"):
        dt_choice.choose_dt(one, duration=2.5)
    assert {d for _, d in seen} == {2.5} and [w for w, _ in seen][-1] == "rung"
    assert floors and set(floors) == {2.5}


def test_a_verdict_1_s_does_not_resolve_is_checked_again_on_10_s(monkeypatch):
    """Without --check-duration a check is run again on 10 s and judged by it only where 1 s
    does not resolve its verdict (golden 0.5 ms later more than half the limit off itself, and
    at least as far as the check is from the limit), pass or fail, and 10 s does resolve it;
    golden's 10-s variation is measured once, and only where a verdict asks."""
    from spll_hw.backends import get
    from spll_hw.exporters import FolderRun, MemoryCheck
    from spll_hw.exporters.check import check_run

    one = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:1])
    run = FolderRun.by_backend("golden", get("golden"), one)
    reports = {d: check_run(run, "lava-standard", one, duration=d) for d in (1.0, 10.0)}
    longer, lines = [], []

    def measured(network, duration):
        assert duration == dt_ladder.judging.LONGER
        longer.append(duration)
        return longer_resolution

    def trial(error: float, resolution: float, longer_error: float):
        """A check of ``error`` whose inputs move golden by ``resolution`` on 1 s, and of
        ``longer_error`` on 10 s."""

        def check(duration):
            report = replace(reports[duration], resolution=resolution, max_error=0.07)
            value = error if duration == 1.0 else longer_error
            return dt_choice.Trial(5e-5, value, 0.07, np.zeros(1),
                                   checked=MemoryCheck(run, report))  # fmt: skip

        return check

    monkeypatch.setattr(dt_ladder.judging, "golden_resolution", measured)
    longer_resolution = 0.02
    judge = dt_ladder.judge_by(one, "lava-standard", None, None, lines.append)
    assert judge(trial(0.01, 0.05, 0.09)).error == 0.01  # within the limit by more than 5 %
    assert judge(trial(0.09, 0.03, 0.05)).error == 0.09  # 1 s resolves the limit
    assert judge(trial(0.20, 0.05, 0.05)).error == 0.20  # beyond the limit by more than 5 %
    assert longer == [] and lines == []
    again = judge(trial(0.09, 0.05, 0.05))  # 9 % may be golden's own 5 %: checked on 10 s
    assert again.error == 0.05 and again.passed and again.on == " on 10 s"
    assert again.summary() == "TDE-rate error 5.0 % on 10 s, limit 7 %: passes"
    assert lines == [
        "lava-standard: dt 50 µs, uniform gate levels: TDE-rate error 9.0 %, limit 7 %: fails on "
        "1 s, where golden 0.5 ms later is 5 % off itself (2 % on 10 s): checked again on 10 s"
    ]
    assert judge(trial(0.09, 0.05, 0.08)).error == 0.08 and longer == [10.0]  # measured once
    near = judge(trial(0.055, 0.05, 0.08))  # a pass as unresolved: judged on 10 s, and fails
    assert not near.passed and near.error == 0.08 and longer == [10.0] and len(lines) == 3
    longer_resolution = 0.04  # 10 s does not resolve 7 % either: not run ten times as long
    unresolved = dt_ladder.judge_by(one, "lava-standard", None, None, lines.append)
    assert unresolved(trial(0.09, 0.05, 0.05)).error == 0.09 and len(lines) == 3
    # the user's --check-duration: that one length, never another
    given = dt_ladder.judge_by(one, "lava-standard", None, 10.0, lines.append)
    assert given(trial(0.09, 0.05, 0.08)).error == 0.08 and len(longer) == 2


def test_a_network_the_first_step_passes_is_written_at_it(tmp_path, capsys):
    """The slowest and fastest sPLL of the default preset (56 and 668 Hz): 50 µs passes, so the
    export writes 50 µs integers after one check, said on stderr."""
    two = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(2).build()
    export_standard(two, tmp_path / "out")
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("lava-standard: dt 50 µs, uniform gate levels: TDE-rate error"), err
    assert err[0].endswith("limit 7 %: passes"), err
    assert read_standard(tmp_path / "out").dt == 5e-5


def test_a_step_the_writer_refuses_moves_on_to_a_finer_one():
    """A TDE refractory period of 70 µs is one step at 50 µs, which Loihi's refractory unit
    cannot hold (it needs 2): the writer refuses 50 µs with its reason, and 25 µs (3 steps)
    passes the check."""
    spll = NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[10]
    short = Network((replace(spll, t_tde_refr=7e-5),))
    lines = []
    assert dt_choice.choose_dt(short, log=lines.append).dt == 2.5e-5
    assert lines[0] == (
        "lava-standard: dt 50 µs, uniform gate levels: refused (sPLL 0: t_tde_refr = 7e-05 s is "
        "1 steps at dt = 5e-05 s)"
    )
    assert lines[1].startswith("lava-standard: dt 25 µs, uniform gate levels: TDE-rate error")
    assert lines[1].endswith("passes"), lines


def test_a_network_every_step_refuses_is_refused_naming_each_reason(monkeypatch):
    """sPLL 5 of biotac-tuned-time-scaled-peak: one trigger is hundreds of TDE thresholds in
    a step at 50 and 25 µs and at its own step of 116 µs (a clock per sPLL, with LIF or
    graded CCO currents), beyond Loihi's 16-bit synaptic input; nothing is checked."""
    fast = Network(NetworkConfig.preset("biotac-tuned-time-scaled-peak").build().spll[5:6])
    monkeypatch.setattr(dt_choice, "LADDER", (5e-5, 2.5e-5))
    with pytest.raises(ValueError) as exc:
        dt_choice.choose_dt(fast)
    msg = str(exc.value)
    assert msg.startswith(
        "lava-standard: no time step of 50, 25 µs, nor a clock per sPLL (R = 4), nor a clock per "
        "sPLL (R = 4) with graded CCO currents, represents this network within the declared "
        "tolerance (7 %); the export check's total TDE-rate error: "
        "50 µs refused (lava-standard: sPLL 0: g_tde_trg = 7.63741 gives a trigger of"
    ), msg
    assert "at dt = 5e-05 s), 25 µs refused (lava-standard: sPLL 0: g_tde_trg" in msg, msg
    clock = (
        ", a clock per sPLL (R = 4) refused (the network's sPLLs [0] at their step dt = "
        "0.000115708 s (numbered from 0 among them below): lava-standard: sPLL 0: g_tde_trg"
    )
    assert clock in msg, msg
    assert ", a clock per sPLL (R = 4) with graded CCO currents refused (the network's" in msg
    assert msg.endswith("--to lava writes the exact sPLL (spll-hw's TDE and CCO processes on Lava)")


def test_the_export_command_refuses_a_network_no_step_represents(tmp_path, monkeypatch, capsys):
    """The slowest and fastest sPLL of vibtac-time-scaled-lif on a ladder of 100 and 50 µs: at
    100 µs the check fails with either placement (the fastest's 96 µs TDE refractory period is
    under one step, so nothing holds it), at 50 µs it is one step, which the refractory unit
    cannot hold (refused); exit status 2, each step on stderr, the refusal naming every outcome
    and the worst sPLLs, nothing written."""
    params = tmp_path / "two.toml"
    params.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(2).to_toml())
    monkeypatch.setattr(dt_choice, "LADDER", (1e-4, 5e-5))
    monkeypatch.setattr(dt_choice, "FLOOR_STEPS", ())
    monkeypatch.setattr(dt_choice, "PARTS", replace(dt_choice.PARTS, last=()))
    out = tmp_path / "out"
    args = ["export", "--to", "lava-standard", "--network", str(params), "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    gates = ("uniform", "band-quantile", "32 band-quantile")
    variants = [f"{g} gate levels{h}" for h in ("", ", dithered hold") for g in gates]
    for line, variant in zip(err, variants, strict=False):
        assert line.startswith(f"lava-standard: dt 100 µs, {variant}: TDE-rate"), line
        assert "fails" in line, line
    assert err[6] == (
        "lava-standard: dt 50 µs, uniform gate levels: refused (sPLL 1: t_tde_refr = "
        "9.56023e-05 s is 1 steps at dt = 5e-05 s)"
    )
    assert len(err) == 8 and err[7].startswith("spll-hw export: error: lava-standard: no time "
                                               "step of 100, 50 µs represents")  # fmt: skip
    assert "50 µs refused (sPLL 1: t_tde_refr" in err[7], err[7]
    errors = [float(line.split("TDE-rate error ")[1].split(" %")[0]) for line in err[:6]]
    outcomes = ", ".join(
        f"100 µs {e:.1f} % ({variant.replace('gate levels', 'levels')})"
        for e, variant in zip(errors, variants, strict=True)
    )
    assert outcomes in err[7], err[7]
    assert ". Worst sPLLs at 100 µs: 1 (tau_tde_fac 1396 µs, tau_tde_trg 54 µs" in err[7], err[7]
    assert "Exact integration between steps" in err[7] and "% at 100 µs" in err[7], err[7]
    closest = min(zip(errors, variants, strict=True))
    assert (
        f"the closest, 100 µs with {closest[1]} at {closest[0]:.3g} %, is what --allow-error "
        "writes; --to lava writes the exact sPLL"
    ) in err[7], err[7]
    assert not out.exists()


def test_a_refusal_blames_the_construction_and_names_loihis_decays():
    """A check failed at 50 µs by two sPLLs of the default preset: exact integration between
    steps of 50 µs is within the tolerance on them, so the refusal names the construction: its
    gate's own error and the time constant Loihi's 12-bit decays round most."""
    two = Network(NetworkConfig.preset("vibtac-vary-offset-lif").build().spll[:2])
    failed = [dt_choice.Trial(5e-5, 0.5, 0.07, np.array([0.2, 0.5]))]
    msg = dt_ladder.refusal(two, failed, dt_choice.PARTS)
    assert "50 µs 50.0 % (uniform levels). Worst sPLLs at 50 µs: 1 (tau_tde_fac" in msg, msg
    assert "within the tolerance: the clock is not the cause" in msg, msg
    assert "16-level gate alone, exact in time (standard-exact), is off on the worst sPLLs by" in (
        msg
    ), msg
    assert "; Loihi's 12-bit decays at 50 µs make sPLL " in msg, msg
    assert "the clock, not the construction" not in msg, msg


def test_decay_rounding_names_the_time_constant_rounded_most():
    """At 10 µs the CCO's 68 ms membrane time constant has a 12-bit decay of 1 (4096 · 10 µs /
    68 ms = 0.6): it acts as 41 ms, 40 % off, the furthest of the sPLL's time constants
    (``tau_tde_fac``, 15 ms, has 3: 10 % off)."""
    spll = NetworkConfig.preset("vibtac-time-scaled-lif").build().spll[0]
    assert spll.tau_cco == pytest.approx(0.0678794, rel=1e-5)
    text = dt_choice.decay_rounding(Network((spll,)), np.array([0]), 1e-5)
    assert text.startswith(
        "; Loihi's 12-bit decays at 10 µs make sPLL 0's tau_cco of 67879 µs act as 40955 µs "
        "(40 % off); sPLL 0's feedback kick into its CCO is "
    ), text  # and its feedback kick, a few hundred units of u (the test below)


def test_a_finer_step_is_said_to_be_unrepresentable_where_the_writer_refuses_it():
    """Where exact integration at 5 µs would be within the tolerance, the refusal says whether
    the integers represent the network there: biotac-time-scaled-lif's slowest sPLL is (its
    84 ms ``tau_cco_syn``, a 12-bit decay of 0.24, takes Loihi's longest with its charge kept),
    but not with a 50 ms ``tau_tde_fac`` (the gate's current, 0.4); its fastest sPLL is."""
    net = NetworkConfig.preset("biotac-time-scaled-lif").build()
    assert dt_choice.finer(Network(net.spll[:1]), 5e-6) == "the integers represent it there"
    slow_fac = Network((replace(net.spll[0], tau_tde_fac=0.05),))
    assert dt_choice.finer(slow_fac, 5e-6) == (
        "it is not representable there: sPLL 0: tau_tde_fac = 0.05 s at dt = 5e-06 s "
        "needs a 12-bit decay of 0"
    )
    assert dt_choice.finer(Network(net.spll[-1:]), 5e-6) == "the integers represent it there"


def test_kept_charge_of_a_kick_below_whole_units_a_step():
    """A kick of 384 units of u decaying by 2/4096 a step should lose 0.19 units a step; Loihi's
    decay truncates to whole units, so it loses exactly 1 a step (384, 383, ..., 1) and
    delivers 384 · 385 / 2 units where the exact decay's 384 · 2048 would: 385 / 4096. A kick
    of many units a step keeps most of its charge; none keeps all of it."""
    from mappings.lava.loihi import kept_charge

    kept = kept_charge(np.array([384, 100_000]), np.array([2, 2]))
    assert kept[0] == pytest.approx(385 / 4096, rel=1e-12)
    assert 0.9 < kept[1] < 1.0


def test_a_refusal_names_a_feedback_kick_that_loses_its_charge():
    """sPLL 4 of biotac-time-scaled-lif at 25 µs: its CCO fires every few hundred steps, so a
    TDE spike's feedback into it is a few hundred units of u decaying by 2/4096 a step, which
    keeps about a tenth of its charge (its CCO fires 48 times on the check's inputs where
    golden's fires 137-155 times, docs/notes/2026-11-27-loihi-integers-on-slow-synapses.md);
    the clause after the decays' rounding names it. The fast sPLL 49's kick keeps most of its
    charge and is not named."""
    net = NetworkConfig.preset("biotac-time-scaled-lif").build()
    slow = Network((net.spll[4],))
    text = dt_choice.decay_rounding(slow, np.array([0]), 2.5e-5)
    assert "; sPLL 0's feedback kick into its CCO is " in text, text
    kick, delta = dt_choice.feedback_kicks(dt_choice.lava_standard(slow, dt=2.5e-5))
    assert delta[0] == 2 and 100 < kick[0] < 2048, (kick, delta)
    assert "units of u decaying by 2/4096 a step, which Loihi's whole-unit decay cuts to" in text
    fast = Network((net.spll[49],))
    assert "feedback kick" not in dt_choice.decay_rounding(fast, np.array([0]), 2.5e-5)
