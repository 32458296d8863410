"""The standard sPLL on Lava's own processes (mappings/lava/standard.py): the exported folder
runs on lava-nc alone and matches the project's bit-accurate reference (mappings/lava/loihi.py);
bad networks are refused."""

from __future__ import annotations

import ast
import importlib.util
import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mappings.lava.export import read_standard
from mappings.lava.exporter import export_standard
from mappings.lava.loihi import simulate_fixed
from mappings.lava.standalone_run import n_processes, split
from mappings.lava.standard import EXPORT_GATE, EXPORT_LEVELS, lava_standard
from mappings.lava.standard_backend import LavaStandard, StandardFixedPoint
from mappings.nir.executor import input_steps
from spll_hw import Network, network_frequencies, simulate_batch
from spll_hw.config import NetworkConfig
from spll_hw.harness.metrics import rate_error

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

ROOT = Path(__file__).resolve().parents[1]
HAS_LAVA = importlib.util.find_spec("lava") is not None
DT = 5e-5
#: Runs run.py as a user would, with the project's packages unimportable.
RUNNER = (
    "import runpy, sys\n"
    "for m in ('spll_hw', 'mappings', 'quantize'): sys.modules[m] = None\n"
    "sys.argv = ['run.py', 'spikes.npy', *sys.argv[1:]]\n"
    "runpy.run_path('run.py', run_name='__main__')\n"
)


@pytest.fixture(scope="module")
def net():
    return Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))


def _outside_env() -> dict:
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def _run_py(folder, spikes: np.ndarray, duration: float, jobs: int = 1) -> dict:
    """The TDE and CCO counts the exported ``run.py`` in ``folder`` prints on lava-nc for the
    input ``spikes`` [s] of ``duration`` [s], with spll-hw not importable, its independent
    parts ``jobs`` at a time (one, run.py's default, leaves the other core to pytest's other
    worker)."""
    np.save(folder / "spikes.npy", spikes)
    done = subprocess.run([sys.executable, "-c", RUNNER, repr(duration), "--jobs", str(jobs)],
                          cwd=folder,
                          env=_outside_env(), capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_export_writes_without_lava_and_run_py_imports_no_project_code(net, tmp_path):
    code = (
        "import sys; sys.modules['lava'] = None\n"  # as if lava-nc were not installed
        "from tests.test_standard_lava import _export\n"
        f"_export({str(tmp_path)!r})\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [
        "README.md", "check_counts.py", "lava_compat.py", "params.npz", "run.py", "spll_grid.py",
        "standard.json",
    ]  # fmt: skip
    for script in ("run.py", "lava_compat.py", "spll_grid.py", "check_counts.py"):
        tree = ast.parse((tmp_path / script).read_text())
        imported = {
            (n.module if isinstance(n, ast.ImportFrom) else a.name).split(".")[0]
            for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom)
            for a in (n.names if isinstance(n, ast.Import) else [None])
        }  # fmt: skip
        assert imported <= {
            "__future__",
            "argparse",
            "json",
            "math",
            "os",
            "sys",
            "time",
            "traceback",
            "pathlib",
            "numpy",
            "lava",
            "lava_compat",
            "spll_grid",
            "check_counts",
            "typing",
            "ast",
            "importlib",
            "multiprocessing",
            "scipy",  # lava-nc 0.10 requires it
        }, imported
    info = json.loads((tmp_path / "standard.json").read_text())
    assert info["gate_levels"] == EXPORT_LEVELS and info["populations"]["gate"]["du"] == 4095


def test_run_py_says_what_is_wrong_with_its_arguments(net, tmp_path):
    """run.py answers --help, and a wrong argument (or --check in a folder written without its
    check) with exit status 2 and what is wrong, before it builds anything (no lava-nc
    needed)."""
    export_standard(net, tmp_path, dt=DT)

    def run_py(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "run.py", *args], cwd=tmp_path,
                              env=_outside_env(), capture_output=True, text=True,
                              timeout=120)  # fmt: skip

    shown = run_py("--help")
    assert shown.returncode == 0 and "--check [INPUT ...]" in shown.stdout
    for args, words in (
        ([], "give a spike file and a duration"),
        (["spikes.npy", "-1"], "duration must be a finite time > 0 s, got -1"),
        (["missing.npy", "1"], "cannot read the spike times missing.npy"),
        (["spikes.npy", "1", "--check"], "--check takes input numbers, not a spike file"),
        (["--check"], "no check.json or check_inputs.npz, so there is nothing to compare"),
    ):
        done = run_py(*args)
        assert done.returncode == 2, (args, done.stderr)
        assert words in done.stderr, (args, done.stderr)


