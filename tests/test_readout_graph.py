"""The multichannel readout as a NIR graph of standard nodes (mappings/nir/readout_graph.py),
decided by mappings/nir/standalone_decide.py: run by spll-hw's executor on random TDE
trains it decides as spll-hw's ``decide`` / ``decide_staged`` on the same spikes moved to their
step's end (class, fired, and the step ``ceil(t*/dt)`` of the decision time); its starter,
counters and stage windows fire in exactly their steps; bad input is a clear ValueError.

The random trains hold spikes of at most one TDE a step: the graph sums a step's spikes into one
jump, where the reference passes simultaneous spikes one at a time (readout_graph's docstring)."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir import standalone_decide as sd  # noqa: E402
from mappings.nir.executor import run_nir  # noqa: E402
from mappings.nir.files import read_graph, write_graph  # noqa: E402
from mappings.nir.readout_graph import (  # noqa: E402
    MAX_COUNT,
    NODE_NAMES,
    Layout,
    ReadoutArrays,
    latest_switch,
    to_readout_nir,
    write_readout,
)
from spll_hw.model.grid import spike_steps  # noqa: E402
from spll_hw.multichannel.readout import (  # noqa: E402
    START,
    Readout,
    StagedReadout,
    decide,
    decide_staged,
)

CLASSES = ("a", "b", "c", "d", "e")


def _readout(rng, k: int, d: int) -> Readout:
    """Mixed-sign weights and biases of the size that makes membranes of TDEs at 30-200 Hz
    cross 0.05-0.4 score x s within a fraction of a second, some only after a dip."""
    return Readout(rng.normal(0, 0.004, (k, d)), rng.normal(0.3, 0.6, k), CLASSES[:k])


def _trains(rng, d: int, steps: int) -> list[np.ndarray]:
    """TDE spike steps (1-based) of one run, at most one TDE a step (a TDE may spike twice in
    its step)."""
    taken = np.zeros(steps + 1, bool)
    out = []
    for _ in range(d):
        n = rng.integers(1, steps + 1, rng.poisson(rng.uniform(30, 200) * steps * 1e-4))
        n = np.sort(n[~taken[n]])
        taken[n] = True
        out.append(np.r_[n, n[rng.random(n.size) < 0.05]])  # a few doubles
    return [np.sort(n) for n in out]


def _reference(readout, trains, steps: int, dt: float, threshold: float, not_before: float):
    """spll-hw's decision on the spikes at their step's end, ``n dt``."""
    spikes = [n * dt for n in trains]
    if isinstance(readout, StagedReadout):
        return decide_staged(readout, spikes, steps * dt, threshold, not_before)
    return decide(readout.membrane_path(spikes, steps * dt), threshold, not_before)


def _graph_decisions(readout, batch, steps, dt, threshold, not_before):
    """The graph's decisions (executor + standalone decide) and its output per step."""
    d = readout.weights.shape[-1]
    counts = np.zeros((steps, len(batch), d))
    for b, trains in enumerate(batch):
        for i, n in enumerate(trains):
            np.add.at(counts[:, b, i], n - 1, 1.0)
    graph = to_readout_nir(readout, threshold, dt, not_before)
    out = run_nir(graph, counts, dt)
    arrays = ReadoutArrays.of(readout)
    made = sd.decide(out, counts, arrays.weights, arrays.bias, threshold, arrays.starts, dt,
                     not_before)  # fmt: skip
    return made, out


CASES = [  # (seed, classes, TDEs, staged, dt, steps)
    (0, 3, 6, False, 1e-4, 5000),
    (1, 4, 8, True, 1e-4, 6000),
    (2, 5, 12, True, 1e-4, 6000),
    (3, 5, 10, False, 1e-4, 6000),
    (4, 4, 9, True, 5e-5, 10000),
]


