"""A clock per set of sPLLs on Loihi's integers (mappings/lava/clocks.py): each sPLL's step
holds its refractory period in exactly R + 1/2 steps, a time-scaled network's sPLLs get its
base sPLL's integers, one refractory period is one part, and what Loihi cannot hold is refused
by name; the folder of such integers reads back as written, its run.py on lava-nc bins the input
at each clock's step, and the export writes it where no one step passes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mappings.lava import dt_choice
from mappings.lava.clocks import ClockedStandard, clocked_standard, run_clocked, spll_steps
from mappings.lava.export import read_standard, write_standard
from mappings.lava.loihi import run_trains
from mappings.lava.standalone_run import load_clocks, part_seconds, seconds
from mappings.lava.standard import lava_standard
from spll_hw import Network, network_frequencies
from spll_hw.backends import get
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.construction.gate import GateOptions
from spll_hw.exporters.check_files import stored_duration
from spll_hw.harness.metrics import rate_error
from spll_hw.model.holds import compensated_hold
from spll_hw.params import PARAM_NAMES

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train
from .test_standard_lava import HAS_LAVA, _run_py


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
    """Measured 3.8 % and 1.7 % (4.2 % on the whole preset's check:
    docs/notes/2026-11-28-clock-per-spll.md)."""
    trains = [poisson_train(150.0, 1.0, 0), poisson_train(400.0, 1.0, 1)]
    results = run_clocked(clocked_standard(scaled, 4), trains, 1.0)
    golden = get("golden").simulate_batch(scaled, trains, 1.0)
    errors = [rate_error(r, g) for r, g in zip(results, golden, strict=True)]
    assert max(errors) < 0.06, errors
    assert results[0].info["dt"] == pytest.approx(spll_steps(scaled, 4).tolist())


def test_an_open_loop_cco_is_named_in_the_whole_networks_numbers(scaled):
    """A clock per sPLL answers the per-sPLL verdict's question as one step does: sPLL 2's
    g_cco, made far under Loihi's smallest weight at its own step, rounds to 0 there, and the
    export check fails that sPLL by its number in the network."""
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.spll_verdict import open_loop

    assert clocked_standard(scaled, 4).open_loop().tolist() == []
    matrix = scaled.matrix()
    matrix[2, PARAM_NAMES.index("g_cco")] *= 1e-6
    weak = Network.from_matrix(matrix, layout=scaled.layout)
    assert clocked_standard(weak, 4).open_loop().tolist() == [2]
    backend = get("standard-fixed-point", clock="per-spll", holds=4)
    run = FolderRun.by_backend("a clock per sPLL", backend, weak)
    assert open_loop(run, weak).tolist() == [2]


def test_one_refractory_period_is_one_part_at_one_step():
    net = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))
    clocked = clocked_standard(net, 4)
    (part,) = clocked.parts
    assert part.spll.tolist() == list(range(12))
    dt = float(_refractory(net)[0] / 4.5)
    alone = lava_standard(net, GateOptions(gate=clocked.gate), dt=dt)
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


def test_a_clocked_folder_reads_back_as_written(scaled, tmp_path):
    """params.npz holds each clock's integers with its sPLLs numbered in the whole network;
    read back, they are those written and run as they did; standard.json and the README state
    each clock's step and that the folder runs offline."""
    clocked = clocked_standard(scaled, 4)
    write_standard(clocked, tmp_path)
    back = read_standard(tmp_path)
    assert isinstance(back, ClockedStandard) and back.difference(clocked) is None
    one = lava_standard(scaled, dt=1e-5)
    assert clocked.difference(one) == "a clock per set of sPLLs against one clock"
    clocks = load_clocks(tmp_path / "params.npz")
    assert [c["dt"] for c in clocks] == [part.params.dt for part in clocked.parts]
    assert [int(c["members"]["tde"][0]) for c in clocks] == [0, 1, 2, 3, 4]
    info = json.loads((tmp_path / "standard.json").read_text())
    assert info["clock"] == "per-spll" and info["holds"] == 4 and len(info["clocks"]) == 5
    readme = (tmp_path / "README.md").read_text()
    assert "**Offline, not real time.**" in readme
    assert f"| sPLL 4 | {clocked.parts[4].params.dt * 1e6:.4g} |" in readme
    # Its time for 1 s of input: each clock's parts over that clock's steps in a second.
    costs = [part_seconds(processes, neurons, round(1 / part.params.dt))
             for part in clocked.parts
             for processes, neurons in zip(part.params.part_processes(),
                                           part.params.part_neurons(), strict=True)]  # fmt: skip
    assert f"1 s of input takes about {seconds(costs, 1) / 60:.3g} min" in " ".join(readme.split())
    train = [poisson_train(300.0, 0.3, 4)]
    (a,), (b,) = run_clocked(clocked, train, 0.3), run_clocked(back, train, 0.3)
    assert a.tde_counts.tolist() == b.tde_counts.tolist() and a.tde_counts.sum() > 10