def _export(out: str) -> None:
    """Export the test network (called in a subprocess without lava-nc)."""
    n = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))
    export_standard(n, out, dt=DT)


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
@pytest.mark.parametrize("layout", ["vary-offset", "grouped:3"])
def test_run_py_on_lava_matches_the_bit_accurate_reference_spike_for_spike(net, tmp_path, layout):
    """run.py on lava-nc, with spll-hw unimportable, counts exactly what simulate_fixed does;
    a grouped layout runs one level/TDE/CCO process per group of time constants."""
    if layout != "vary-offset":
        net = NetworkConfig.preset("vibtac-time-scaled-lif").with_layout(layout).build()
    # 2000 steps of the 12 sPLLs (34 TDE spikes), 500 of the grouped 50 (148): over 20 each
    duration = 0.1 if layout == "vary-offset" else 0.025
    x = poisson_train(300.0, duration, seed=3)
    export_standard(net, tmp_path, dt=DT)
    lava = _run_py(tmp_path, x, duration)
    # what the folder holds: the export chooses the gate placement whose check passes (the
    # grouped layout's: band-quantile, its triggers split over exponents)
    params = read_standard(tmp_path)
    # gate, then per group level, TDE, CCO and the end and hold neurons of 2 refractory units
    assert len(params.lif) == (8 if layout == "vary-offset" else 22)
    ref = simulate_fixed(params, input_steps(x, duration, DT)[:, None])
    assert lava["steps"] == round(duration / DT) and lava["dt"] == DT
    assert lava["tde_counts"] == ref["tde_counts"][0].tolist()
    assert lava["cco_counts"] == ref["cco_counts"][0].tolist()
    assert sum(lava["tde_counts"]) > 20 and min(lava["cco_counts"]) > 0


@pytest.mark.parametrize(
    ("preset", "dt"),
    [("biotac-tuned-vary-offset-pacinian", DT), ("vibtac-time-scaled-lif", 2.5e-5),
     ("biotac-vary-offset-lif", DT)],
)  # fmt: skip
def test_run_py_splits_the_network_into_sets_that_count_as_the_whole(preset, dt):
    """run.py runs a network's independent parts one after another (lava-nc starts an OS
    process per Lava process: a tuned or time-scaled network whole is about 1900): one part
    per set of decays (a vary-offset network whole), each of about 40 processes, every sPLL in
    exactly one, and the parts' counts by Loihi's integers are the whole network's, every
    sPLL."""
    net = NetworkConfig.preset(preset).build()
    params = lava_standard(net, dt=dt)
    parts = split(params.params())
    sets = [pop for pop in params.lif if pop.startswith("tde")]
    assert len(parts) == len(sets)
    held = np.concatenate([part["members"][pop] for part in parts for pop in part["lif"]
                           if pop.startswith("tde")])  # fmt: skip
    assert sorted(held.tolist()) == list(range(net.n_spll))
    assert max(n_processes(part) for part in parts) <= 50
    assert len(parts) == (1 if "vary-offset" in preset and "tuned" not in preset else 50)
    words = f"network's {len(parts)} independent parts" if len(parts) > 1 else "runs them together"
    assert words in params.readme()
    counts = input_steps(poisson_train(300.0, 0.1, seed=5), 0.1, dt)[:, None]
    whole = simulate_fixed(params, counts)
    tde, cco = np.zeros((2, net.n_spll), np.int64)
    for part in parts:
        ran = simulate_fixed(replace(params, lif=part["lif"], dense=part["dense"],
                                     members=part["members"]), counts)  # fmt: skip
        tde += ran["tde_counts"][0]
        cco += ran["cco_counts"][0]
    np.testing.assert_array_equal(tde, whole["tde_counts"][0])
    np.testing.assert_array_equal(cco, whole["cco_counts"][0])
    assert whole["tde_counts"].sum() > 100