@pytest.mark.parametrize(("seed", "k", "d", "staged", "dt", "steps"), CASES)
def test_graph_decides_as_spll_hw(seed, k, d, staged, dt, steps):
    rng = np.random.default_rng(seed)
    if staged:  # switched at 0.2 s and 0.4 s (on the grid: k dt, as the spikes)
        readout = StagedReadout(tuple(_readout(rng, k, d) for _ in range(3)),
                                (0.0, round(0.2 / dt) * dt, round(0.4 / dt) * dt))  # fmt: skip
    else:
        readout = _readout(rng, k, d)
    batch = [_trains(rng, d, steps) for _ in range(12)]
    fired, mid = 0, 0
    for threshold in (0.05, 0.15, 0.4, math.inf):
        made, _ = _graph_decisions(readout, batch, steps, dt, threshold, START)
        for b, trains in enumerate(batch):
            ref = _reference(readout, trains, steps, dt, threshold, START)
            expected = (ref.label, int(spike_steps(ref.time, dt)), ref.fired)
            assert tuple(made[b]) == expected, (threshold, b, ref)
            fired += ref.fired
            mid += ref.fired and ref.time > START
    assert fired >= 12 and mid >= 6  # decisions at the switch-on, mid-run and at the end


def test_switches_fire_in_their_steps():
    """Starter in step 1 only, the always row every step, each counter once in its step,
    each stage's window in exactly its steps, no decision before the first of them, even on a
    threshold every membrane passes at once; an empty stage (switched off before not_before)
    never. Stage 0 from step 1 (bias), 2 (starter) and later (counter)."""
    rng = np.random.default_rng(5)
    dt, steps = 1e-4, 400
    parts = tuple(_readout(rng, 3, 4) for _ in range(4))
    for not_before, first in ((0.0, 1), (1.5e-4, 2), (0.01, 100)):
        staged = StagedReadout(parts, (0.0, 0.005, 0.02, 0.03))
        _, out = _graph_decisions(staged, [_trains(rng, 4, steps)], steps, dt, 1e-6, not_before)
        layout = Layout(4, 3, 4, ())
        spikes = out[:, 0]
        cells = spikes[:, layout.sk :]  # the relays: c_cells' spikes, row for row
        assert np.flatnonzero(cells[:, layout.starter]).tolist() == [0]
        assert cells[:, layout.always].all()
        windows = sd.stage_windows(staged.starts, not_before, dt)
        assert windows.first[~windows.empty][0] == first
        for s in range(4):
            on = np.flatnonzero(cells[:, layout.window(s)]) + 1
            if windows.empty[s]:
                assert on.size == 0 and not_before > staged.starts[s + 1]
                continue
            last = min(int(windows.last[s]), steps)
            assert on.tolist() == list(range(int(windows.first[s]), last + 1)), s
        counters = cells[:, layout.starter + 1 :]
        expected = sorted(int(f) - 1 for f, e in zip(windows.first, windows.empty, strict=True)
                          if not e and f >= 3)  # fmt: skip
        assert sorted((np.flatnonzero(counters.any(axis=1)) + 1).tolist()) == expected
        assert counters.sum() == len(expected)
        decisions = spikes[:, : layout.sk]
        first_on = int(windows.first[~windows.empty].min())
        assert not decisions[: first_on - 1].any() and decisions[first_on - 1].any()


def test_counter_counts_to_its_limit():
    """A stage switched on in step MAX_COUNT + 1 is built (its counter's offset is -1 +
    2**-23, exact in float32); one step later is refused, naming the limit."""
    rng = np.random.default_rng(6)
    readout = _readout(rng, 3, 4)
    dt = 1e-4
    graph = to_readout_nir(readout, 0.5, dt, not_before=(MAX_COUNT + 1) * dt)
    offsets = graph.nodes[NODE_NAMES["switch"]].weight
    assert offsets.min() == -(2.0**20) and (-1 + 2.0**-23) in offsets
    assert latest_switch(dt) == pytest.approx((MAX_COUNT + 1) * dt)
    with pytest.raises(ValueError, match=f"count to step {MAX_COUNT + 1}"):
        to_readout_nir(readout, 0.5, dt, not_before=(MAX_COUNT + 1.5) * dt)


def test_written_graph_reads_back_and_runs_alike(tmp_path):
    rng = np.random.default_rng(7)
    readout = StagedReadout(tuple(_readout(rng, 3, 5) for _ in range(2)), (0.0, 0.15))
    graph = to_readout_nir(readout, 0.1, 1e-4)
    back = read_graph(write_graph(tmp_path / "readout.nir", graph))
    counts = rng.poisson(0.02, (2500, 3, 5)).astype(float)
    assert np.array_equal(run_nir(back, counts, 1e-4), run_nir(graph, counts, 1e-4))
    assert back.metadata["format"] == graph.metadata["format"]
    assert {type(n).__name__ for n in back.nodes.values()} <= {
        "Input", "Affine", "Linear", "CubaLIF", "LIF", "Output"
    }  # fmt: skip


