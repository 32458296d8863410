"""Graded CCO currents (mappings/lava/graded_current.py): a GradedVec keeps each CCO's current
finer than Loihi's u and passes it to the CCO every step; what it keeps of a kick, its
integers spike for spike on lava-nc, and the export's rung that uses it."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from mappings.lava.clocks import sub_network
from mappings.lava.export import read_standard, write_standard
from mappings.lava.graded_current import graded_current
from mappings.lava.loihi import DECAY_UNITY, kept_charge, simulate_fixed
from mappings.lava.standard import LavaStandard, lava_standard
from mappings.nir.executor import input_steps
from spll_hw import Network, network_frequencies
from spll_hw.config import NetworkConfig

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train
from .test_standard_lava import DT, _run_py

HAS_LAVA = importlib.util.find_spec("lava") is not None


@pytest.fixture(scope="module")
def net():
    return Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 12))


def _fires(kicks: np.ndarray, delta: int, theta: int, current: str) -> np.ndarray:
    """Which of ``kicks.size`` CCOs (threshold ``theta`` in u units, their membranes not
    leaking) one kick of ``kicks`` a_in units each, into a current decaying by ``delta / 4096``
    a step, takes past the threshold. A relay neuron fires once and kicks every CCO, directly
    and, with ``current="graded"``, through its graded current."""
    m = kicks.size
    zeros = np.zeros(m, np.int64)
    lif = {
        "gate": {"du": 4095, "dv": 4095, "vth": 1, "bias_mant": zeros[:1], "bias_exp": zeros[:1]},
        "cco": {"du": 4095 if current == "graded" else delta - 1, "dv": 0,
                "vth": theta >> 6, "bias_mant": zeros, "bias_exp": zeros},
    }  # fmt: skip
    dense = {
        "input_gate": ("input", "gate", np.array([[2]]), 0, 8),
        "gate_cco": ("gate", "cco", kicks[:, None], 0, 0),
    }
    if current == "graded":
        cur = graded_current("cco", "", delta, kicks, np.ones(m), np.zeros(m, np.int64), 1)
        lif |= cur.lif
        dense |= cur.dense
    params = LavaStandard(1e-4, m, 1, lif, dense, None, {"cco": np.arange(m)})
    counts = np.zeros((40 * DECAY_UNITY // delta, 1), np.int64)
    counts[10 * DECAY_UNITY // delta] = 1  # once the graded currents' pedestal has settled
    return simulate_fixed(params, counts)["cco_counts"][0] > 0


@pytest.mark.parametrize(("kicks", "delta"), [((50, 100), 17), ((30, 60), 9), ((50, 100), 60),
                                             ((50, 100), 301)])  # fmt: skip
def test_a_graded_current_delivers_a_kicks_charge(kicks, delta):
    """A kick of ``k`` a_in units into a current decaying by ``δ / 4096`` charges the
    membrane by ``64 k 4096 / δ`` (u units). Through a LIF's own u it delivers what
    kept_charge says (82-92 % at δ = 9 and 17 with kicks of 30-100 a_in units, the -lif CCOs'
    case, a unit of u lost every step); through a graded current, which rounds each step's
    current to an a_in unit (floors it where its pedestal cannot be placed), at least 95 % and
    never more than the whole: of CCOs kicked by 51 kicks in the range, those whose kick's
    95 % crosses the threshold fire, those whose whole charge does not, do not, and no fewer
    than through a LIF. A δ over 8 bits (301) is split into two Dense."""
    kicks = np.linspace(*kicks, 51).round().astype(np.int64)
    charge = 64 * kicks * DECAY_UNITY / delta
    theta = int(charge[25]) & ~63
    graded = _fires(kicks, delta, theta, "graded")
    assert graded[0.95 * charge > theta].all() and not graded[charge <= theta].any()
    lif = _fires(kicks, delta, theta, "lif")
    kept = charge * kept_charge(64 * kicks, np.full(kicks.size, delta))
    clear = np.abs(kept - theta) > 0.01 * theta
    np.testing.assert_array_equal(lif[clear], (kept > theta)[clear])
    assert graded.sum() >= lif.sum() + (delta < 20)


def test_the_graded_rung_writes_what_it_checked(net, tmp_path):
    """lava_standard(current="graded"): one GradedVec per set of decays (``cur``, marked
    ``graded``), its CCOs' u memoryless; the folder reads back to the same integers, says
    ``cco_current`` in standard.json and GradedVec in its README; an unknown current is
    refused by name."""
    params = lava_standard(net, dt=DT, current="graded")
    assert params.current == "graded" and params.lif["cur"]["graded"] == 1
    assert params.lif["cco"]["du"] == 4095
    assert {"cur_keep", "cur_decay", "cur_cco"} <= set(params.dense)
    write_standard(params, tmp_path)
    back = read_standard(tmp_path)
    assert params.difference(back) is None and back.current == "graded"
    assert back.info()["cco_current"] == "graded"
    assert "GradedVec" in (tmp_path / "README.md").read_text()
    assert lava_standard(net, dt=DT).current == "lif"
    with pytest.raises(ValueError, match="current must be one of"):
        lava_standard(net, dt=DT, current="float")


def test_a_graded_clocked_folder_runs_as_the_backend_that_checked_it(tmp_path):
    """The graded clock per sPLL read back from its folder runs as the backend whose check
    chose it (same options, current included), so the export's check from memory is the
    folder's and is not run a second time."""
    from mappings.lava.check import read_standard as read_back
    from spll_hw.backends import get
    from spll_hw.exporters import FolderRun

    two = NetworkConfig.preset("biotac-time-scaled-lif").with_n(2).build()
    backend = get("standard-fixed-point", clock="per-spll", holds=4, current="graded",
                  levels=64, placement="band-quantile")  # fmt: skip
    write_standard(backend.prepared(two), tmp_path)
    memory = FolderRun.by_backend("memory", backend, two)
    assert read_back(tmp_path, two).runs_as(memory, two)
    lif = get("standard-fixed-point", clock="per-spll", holds=4, levels=64,
              placement="band-quantile")  # fmt: skip
    assert not read_back(tmp_path, two).runs_as(FolderRun.by_backend("lif", lif, two), two)


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
@pytest.mark.parametrize("preset", [None, "biotac-time-scaled-lif"])
def test_run_py_runs_graded_currents_spike_for_spike(net, tmp_path, preset):
    """run.py on lava-nc (spll-hw unimportable) counts exactly what simulate_fixed does with
    graded currents: Lava's GradedVec and graded Dense are the arithmetic loihi.py states
    (a vary-offset network, and two sPLLs of -lif at the step of the faster's clock, for 30 ms:
    1875 of lava-nc's steps of 59 processes, 7 TDE spikes and 4 of the slower CCO's)."""
    if preset is not None:
        net = sub_network(NetworkConfig.preset(preset).build(), np.array([20, 49]))
    params = lava_standard(net, dt=DT if preset is None else 1.6e-5, current="graded")
    write_standard(params, tmp_path)
    duration = 0.1 if preset is None else 0.03
    x = poisson_train(300.0, duration, seed=3)
    lava = _run_py(tmp_path, x, duration)
    ref = simulate_fixed(read_standard(tmp_path), input_steps(x, duration, params.dt)[:, None])
    assert lava["tde_counts"] == ref["tde_counts"][0].tolist()
    assert lava["cco_counts"] == ref["cco_counts"][0].tolist()
    assert sum(lava["tde_counts"]) > 5 and min(lava["cco_counts"]) > 0