def _natively_held(params, counts: np.ndarray, holds: dict) -> dict:
    """simulate_fixed's arithmetic on ``params`` without its refractory units, each TDE and CCO
    held by a counter instead (v = 0 for ``base`` steps after each spike, ``base + step``
    after every ``period``-th: ``holds[part]``, a CounterDither per sPLL): the raster the
    units must reproduce."""
    from mappings.lava.loihi import UV_MAX, _decay, _Merged

    unit = ("end_", "hold_", "dither_")
    lif = {pop: v for pop, v in params.lif.items() if not pop.startswith(unit)}
    dense = {
        name: d for name, d in params.dense.items()
        if (d[0] == "input" or d[0] in lif) and d[1] in lif and "_start_" not in name
    }  # fmt: skip
    members = {pop: params.members[pop] for pop in lif if pop in params.members}
    net = _Merged(replace(params, lif=lif, dense=dense, members=members))
    base, step, period = (np.zeros(net.size, np.int64) for _ in range(3))
    for part in ("tde", "cco"):
        (cols, spll), _ = net.parts[part]
        for mine, theirs in zip((base, step, period), holds[part], strict=True):
            mine[cols] = theirs[spll]
    u, v, spikes, left, count = (np.zeros((1, net.size), np.int64) for _ in range(5))
    rasters = {part: [] for part in ("tde", "cco")}
    for t in range(counts.shape[0]):
        a_in = np.asarray(net.w @ spikes.T).T
        for w, e in net.shifted:  # a graded current's decay and its pass to the CCO
            a_in += np.asarray(w @ spikes.T).T >> -e
        for cols, w, e in net.inputs if t else ():
            a_in[:, cols] += (counts[t - 1][:, None] * w) << e
        u = _decay(u, net.keep_u) + (a_in << 6)
        v = np.clip(_decay(v, net.keep_v) + u + net.bias, -UV_MAX + 1, UV_MAX - 1)
        v[left > 0] = 0
        left = np.maximum(left - 1, 0)
        fired = v > net.threshold
        count += fired
        due = (period > 0) & (count >= period)
        count[due] = 0
        v[fired], left[fired] = 0, (base + step * due)[fired]
        spikes = fired.astype(np.int64)
        spikes[:, net.graded] = a_in[:, net.graded]
        for part in rasters:
            rasters[part].append(net.output(part, fired)[0])
    return {part: np.array(r) for part, r in rasters.items()}


# The tuned preset's runs are 0.05 s (the Python reference's step loop is this test's time):
# its TDEs still spike about 50 times each, past every dither period (2..16).
@pytest.mark.parametrize(("preset", "dt", "hold", "current", "duration"), [
    ("biotac-vary-offset-lif", 5e-5, "compensated", "lif", 0.1),
    ("vibtac-vary-offset-lif", 1e-5, "compensated", "lif", 0.1),
    ("biotac-vary-offset-lif", 5e-5, "dithered", "lif", 0.1),
    ("biotac-vary-offset-peak", 1e-5, "dithered", "lif", 0.1),
    ("biotac-tuned-time-scaled-peak", 1e-5, "dithered", "lif", 0.05),
    ("biotac-vary-offset-lif", 5e-5, "compensated", "graded", 0.1),
    ("biotac-tuned-time-scaled-peak", 1e-5, "dithered", "graded", 0.05),
])  # fmt: skip
def test_refractory_units_hold_exactly_their_steps(preset, dt, hold, current, duration):
    """The units (end counter, hold neuron, forcing current and, dithered, the counter that
    lengthens or shortens every n-th hold by a step) give spike for spike what the same
    integers give with each TDE and CCO held at 0 by a counter for its hold's steps;
    biotac-vary-offset-lif drives its TDEs hard, and the CCOs' thresholds there need the force
    to be cleared within a held run (below theta). Dithered, t_refr = 1 ms is 19.5 steps at
    50 µs, held 19 and 20 in turn; the tuned time-scaled preset's periods are lengthened and
    shortened one spike in 2..16. With graded CCO currents (a memoryless CCO u, its current's
    kicks carried in its a_in beside the force) the units hold as exactly."""
    from mappings.lava import integers

    net = NetworkConfig.preset(preset).build()
    params = lava_standard(net, dt=dt, hold=hold, current=current)
    counts = input_steps(poisson_train(300.0, duration, seed=5), duration, dt).astype(np.int64)[
        :, None
    ]
    units = simulate_fixed(params, counts, record_spikes=True)
    holds = {part: integers.holds(np.array([getattr(q, f"t_{part}_refr") for q in net.spll]),
                                  dt, hold)
             for part in ("tde", "cco")}  # fmt: skip
    assert any(pop.startswith("dither_") for pop in params.lif) == (hold == "dithered")
    held = _natively_held(params, counts, holds)
    for part in ("tde", "cco"):
        np.testing.assert_array_equal(units[f"{part}_raster"][:, 0], held[part])
        shortest = holds[part].base + np.minimum(holds[part].step, 0)
        for i in range(net.n_spll):
            assert np.all(np.diff(np.flatnonzero(held[part][:, i])) > shortest[i])
    assert units["tde_counts"].sum() > 100