def test_a_clocked_folder_with_a_member_outside_its_clock_is_refused_by_name(scaled, tmp_path):
    write_standard(clocked_standard(scaled, 4), tmp_path)
    with np.load(tmp_path / "params.npz") as raw:
        arrays = dict(raw)
    arrays["clock1.members.tde"] = np.array([3])
    np.savez(tmp_path / "params.npz", **arrays)
    with pytest.raises(ValueError, match=r"not a readable lava-standard export: members\.tde "
                                         r"names sPLLs outside its clock's \[1\]"):  # fmt: skip
        read_standard(tmp_path)


def test_the_backends_take_a_clock_per_spll(scaled):
    """standard-fixed-point:clock=per-spll runs what clocked_standard builds, spike for spike,
    with each sPLL's spike times on its own grid; it has no one step."""
    backend = get("standard-fixed-point", clock="per-spll", holds=5, levels=32,
                  placement="band-quantile")  # fmt: skip
    assert backend.capabilities.dt is None and backend.capabilities.rate_tolerance == 0.07
    assert backend.capabilities.summary() == "a step per sPLL, fixed point"
    assert backend.spec.startswith("standard-fixed-point:")
    assert "clock=per-spll" in backend.spec and "holds=5" in backend.spec
    assert backend.prepared(scaled).difference(clocked_standard(scaled, 5)) is None
    train = [poisson_train(300.0, 0.3, 5)]
    (mine,) = backend.simulate_batch(scaled, train, 0.3, record_spikes=True)
    (theirs,) = run_clocked(clocked_standard(scaled, 5), train, 0.3)
    assert mine.tde_counts.tolist() == theirs.tde_counts.tolist()
    steps = spll_steps(scaled, 5)
    for i, times in enumerate(mine.tde_spikes):
        assert times.size == mine.tde_counts[i]
        assert np.allclose(times / steps[i], np.round(times / steps[i]))
    with pytest.raises(ValueError, match=r"holds must be an integer in 2\.\.64, got 1"):
        get("standard-fixed-point", clock="per-spll", holds=1)


def test_the_export_writes_a_clock_per_spll_where_no_step_passes(tmp_path, monkeypatch, capsys):
    """The slowest and fastest sPLL of vibtac-time-scaled-lif on a ladder of 100 and 50 µs:
    every gate fails at 100 µs and 50 µs is refused (test_lava_dt_choice.py), so the export
    writes its last rung, a clock per sPLL, whose check passes (4.3 % on 1 s; golden moved
    0.5 ms is 4.1 % off itself there, so it is judged again on 10 s, where it passes, resolved);
    the folder stores its 10-s inputs (what ``export --check`` runs by default, as
    test_export_check.py shows) and checks again as written, here on 1 s of them
    (``--check-duration 1``: a tenth of the work of a second 10-s run)."""
    params = tmp_path / "two.toml"
    params.write_text(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(2).to_toml())
    monkeypatch.setattr(dt_choice, "LADDER", (1e-4, 5e-5))
    out = tmp_path / "out"
    assert (
        main(["export", "--to", "lava-standard", "--network", str(params), "--out", str(out)]) == 0
    )
    err = capsys.readouterr().err.splitlines()
    clock = "lava-standard: a clock per sPLL (R = 4), 32 band-quantile gate levels: TDE-rate error "
    assert err[7].startswith(clock) and err[8].startswith(clock), err
    assert err[7].endswith("limit 7 %: passes on 1 s, where golden 0.5 ms later is 4.14 % off "
                           "itself (0.456 % on 10 s): checked again on 10 s"), err  # fmt: skip
    assert err[8].endswith("on 10 s, limit 7 %: passes"), err
    back = read_standard(out)
    assert isinstance(back, ClockedStandard) and [p.spll.tolist() for p in back.parts] == [[0], [1]]
    record = json.loads((out / "check.json").read_text())
    assert record["passed"] and "2 clocks, R = 4" in record["runs"], record["runs"]
    assert record["resolution"]["resolves_limit"]
    assert {x["duration_s"] for x in record["inputs"]} == {10.0} and stored_duration(out) == 10.0
    again = tmp_path / "again"
    assert main(["export", "--check", str(out), "--check-duration", "1", "--out", str(again)]) == 0
    record = json.loads((again / "check.json").read_text())
    assert record["passed"] and "2 clocks, R = 4" in record["runs"], record["runs"]
    assert {x["duration_s"] for x in record["inputs"]} == {1.0}


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_run_py_runs_each_clock_at_its_own_step_spike_for_spike(scaled, tmp_path):
    """The folder's run.py on lava-nc (spll-hw unimportable) bins the input at each clock's
    step and counts exactly what run_clocked does, its two parts stepping at once (--jobs 2;
    every other run.py test runs its parts one after another, the default); it prints each
    sPLL's step."""
    two = Network(scaled.spll[3:5])
    clocked = clocked_standard(two, 4)
    write_standard(clocked, tmp_path)
    duration = 0.03
    x = poisson_train(300.0, duration, seed=6)
    lava = _run_py(tmp_path, x, duration, jobs=2)
    (ref,) = run_clocked(clocked, [x], duration)
    assert lava["tde_counts"] == ref.tde_counts.tolist() and sum(lava["tde_counts"]) > 2
    assert lava["cco_counts"] == ref.cco_counts.tolist()
    assert lava["dt"] == pytest.approx(clocked.steps.tolist())
    assert lava["steps"] == [round(duration / dt) for dt in clocked.steps]
