"""``spll-hw report``: each construction cell costed the way its target realises it (issue 58),
a word on small samples, and one rule for the headline's choice among ties (issue 62)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from spll_hw import backends, chips
from spll_hw.cli.jobs.report import checked_plan
from spll_hw.cli.main import build_parser, main
from spll_hw.config import NetworkConfig
from spll_hw.harness.accuracy import ScoredCell
from spll_hw.harness.costs import CHOICE_WORDS, CostCell, SampleEnergy, cheapest_ties, choose
from spll_hw.neuron_graph import graph_cost, graph_resources
from spll_hw.report.constraints import energy_headline, headline
from spll_hw.report.constraints_score import COSTED_SAMPLES, costed_trains

from .figure_checks import capture_figures
from .pipeline_data import BIOTAC_DIR


@pytest.fixture(scope="module")
def four(tmp_path_factory) -> Path:
    """The default vary-offset preset with 4 sPLLs: its constructions run in a second."""
    path = tmp_path_factory.mktemp("net") / "four.toml"
    path.write_text(NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).to_toml())
    return path


def test_report_costs_each_construction_cell_as_its_target_realises_it(four, tmp_path, monkeypatch):
    """standard-fixed-point at loihi2's 40-us step: its neurons, synapses, cores and dynamic
    energy per sample are graph_cost's of the same run, set against the sPLL's by the range
    rule; standard-exact has no graph of neurons and is scored, not costed."""
    figures = capture_figures(monkeypatch)
    argv = [
        "report", "--network", str(four), "--synthetic-classes", "3", "--synthetic-samples", "6",
        "--duration", "0.5", "--layouts", "vary-offset", "--profiles", "none,loihi2",
        "--steps", "40us", "--constructions", "standard-fixed-point,standard-exact:levels=4",
        "--compare-backends", "golden", "--folds", "2", "--cv-repeats", "2", "--quiet",
        "--jobs", "1", "--out", str(tmp_path / "out"),
    ]  # fmt: skip
    assert main(argv) == 0
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    rows = {(r["construction"], r["profile"]): r for r in results["constructions"]}
    row = rows["standard-fixed-point", "loihi2@40us"]
    # By hand: the construction at the profile's step, run on the report's costed samples.
    args = build_parser().parse_args(argv)
    plan = checked_plan(args, lambda *_: None)
    from spll_hw.cli.inputs import load_split

    samples, _ = load_split(args)
    trains, window = costed_trains(plan.encoder, samples, plan.input_level)
    assert len(trains) == COSTED_SAMPLES
    network = plan.network.config.with_layout("vary-offset").build()
    backend = backends.get("standard-fixed-point", dt=4e-5)
    graph = backend.neuron_graph(network)
    costs = [graph_cost(graph, "loihi2@40us", r)
             for r in backend.simulate_batch(network, trains, window)]  # fmt: skip
    assert row["target"] == "lava-standard" and row["backend"] == backend.spec
    assert (row["neurons"], row["synapses"], row["dt_s"]) == (
        graph.neurons, graph.n_synapses, [4e-5])  # fmt: skip
    assert row["cores"] == graph_resources(graph, "loihi2@40us").cores >= 1
    energy = row["energy_J"]
    assert energy["dynamic"] == pytest.approx(np.mean([c.dynamic_energy for c in costs]))
    assert energy["dynamic_range"] == pytest.approx([
        np.mean([c.dynamic_range.low for c in costs]),
        np.mean([c.dynamic_range.high for c in costs]),
    ])  # fmt: skip
    # Against the two-compartment sPLL of the same layout and column, on the same figures.
    spll = next(c for c in results["costs"]
                if (c["layout"], c["column"]) == ("vary-offset", "loihi2@40us"))  # fmt: skip
    assert spll["cores"] == 1 and spll["energy_J"]["dynamic"] != energy["dynamic"]
    against = row["against_spll"]
    assert against["ratio"] == pytest.approx(energy["dynamic"] / spll["energy_J"]["dynamic"])
    ranges = {k: tuple(v) for k, v in energy["ranges"].items()}
    assert against["cheaper"] == chips.cheaper(energy["counts"], spll["energy_J"]["counts"], ranges)
    # Unstepped columns: no chip tables under none, so neurons but no cores or energy.
    bare = rows["standard-fixed-point", "none"]
    assert bare["neurons"] == backends.get("standard-fixed-point").neuron_graph(network).neurons
    assert bare["cores"] is None and bare["energy_J"] is None
    exact = rows["standard-exact:levels=4", "loihi2@40us"]
    assert exact["neurons"] is None and exact["energy_J"] is None and exact["fits"]
    # The table and the picture say it beside the accuracy change.
    summary = (tmp_path / "out" / "summary.md").read_text()
    start = "| `standard-fixed-point` | vary-offset | loihi2@40us |"
    line = next(x for x in summary.splitlines() if x.startswith(start))
    assert f"| {graph.neurons} | {graph.n_synapses} | 40 µs | {row['cores']} |" in line
    assert against["words"] in line and "the two-compartment sPLL's" in against["words"]
    picture = figures["construction.png"]
    energy_ax = picture.axes[1]
    assert energy_ax.get_yscale() == "log"
    assert [t.get_text() for t in energy_ax.get_xticklabels()] == [
        "two-compartment sPLL", "standard-fixed-point"]  # fmt: skip


def test_report_on_few_samples_says_so_next_to_the_change(tmp_path):
    """6 samples per class: the headline and the summary say the intervals are wide, and
    results.json carries small_sample; 20 per class: no such word."""
    common = ["--layouts", "time-scaled,vary-offset", "--profiles", "none",
              "--compare-backends", "golden", "--folds", "2", "--cv-repeats", "2", "--quiet",
              "--jobs", "1"]  # fmt: skip
    few, many = tmp_path / "few", tmp_path / "many"
    assert main(["report", "--synthetic-classes", "2", "--synthetic-samples", "6", "--duration",
                 "0.3", *common, "--out", str(few)]) == 0  # fmt: skip
    results = json.loads((few / "results.json").read_text())
    assert results["small_sample"] is True and results["samples_per_class"] == 6
    summary = (few / "summary.md").read_text()
    answer = summary.splitlines()[2]
    assert answer.startswith("**Least accuracy lost")
    assert "6 samples per class: intervals are wide" in answer
    table = summary.partition("## Accuracy per layout")[2]
    assert table.index("samples per class: intervals are wide") < table.index("| layout |")
    assert main(["report", "--synthetic-classes", "2", "--synthetic-samples", "20",
                 "--duration", "0.3", *common, "--out", str(many)]) == 0  # fmt: skip
    results = json.loads((many / "results.json").read_text())
    assert results["small_sample"] is False and results["samples_per_class"] == 20
    assert "intervals are wide" not in (many / "summary.md").read_text()
    # Held out: the test samples per class and the recordings the bootstrap resamples.
    held = tmp_path / "held"
    assert main([
        "report", "--dataset", "biotac", "--data", str(BIOTAC_DIR), "--classes", "1,2",
        "--recordings", "1-4", "--holdout-recordings", "4", "--layouts", "time-scaled,vary-offset",
        "--profiles", "none", "--compare-backends", "golden", "--quiet", "--jobs", "1",
        "--out", str(held),
    ]) == 0  # fmt: skip
    results = json.loads((held / "results.json").read_text())
    assert results["small_sample"] is True and results["held_out_recordings"] == 2
    n = results["samples_per_class"]
    assert (
        f"{n} test samples per class from 2 held-out recordings"
        in ((held / "summary.md").read_text().splitlines()[2])
    )


RANGES = {"neuron_update": (1e-12, 3e-12), "step": (1e-9, 2e-9)}


def _cost(layout: str, column: str, cores: int, updates: float, steps: float) -> CostCell:
    """A fitting cell on loihi2's chip whose dynamic energy is ``updates`` and ``steps`` priced
    at the figures of :data:`RANGES`."""
    counts = {"neuron_update": updates, "step": steps}
    ends = {"low": 0, "high": 1}
    at = {k: sum(counts[f] * RANGES[f][end] for f in counts) for k, end in ends.items()}
    values = {k: float(np.mean(v)) for k, v in RANGES.items()}
    energy = SampleEnergy(
        sum(counts[k] * values[k] for k in counts), 0.0, None, None,
        chips.EnergyRange(at["low"], at["high"]), None, counts, dict(RANGES), values,
    )  # fmt: skip
    fit = chips.ChipFit(chips.describe("loihi2"), True, (), cores, 1, "", {}, ())
    return CostCell(layout, column, fit, energy, None, None, ())


def _cell(layout: str, column: str, change: tuple[float, float, float]) -> ScoredCell:
    from spll_hw.stats import Interval

    return ScoredCell(layout, column, "golden", accuracy=Interval(0.8, 0.7, 0.9), mean=0.8,
                      change=Interval(*change))  # fmt: skip


def test_the_headline_chooses_among_ties_by_one_rule_and_names_it():
    """Two columns in the same tie situation name the same kind of choice: two ties where one
    is cheaper at every figure (though its mean is lower) name the cheaper; two the ranges
    cannot rank name the one on fewer cores; ties without a cost model the highest mean; and
    no tie the least loss. The energy headline speaks with the same words."""
    costs, cells = [], []
    for column in ("loihi2@40us", "loihi2@80us"):
        cells += [_cell("grouped:2", column, (0.01, -0.02, 0.04)),
                  _cell("vary-offset", column, (0.0, -0.03, 0.03))]  # fmt: skip
        costs += [
            _cost("grouped:2", column, 1, 2e6, 2e4),
            _cost("vary-offset", column, 1, 1e6, 1e4),
        ]
    for column in ("loihi1@40us", "loihi1@80us"):  # the ranking flips inside the ranges
        cells += [_cell("grouped:2", column, (0.01, -0.02, 0.04)),
                  _cell("grouped:4", column, (0.0, -0.03, 0.03))]  # fmt: skip
        costs += [_cost("grouped:2", column, 3, 4e6, 1e3), _cost("grouped:4", column, 2, 1e6, 4e3)]
    flip = [c for c in costs if c.column == "loihi1@40us"]
    assert chips.cheaper(flip[0].energy.counts, flip[1].energy.counts, RANGES) is None
    for column in ("fixed16", "fixed8"):  # no cost model: the highest mean
        cells += [_cell("grouped:2", column, (0.01, -0.02, 0.04)),
                  _cell("grouped:4", column, (0.0, -0.03, 0.03))]  # fmt: skip
    for column in ("analog", "dynapse2"):  # every layout a loss: the least one
        cells += [_cell("grouped:2", column, (-0.05, -0.08, -0.02)),
                  _cell("grouped:4", column, (-0.1, -0.15, -0.05))]  # fmt: skip
    expected = {
        "loihi2": ("vary-offset", CHOICE_WORDS["cheapest"].format(n=2)),
        "loihi1": ("grouped:4", CHOICE_WORDS["cores"].format(n=2)),
        "fixed": ("grouped:2", CHOICE_WORDS["mean"].format(n=2)),
        "analog": ("grouped:2", CHOICE_WORDS["least loss"]),
        "dynapse2": ("grouped:2", CHOICE_WORDS["least loss"]),
    }
    line = headline(cells, costs)
    columns = list(dict.fromkeys(c.column for c in cells))
    for column in columns:
        chosen = choose([c for c in cells if c.column == column], costs)
        layout, words = next(v for k, v in expected.items() if column.startswith(k))
        assert (chosen.layout, chosen.words()) == (layout, words), column
        assert f"{column}: {layout}, " in line and f"({words})" in line.partition(column)[2]
    # The energy headline, per chip over its steps, speaks the same words.
    found = {f.chip: f for f in cheapest_ties(cells, costs)}
    assert found["loihi2"].kind == "cores"  # the two steps' vary-offset cells cannot be ranked
    assert found["loihi2"].cell.layout == "vary-offset" and found["loihi1"].cell.layout == (
        "grouped:4"
    )
    energy = energy_headline(cells, costs)
    assert all(f.words() in energy for f in found.values())