def test_a_counter_dithers_the_hold_nearest_the_mean_correct_one():
    """counter_dither: the mean hold base + step / period nearest t_refr/dt - 1/2 of the
    candidates a counter makes (period 2..16), never further from it than the undithered
    round(t_refr/dt - 1/2) and from 3 steps on at most 1/12 of a step; a whole or half hold
    exactly; lengthening from 3 steps, shortening from 4."""
    from spll_hw.model.holds import compensated_hold, counter_dither

    dt = 1e-5
    t_refr = np.linspace(20e-6, 1.2e-3, 2001)
    h = t_refr / dt - 0.5
    d = counter_dither(t_refr, dt)
    assert set(np.unique(d.step)) == {-1, 0, 1} and d.period.max() == 16
    assert np.all(np.abs(d.mean - h) <= np.abs(compensated_hold(t_refr, dt) - h) + 1e-12)
    # from 3 steps on, within the widest gap between candidates (1/3 .. 1/2: 1/12)
    assert np.all((np.abs(d.mean - h) <= 1 / 12 + 1e-9)[h >= 3])
    np.testing.assert_array_equal(d.period[d.step == 0], 0)
    assert d.base[d.step == 1].min() >= 3 and d.base[d.step == -1].min() >= 4
    whole = counter_dither(np.array([75e-6, 100e-6, 30e-6]), dt)  # h = 7, 9.5, 2.5
    assert whole.mean.tolist() == [7.0, 9.5, 3.0] and whole.step.tolist() == [0, 1, 0]
    assert counter_dither(np.array([1.2345e-3]), dt).mean[0] == pytest.approx(122.95, abs=1 / 32)


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_run_py_runs_the_dithered_hold_spike_for_spike(net, tmp_path):
    """A folder written with the dithered hold reads back as written (its counters and
    standard.json's refractory_hold) and its run.py on lava-nc (spll-hw unimportable) counts
    exactly what simulate_fixed does."""
    from mappings.lava.export import write_standard

    params = lava_standard(net, dt=DT, hold="dithered")
    assert {"dither_tde", "dither_cco"} <= set(params.lif)
    write_standard(params, tmp_path)
    back = read_standard(tmp_path)
    assert params.difference(back) is None and back.hold == "dithered"
    assert "one spike in n" in (tmp_path / "README.md").read_text()
    duration = 0.1
    x = poisson_train(300.0, duration, seed=3)
    lava = _run_py(tmp_path, x, duration)
    ref = simulate_fixed(back, input_steps(x, duration, DT)[:, None])
    assert lava["tde_counts"] == ref["tde_counts"][0].tolist()
    assert lava["cco_counts"] == ref["cco_counts"][0].tolist()
    assert sum(lava["tde_counts"]) > 20


def test_reference_counts_against_golden(net):
    duration = 0.5
    trains = [poisson_train(300.0, duration, seed) for seed in (0, 1)]
    golden = simulate_batch(net, trains, duration)
    results = StandardFixedPoint(dt=DT).simulate_batch(net, trains, duration)
    errors = [rate_error(r, g) for r, g in zip(results, golden, strict=True)]
    assert max(errors) < 0.12, errors
    for r, g in zip(results, golden, strict=True):
        assert abs(r.cco_counts.sum() / g.cco_counts.sum() - 1) < 0.05


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_lava_standard_backend_equals_the_reference_backend(net):
    x = [poisson_train(300.0, 0.05, seed=7)]
    lava = LavaStandard(dt=DT).simulate_batch(net, x, 0.05)[0]
    ref = StandardFixedPoint(dt=DT).simulate_batch(net, x, 0.05)[0]
    np.testing.assert_array_equal(lava.tde_counts, ref.tde_counts)
    np.testing.assert_array_equal(lava.cco_counts, ref.cco_counts)
    assert lava.backend == "lava-standard"  # DT is the default step