def test_the_ladder_tries_graded_currents_after_the_clock_per_spll(monkeypatch):
    """Where no step passes and the clock per sPLL with LIF currents fails, the ladder tries
    the same clock with graded CCO currents and 64 levels, and writes it where it passes; its
    trial is the check of what lava_standard(current="graded") writes."""
    from dataclasses import replace

    from mappings.lava import dt_choice

    def trial(network, dt, placement, levels=None, hold=None, duration=1.0):
        return dt_choice.Trial(dt, 0.12, 0.07, np.zeros(1), placement=placement, levels=levels,
                               hold=hold)  # fmt: skip

    lif = dt_choice.Trial(float("nan"), 0.083, 0.07, np.zeros(1), placement="band-quantile",
                          levels=32, clock=dt_choice.CLOCK)  # fmt: skip
    graded = replace(lif, error=0.065, levels=64, clock=dt_choice.GRADED_CLOCK)
    monkeypatch.setattr(dt_choice, "trial", trial)
    rungs = (lambda _, **__: lif, lambda _, **__: graded)
    monkeypatch.setattr(dt_choice, "PARTS", replace(dt_choice.PARTS, last=rungs))
    one = Network(NetworkConfig.preset("biotac-time-scaled-lif").build().spll[:1])
    lines = []
    chosen = dt_choice.choose_dt(one, log=lines.append)
    assert chosen.clock == dt_choice.GRADED_CLOCK and chosen.passed
    assert lines[-2:] == [
        "lava-standard: a clock per sPLL (R = 4), 32 band-quantile gate levels: TDE-rate error "
        "8.3 %, limit 7 %: fails",
        "lava-standard: a clock per sPLL (R = 4) with graded CCO currents, 64 band-quantile gate "
        "levels: TDE-rate error 6.5 %, limit 7 %: passes",
    ]
    monkeypatch.undo()
    two = sub_network(NetworkConfig.preset("biotac-time-scaled-lif").build(), np.array([0, 49]))
    real = dt_choice.graded_clock_trial(two)
    assert real.clock == dt_choice.GRADED_CLOCK and real.levels == 64 and real.error is not None
    assert real.checked.run.backend.options["current"] == "graded"