def test_standalone_decide_needs_numpy_only(tmp_path):
    source = Path(sd.__file__).read_text()
    imported = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            imported |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            imported.add((node.module or "").split(".")[0])
    assert imported <= {"__future__", "json", "math", "pathlib", "typing", "numpy"}
    times = [0.0, 1e-4, 2e-4, 2.00001e-4, 0.3, 0.1, 0.49e-3, 1.0]
    assert [sd.grid_step(t, 1e-4) for t in times] == spike_steps(times, 1e-4).tolist()
    rng = np.random.default_rng(8)
    w, b = rng.normal(size=(2, 3, 4)), rng.normal(size=(2, 3))
    path = sd.save_readout(tmp_path / sd.READOUT_FILE, w, b, (0.0, 0.5), 0.3, 1e-4,
                           class_names=("x", "y", "z"))  # fmt: skip
    back = sd.load_readout(path)
    assert np.array_equal(back["weights"], w) and np.array_equal(back["bias"], b)
    assert back["class_names"] == ["x", "y", "z"] and back["threshold"] == 0.3
    assert back["starts"].tolist() == [0.0, 0.5] and back["not_before"] == START
    staged = StagedReadout((Readout(w[0], b[0], ("x", "y", "z")),
                            Readout(w[1], b[1], ("x", "y", "z"))), (0.0, 0.5))  # fmt: skip
    again = sd.load_readout(write_readout(tmp_path / "r.npz", staged, 0.3, 1e-4))
    assert all(np.array_equal(again[key], back[key]) for key in sd.DECIDE_KEYS)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"threshold": 0.0}, "threshold must be > 0"),
        ({"threshold": -1.0}, "threshold must be > 0"),
        ({"threshold": math.nan}, "threshold must be > 0"),
        ({"dt": 0.0}, "dt must be a finite time > 0"),
        ({"dt": -1e-4}, "dt must be a finite time > 0"),
        ({"dt": math.inf}, "dt must be a finite time > 0"),
        ({"not_before": -0.1}, "not_before must be a finite time >= 0"),
        ({"weights": math.nan}, "readout weights must be finite"),
        ({"bias": math.inf}, "readout bias must be finite"),
        ({"readout": "ridge"}, "must be a Readout or StagedReadout"),
    ],
)
def test_bad_input_refused(change, message):
    rng = np.random.default_rng(9)
    readout = _readout(rng, 3, 4)
    if "weights" in change:
        readout = Readout(np.full((3, 4), change.pop("weights")), readout.bias, CLASSES[:3])
    if "bias" in change:
        readout = Readout(readout.weights, np.full(3, change.pop("bias")), CLASSES[:3])
    args = {"readout": readout, "threshold": 0.2, "dt": 1e-4, "not_before": START, **change}
    with pytest.raises(ValueError, match=message):
        to_readout_nir(**args)


def test_standalone_decide_refuses_bad_shapes():
    w, b = np.zeros((3, 4)), np.zeros(3)
    with pytest.raises(ValueError, match="output_spikes must have shape"):
        sd.decide(np.zeros((5, 1, 2)), np.zeros((5, 1, 4)), w, b, 0.1, (0.0,), 1e-4)
    with pytest.raises(ValueError, match="tde_counts must have shape"):
        sd.decide(np.zeros((5, 1, 3)), np.zeros((5, 2, 4)), w, b, 0.1, (0.0,), 1e-4)
    with pytest.raises(ValueError, match="readout arrays must be"):
        sd.decide(np.zeros((5, 1, 3)), np.zeros((5, 1, 4)), w, b, 0.1, (0.0, 0.2), 1e-4)
    with pytest.raises(ValueError, match="threshold must be > 0"):
        sd.decide(np.zeros((5, 1, 3)), np.zeros((5, 1, 4)), w, b, 0.0, (0.0,), 1e-4)