def test_a_gate_passed_is_the_gate_written(net):
    """The builder's own gate passed back gives the same integers; another gate is the one
    written; a gate of another network's size is refused by name."""
    from spll_hw.construction.gate import Gate, GateOptions, gate_levels

    band = gate_levels(net, 8, "band-quantile")
    own = lava_standard(net, GateOptions(8, "band-quantile"), dt=DT)
    given = lava_standard(net, GateOptions(gate=band), dt=DT)
    assert own.difference(given) is None
    uniform = lava_standard(net, GateOptions(8), dt=DT)
    assert uniform.difference(own) is not None  # the two placements differ
    assert given.info()["thresholds_A"] == band.thresholds.tolist()
    with pytest.raises(ValueError, match="the gate has levels for 3 sPLLs, the network has 12"):
        lava_standard(net, GateOptions(gate=Gate(band.thresholds[:3], band.increments[:3])), dt=DT)


def test_every_set_of_decays_gets_its_own_processes_and_thresholds():
    """A time-scaled layout (every sPLL its own time constants) runs one level, TDE and CCO
    process per sPLL, each with the finest vth its own sPLL allows (not the network's worst);
    the README states what lava-nc's runtime costs for it."""
    scaled = Network.time_scaled(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 300.0, 30))
    params = lava_standard(scaled, dt=DT)
    for part in ("level", "tde", "cco"):
        pops = [pop for pop in params.lif if pop.startswith(part)]
        assert len(pops) == 30
        assert sorted(int(params.members[pop][0]) for pop in pops) == list(range(30))
    vth = {int(params.lif[pop]["vth"]) for pop in params.lif if pop.startswith("tde")}
    assert len(vth) > 1 and min(vth) >= 64
    parts = [n_processes(part) for part in split(params.params())]
    assert len(parts) == 30 and params.n_processes == sum(parts)
    assert f"{params.n_processes} Lava processes in 30 sets of decays" in params.readme()
    assert params.info()["lava_processes"] == params.n_processes and not params.notes


def test_the_readme_prints_the_runtime_models_estimate():
    """The README's time and memory for 1 s of input are run.py's model (standalone_run.seconds:
    a start, then per Lava process of each part a compile-and-start, and each step a cost per
    Lava process and per neuron; two jobs start the parts faster) and lava_gb's of the parts
    run.py runs, their processes and neurons."""
    from mappings.lava import standalone_run as run
    from mappings.lava import standard

    params = lava_standard(NetworkConfig.preset("biotac-tuned-vary-offset-lif").with_n(3).build(),
                           dt=DT)  # fmt: skip
    parts = [n_processes(part) for part in split(params.params())]
    neurons = [run.n_neurons(part) for part in split(params.params())]
    assert params.part_processes() == parts and params.part_neurons() == neurons
    assert sum(neurons) == sum(p["bias_mant"].size for p in params.lif.values())
    steps = round(1 / DT)
    start = sum(p * run.PROCESS_START_S for p in parts)
    step = sum(steps * (p * run.PROCESS_STEP_S + m * run.NEURON_STEP_S)
               for p, m in zip(parts, neurons, strict=True))  # fmt: skip
    one = run.START_S + start + step
    two = run.START_S + start / run.PARALLEL_START + step
    costs = [run.part_seconds(p, m, steps) for p, m in zip(parts, neurons, strict=True)]
    assert run.seconds(costs, 1) == pytest.approx(one)
    assert run.seconds(costs, 2) == pytest.approx(two)
    assert run.seconds(costs[:1], 2) == pytest.approx(run.START_S + sum(costs[0]))  # one part
    gb = sorted(parts)[-2:]
    readme = " ".join(params.readme().split())
    assert (f"1 s of input takes about {one / 60:.3g} min and "
            f"{max(parts) * standard.LAVA_PROCESS_MB / 1024:.1f} GB with `--jobs 1` (run.py's "
            f"default), {two / 60:.3g} min and {sum(gb) * standard.LAVA_PROCESS_MB / 1024:.1f} "
            "GB with `--jobs 2`") in readme  # fmt: skip
    assert f"{run.PROCESS_STEP_S * 1e3:.3g} ms per Lava process" in readme
    assert f"{run.NEURON_STEP_S * 1e6:.3g} µs per neuron" in readme


def test_run_py_says_what_is_left_from_the_parts_run_so_far(capsys):
    """After each part but the last, run.py prints what the rest will take: the model's time
    for them scaled by how long the parts so far took against the model's time for those."""
    from mappings.lava import standalone_run as run

    costs = [(1.0, 9.0), (2.0, 18.0), (1.0, 9.0)]  # model: 10 s, 20 s, 10 s
    run._left(25.0, costs, [0], 1)  # the first part took 2.5 times the model's 10 s
    assert "25 s so far, about 1.25 min left (this machine: 2.5 times" in capsys.readouterr().err
    run._left(40.0, costs, [0, 1, 2], 1)
    assert capsys.readouterr().err == ""  # nothing left


def test_run_py_runs_the_parts_one_after_another_unless_told():
    """run.py's --jobs is 1 unless given (on 2 cores parts stepping at once are slower than one
    after another once an input has more than a few hundred steps)."""
    from mappings.lava.standalone_run import _arguments

    assert _arguments().parse_args(["spikes.npy", "1"]).jobs == 1
    assert _arguments().parse_args(["spikes.npy", "1", "--jobs", "2"]).jobs == 2
    assert "default 1" in " ".join(_arguments().format_help().split())


def test_each_target_neuron_gets_the_weight_exponent_of_its_own_trigger(net):
    """One set of decays whose triggers span 2^7: each sPLL's trigger rounds at the exponent
    of its own largest weight (a Dense per exponent), not at the network's largest."""
    from mappings.lava.integers import dense_weights

    spread = Network(tuple(replace(q, g_tde_trg=q.g_tde_trg * 2 ** (7 * i / (net.n_spll - 1)))
                           for i, q in enumerate(net.spll)))  # fmt: skip
    params = lava_standard(spread, dt=DT)
    split = {d[3]: np.abs(d[2]) for name, d in params.dense.items()
             if name.startswith("gate_tde_e")}  # fmt: skip
    assert len(split) > 1 and "gate_tde" not in params.dense
    exp_of = {int(i): e for e, w in split.items() for i in np.flatnonzero(w.sum(axis=1))}
    assert sorted(exp_of) == list(range(net.n_spll))  # each sPLL's trigger in one Dense
    assert exp_of[0] < exp_of[net.n_spll - 1]
    assert all(w.max() > 127 for w in split.values())  # each exponent uses its 8 bits
    # the rounding alone: rows of 1000 and 3 (a_in units) keep 3 exactly beside 1000's 2^2
    weights, vanished = dense_weights(np.array([[1000.0, 500.0], [3.0, 1.2]]), "test")
    assert sorted(weights) == [0, 2] and vanished.size == 0
    assert weights[0].tolist() == [[0, 0], [3, 1]] and weights[2].tolist() == [[250, 125], [0, 0]]


@pytest.fixture(scope="module")
def spanning():
    """biotac-vary-offset-peak on band-quantile levels at 50 µs: each TDE's trigger weights
    span more than 8 bits (1.6 a_in units beside 3120), the smallest under half a unit."""
    net = NetworkConfig.preset("biotac-vary-offset-peak").build()
    return lava_standard(net, replace(EXPORT_GATE, placement="band-quantile"), dt=DT)


def test_a_trigger_spanning_more_than_8_bits_gives_each_weight_its_own_exponent(spanning):
    """Where one TDE's weights span more than one exponent's 8 bits, each takes the exponent
    that fits itself (a Dense per exponent, summed into the TDE) instead of rounding to 0 at
    its largest's; one under half an a_in unit rounds to 0, and the notes say so."""
    from mappings.lava.integers import dense_weights

    trigger = {d[3]: np.abs(d[2]) for name, d in spanning.dense.items()
               if name.startswith("gate_tde_e")}  # fmt: skip
    value = sum(w * 2.0**e for e, w in trigger.items())  # a_in units, (N, gate size)
    nonzero = np.where(value > 0, value, np.inf)
    assert np.max(value.max(axis=1) / nonzero.min(axis=1)) > 255  # one row, beyond 8 bits
    assert all(w[w > 0].min() > 127 for e, w in trigger.items() if e > 0)  # 8 bits each
    assert spanning.notes[0].startswith("sPLLs 0-49: ")
    assert "trigger (g_tde_trg) weights under half of Loihi's smallest" in spanning.notes[0]
    # the rounding alone: 1.6 beside 1000 keeps its own exponent 0, 0.3 rounds to 0; a row
    # within 8 bits keeps its one exponent
    weights, vanished = dense_weights(np.array([[1000.0, 1.6, 0.3], [1000.0, 500.0, 0.0]]), "test")
    assert sorted(weights) == [0, 2] and vanished.size == 0
    assert weights[0].tolist() == [[0, 2, 0], [0, 0, 0]]
    assert weights[2].tolist() == [[250, 0, 0], [250, 125, 0]]
    with pytest.raises(ValueError, match="sPLL 1: a test weight of at most 0.4 .* rounds to 0"):
        dense_weights(np.array([[3.0, 1.0], [0.4, 0.2]]), "test")
    _, vanished = dense_weights(np.array([[3.0, 1.0], [0.4, 0.2]]), "test", may_vanish=True)
    assert vanished.tolist() == [1]


def test_a_trigger_spanning_more_than_8_bits_is_written_and_read_back_to_the_same_spikes(
    spanning, tmp_path
):
    from mappings.lava.export import read_standard, write_standard

    write_standard(spanning, tmp_path)
    back = read_standard(tmp_path)
    assert spanning.difference(back) is None
    counts = input_steps(poisson_train(300.0, 0.05, seed=5), 0.05, DT)[:, None]
    ref, again = simulate_fixed(spanning, counts), simulate_fixed(back, counts)
    for part in ("tde_counts", "cco_counts"):
        np.testing.assert_array_equal(ref[part], again[part])
    assert ref["tde_counts"].sum() > 20


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_run_py_runs_a_trigger_split_over_exponents_spike_for_spike(spanning, tmp_path):
    """The exported run.py on lava-nc (spll-hw unimportable) sums the trigger's Dense of
    several exponents into each TDE exactly as the bit-accurate reference does."""
    from mappings.lava.export import write_standard

    duration = 0.05
    x = poisson_train(300.0, duration, seed=5)
    write_standard(spanning, tmp_path)
    lava = _run_py(tmp_path, x, duration)
    ref = simulate_fixed(spanning, input_steps(x, duration, DT)[:, None])
    assert lava["tde_counts"] == ref["tde_counts"][0].tolist()
    assert lava["cco_counts"] == ref["cco_counts"][0].tolist()
    assert sum(lava["tde_counts"]) > 20


def test_a_feedback_under_loihis_smallest_weight_is_left_out_and_said():
    """vibtac-vary-offset-peak's g_cco (0.117) is under half an a_in unit at the CCO's largest
    threshold: the CCOs run without it (golden: 0.6 % TDE-rate change) and the notes, the
    README and standard.json say so for every sPLL."""
    params = lava_standard(NetworkConfig.preset("vibtac-vary-offset-peak").build(), dt=DT)
    into_cco = {name for name, d in params.dense.items() if d[:2] == ("gate", "cco")}
    assert into_cco == {"gate_cco_start_7", "gate_cco_start_0"}  # its refractory unit's only
    assert len(params.notes) == 1 and params.notes[0].startswith("sPLLs 0-49: g_cco (at most ")
    assert params.info()["notes"] == list(params.notes)
    assert "What the integers leave out" in params.readme() and params.notes[0] in params.readme()


def test_a_kicked_synapse_too_long_for_12_bits_keeps_its_charge(net):
    """At 10 µs a tau_cco_syn of 84 ms needs a 12-bit decay of 0.49: it takes Loihi's longest
    (δ = 1, du = 0, 41 ms), and g_cco is scaled by tau / tau' so that each TDE spike still
    charges the CCO by g_cco * tau_cco_syn; at 50 µs (δ = 2.4, rounded to 2) g_cco stays. A
    tau_tde_fac that long, whose value (not charge) the gate reads, is refused."""
    from mappings.lava.integers import charges, loihi_decays
    from spll_hw.model.roles import roles
    from spll_hw.params import PARAM_NAMES

    r = roles()
    slow = Network(tuple(replace(p, tau_cco_syn=0.084) for p in net.spll))
    p = dict(zip(PARAM_NAMES, slow.matrix().T, strict=True))
    decay = loihi_decays(p, r, 1e-5)
    assert np.all(decay[r.cco_syn.tau] == 1)
    charge_steps = 1 / -np.log1p(-1 / 4096)  # a kick's charge over Loihi's longest decay [dt]
    np.testing.assert_allclose(
        charges(p, r, decay, 1e-5)[r.fed.gain] * charge_steps * 1e-5, p[r.fed.gain] * 0.084
    )
    decay = loihi_decays(p, r, 5e-5)
    assert np.all(decay[r.cco_syn.tau] == 2)
    np.testing.assert_array_equal(charges(p, r, decay, 5e-5)[r.fed.gain], p[r.fed.gain])
    written = lava_standard(slow, dt=1e-5)
    assert written.lif["cco"]["du"] == 0
    assert written.notes[-1].startswith(
        "sPLLs 0-11: tau_cco_syn (at least 0.084 s) is too long for Loihi's 12-bit decays at "
        "dt = 1e-05 s; it decays as the longest they have, 0.041 s"
    ), written.notes
    assert not any("12-bit decays" in note for note in lava_standard(slow, dt=5e-5).notes)
    with pytest.raises(ValueError, match="tau_tde_fac = 0.1 s at dt = 1e-05 s needs a 12-bit"):
        lava_standard(Network(tuple(replace(p, tau_tde_fac=0.1) for p in net.spll)), dt=1e-5)


@pytest.mark.parametrize(("preset", "dt"), [("biotac-vary-offset-peak", 1e-5),
                                            ("biotac-time-scaled-lif", 2.5e-5)])  # fmt: skip
def test_a_free_running_cco_keeps_goldens_period_where_its_decay_rounds(preset, dt):
    """Without input only the offset drives the CCOs. Loihi's 12-bit decay of tau_cco is 27 %
    off on biotac-vary-offset-peak at 10 µs (δ = 1) and 0 (no leak) on biotac-time-scaled-lif's
    slowest CCOs at 25 µs; the offset's bias is calibrated to golden's free-running period, so
    every CCO's count in 1 s is within 1.5 % of golden's (what is left is the hold's whole
    steps, at most half a step a period: 1.3 % on a 700 Hz CCO at 25 µs). With the exact gain
    of the realised decay (before 2026-11-27) they were up to 3.0 % and 6.4 % off."""
    from mappings.lava.integers import loihi_decays
    from spll_hw.model.roles import roles
    from spll_hw.params import PARAM_NAMES

    net = NetworkConfig.preset(preset).build()
    p, r = dict(zip(PARAM_NAMES, net.matrix().T, strict=True)), roles()
    delta = loihi_decays(p, r, dt)[r.cco.tau]
    assert np.any(delta <= 1)
    silent = [np.array([])]
    golden = simulate_batch(net, silent, 1.0)[0].cco_counts
    fixed = StandardFixedPoint(dt=dt).simulate_batch(net, silent, 1.0)[0].cco_counts
    assert golden.min() > 30
    assert np.max(np.abs(fixed / golden - 1)) <= 0.015, (fixed, golden)


def test_networks_lava_standard_cannot_represent_are_refused_by_name(net):
    with pytest.raises(ValueError, match="sPLL 44: t_tde_refr = .* is 1 steps .* dt <= 4.9e-05 s"):
        lava_standard(NetworkConfig.preset("biotac-time-scaled-lif").build(), dt=DT)
    with pytest.raises(ValueError, match="lava-standard: sPLL 5: g_tde_trg = .* smaller dt"):
        lava_standard(NetworkConfig.preset("biotac-tuned-time-scaled-peak").build(), dt=DT)
    with pytest.raises(ValueError, match="tau_tde_fac = .* lava-standard needs 1..4095"):
        lava_standard(net, dt=1e-7)  # a decay below Loihi's 12-bit resolution
    strong = Network(tuple(replace(p, g_tde_trg=1e4) for p in net.spll))
    with pytest.raises(ValueError, match="lava-standard: sPLLs 0-11: g_tde_trg = 10000 .* 16-bit"):
        lava_standard(strong, dt=DT)  # one trigger beyond Loihi's synaptic input
    one_step = Network(tuple(replace(p, t_tde_refr=DT) for p in net.spll))
    with pytest.raises(ValueError, match="t_tde_refr = 5e-05 s is 1 steps .* dt <= 2.5e-05 s"):
        lava_standard(one_step, dt=DT)  # a unit holds 2 steps at least
    with pytest.raises(ValueError, match="drop --profile"):
        export_standard(net, "unused", profile="loihi2")
