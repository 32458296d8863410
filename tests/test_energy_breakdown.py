"""What a sample's energy is spent on, and the accuracy-energy front on ranges.

The breakdown splits each costed cell's dynamic energy into the parts a designer can act on
(neuron updates, synaptic events, spikes, messages and hops, per-step energy), each count ×
figure, static apart; the front keeps a cell unless another is at least as accurate and cheaper
at both ends of the figures' ranges.
"""

from __future__ import annotations

import numpy as np
import pytest

from quantize import load_profile
from spll_hw import chips
from spll_hw.config import NetworkConfig
from spll_hw.harness.accuracy import Column
from spll_hw.harness.breakdown import PARTS, breakdown, levers, markdown, plot_breakdown
from spll_hw.harness.costs import CostCell, SampleEnergy, layout_costs, pareto
from spll_hw.pareto import range_front

from .figure_checks import capture_figures, clipped_texts, legend_over_axes

PRESET = "vibtac-time-scaled-lif"


@pytest.fixture(scope="module")
def cells():
    """vibtac-time-scaled-lif on loihi2 at 10 and 160 µs, 0.5 s of 300 Hz Poisson input."""
    config = NetworkConfig.preset(PRESET)
    train = np.sort(np.random.default_rng(1).uniform(0, 0.5, 150))
    columns = [Column(f"loihi2@{s}", f"loihi2@{s}", f"golden:profile=loihi2@{s}")
               for s in ("10us", "160us")]  # fmt: skip
    return layout_costs(config, ["time-scaled"], columns, [train], 0.5)


def test_the_parts_sum_to_the_dynamic_total_at_the_values_and_at_both_ends(cells):
    for cell in cells:
        b, e = cell.breakdown, cell.energy
        assert [p.name for p in b.parts] == [n for n, _ in PARTS]  # loihi2 prices every part
        assert sum(p.value for p in b.parts) == pytest.approx(e.dynamic, rel=1e-12)
        assert b.dynamic_value == pytest.approx(e.dynamic, rel=1e-12)
        # The parts are counted on the placement at the figures' values; the cost's range
        # spans the placements at the ends of loihi2's placement ranges too (fewer messages
        # crossing cores at the high capacities), so it holds the parts' range, within the
        # messages' share of the energy.
        assert e.dynamic_range.low <= b.dynamic.low and b.dynamic.high <= e.dynamic_range.high
        assert b.dynamic.low == pytest.approx(e.dynamic_range.low, rel=1e-3)
        assert b.dynamic.high == pytest.approx(e.dynamic_range.high, rel=1e-3)
        assert sum(b.share(p) for p in b.parts) == pytest.approx(1.0)
        # Static is apart: not a part, its own range.
        assert b.static == e.static_range and b.static_value == e.static > 0


def test_a_part_is_its_count_times_its_figure_by_hand(cells):
    energy = load_profile("loihi2").chip.energy
    update, step = energy.figure("neuron_update"), energy.figure("step")
    fine, coarse = ({p.name: p for p in c.breakdown.parts} for c in cells)
    # 50 sPLLs of one TDE and one CCO compartment each, updated every step of 0.5 s.
    for parts, steps in ((fine, 50_000), (coarse, 3125)):
        updates, per_step = parts["neuron updates"], parts["per-step energy"]
        assert updates.counts == {"neuron_update": 100 * steps}
        assert updates.value == pytest.approx(100 * steps * update.value)
        assert (updates.low, updates.high) == pytest.approx(
            (100 * steps * update.low, 100 * steps * update.high)
        )
        assert per_step.value == pytest.approx(steps * step.value)
    # The step is the lever: updates and per-step energy fall 16x from 10 to 160 µs, the
    # spikes' parts do not (the same input, nearly the same spikes).
    assert fine["per-step energy"].value == pytest.approx(16 * coarse["per-step energy"].value)
    assert fine["neuron updates"].value == pytest.approx(16 * coarse["neuron updates"].value)
    assert fine["spikes"].value == pytest.approx(coarse["spikes"].value, rel=0.2)
    assert cells[0].breakdown.largest.name == "per-step energy"


def test_the_table_and_the_advice_name_every_cell_and_its_largest_part(cells):
    table = markdown(cells)
    assert table.count("| time-scaled | loihi2@") == 2
    assert "per-step energy" in table.splitlines()[0] and "[low, high], apart" in table
    assert "The largest part is **per-step energy** in 2 cell(s)" in levers(cells)
    assert "a coarser step cuts it" in levers(cells)
    as_json = cells[0].to_dict()["breakdown"]
    assert set(as_json["parts"]) == {n for n, _ in PARTS}
    assert as_json["largest"] == "per-step energy"
    assert sum(p["range_J"][1] for p in as_json["parts"].values()) == pytest.approx(
        as_json["dynamic_J"]["range"][1]
    )


def test_the_picture_stacks_the_parts_with_the_range_and_static_apart(cells, tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    path = tmp_path / "energy_breakdown.png"
    assert plot_breakdown(cells, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig = figures["energy_breakdown.png"]
    dynamic, static = fig.axes
    # One bar per part per cell; the static panel's bars are hatched, one per cell.
    assert len(dynamic.patches) == len(PARTS) * len(cells)
    assert len(static.patches) == len(cells) and all(p.get_hatch() for p in static.patches)
    # The top cell is the first: its stacked bar ends at its dynamic total (linear axis:
    # 10 µs against 160 µs is 16x, under the 20x at which the axis turns logarithmic).
    assert dynamic.get_xscale() == "linear"
    top = [p for p in dynamic.patches if abs(p.get_y() + p.get_height() / 2 - 1) < 1e-9]
    assert max(p.get_x() + p.get_width() for p in top) == pytest.approx(
        cells[0].energy.dynamic / 1e-3
    )  # mJ
    labels = [t.get_text() for t in static.get_legend().get_texts()]
    assert labels[: len(PARTS)] == [n for n, _ in PARTS] and "apart" in labels[-1]
    assert legend_over_axes(static) == 0 and clipped_texts(fig) == []
    assert not plot_breakdown([], tmp_path / "none.png") and not (tmp_path / "none.png").exists()


def test_on_a_log_axis_each_bar_ends_at_its_total_and_splits_by_the_shares(tmp_path, monkeypatch):
    figures = capture_figures(monkeypatch)
    fit = chips.ChipFit(chips.describe("loihi2"), True, (), 1, 1, "", {}, ())
    ranges = {"neuron_update": (1e-12, 1e-12), "step": (1e-9, 1e-9)}
    values = {"neuron_update": 1e-12, "step": 1e-9}

    def costed(updates: float, steps: float) -> CostCell:
        total = updates * 1e-12 + steps * 1e-9
        counts = {"neuron_update": updates, "step": steps}
        span = chips.EnergyRange(total, total)
        energy = SampleEnergy(total, 0.0, None, None, span, None, counts, ranges, values)
        return CostCell("layout", "loihi2", fit, energy, None, None, ())

    # 1 nJ (a quarter of it updates) against 100 nJ: 100x apart, a log axis.
    cells = [costed(250, 0.75), costed(50_000, 50)]
    assert plot_breakdown(cells, tmp_path / "energy_breakdown.png")
    ax = figures["energy_breakdown.png"].axes[0]
    assert ax.get_xscale() == "log"
    left = ax.get_xlim()[0]
    for row, c in zip((1, 0), cells, strict=True):  # the first cell is drawn on top
        bars = [p for p in ax.patches if abs(p.get_y() + p.get_height() / 2 - row) < 1e-9]
        ends = [(p.get_x(), p.get_x() + p.get_width()) for p in bars]
        assert ends[0][0] == pytest.approx(left) and ends[-1][1] == pytest.approx(
            c.energy.dynamic / 1e-9  # nJ
        )
        lengths = [np.log(b / a) for a, b in ends]
        shares = [c.breakdown.share(p) for p in c.breakdown.parts]
        assert np.array(lengths) / sum(lengths) == pytest.approx(shares)


# ------------------------------------------------------------------------ front on ranges
RANGES = {"neuron_update": (0.5e-12, 4e-12), "spike": (1e-12, 3e-12)}
VALUES = {"neuron_update": 1e-12, "spike": 3e-12}


def cell(counts: dict, column: str = "loihi2", ranges=RANGES) -> CostCell:
    """A costed cell of these mean counts on figures ``ranges`` (values :data:`VALUES`)."""
    at = {end: sum(n * ranges[k][end] for k, n in counts.items()) for end in (0, 1)}
    value = sum(n * VALUES[k] for k, n in counts.items())
    energy = SampleEnergy(value, 0.0, None, None, chips.EnergyRange(at[0], at[1]), None,
                          counts, ranges, VALUES)  # fmt: skip
    return CostCell("layout", column, None, energy, None, None, ())


def test_a_range_that_flips_the_ranking_keeps_both_points_on_the_front():
    # A is more accurate and, at the figures' values, cheaper (230 pJ against 280 pJ): on
    # point values B is dominated. But A pays more updates, B more spikes: with updates at
    # their high end and spikes at their low end B is cheaper, so the front keeps both.
    a = cell({"neuron_update": 200, "spike": 10})
    b = cell({"neuron_update": 100, "spike": 60})
    assert a.energy.dynamic < b.energy.dynamic
    assert pareto([a, b], [0.8, 0.7]) == [True, True]
    # A cell cheaper at every figure and as accurate dominates; a less accurate one does not.
    c = cell({"neuron_update": 90, "spike": 50})
    assert pareto([a, b, c], [0.8, 0.7, 0.7]) == [True, False, True]
    assert pareto([b, c], [0.75, 0.7]) == [True, True]


def test_cells_of_two_chips_are_ranked_only_where_their_ranges_do_not_overlap():
    a = cell({"neuron_update": 100, "spike": 10}, "loihi1")
    other = {"neuron_update": (0.5e-12, 4e-12), "spike": (1e-12, 3e-12)}
    b = cell({"neuron_update": 150, "spike": 10}, "loihi2@40us", other)
    # On one chip's figures A would be cheaper throughout; the chips' figures are independent
    # and A's range [60 pJ, 430 pJ] overlaps B's [85 pJ, 630 pJ]: both stay.
    assert chips.cheaper(a.energy.counts, b.energy.counts, RANGES) is True
    assert pareto([a, b], [0.8, 0.8]) == [True, True]
    far = cell({"neuron_update": 1000, "spike": 10}, "loihi2@40us", other)
    assert pareto([a, far], [0.8, 0.8]) == [True, False]


def test_range_front_is_the_point_front_when_the_ranges_are_points():
    cost = [1.0, 2.0, 2.0, 3.0, 0.5]
    accuracy = [0.5, 0.7, 0.6, 0.7, 0.4]
    below = lambda j, i: True if cost[j] < cost[i] else None  # noqa: E731
    assert range_front(accuracy, below) == [0, 1, 2, 4]  # 2 ties 1 on cost: kept
    assert range_front(accuracy, lambda j, i: None) == [0, 1, 2, 3, 4]


def test_breakdown_of_a_figure_no_part_names_is_its_own_part():
    energy = SampleEnergy(
        5e-12, 0.0, None, None, chips.EnergyRange(4e-12, 6e-12), None,
        {"neuron_update": 3, "dendrite": 2}, {"neuron_update": (1e-12, 1e-12),
                                              "dendrite": (0.5e-12, 1.5e-12)},
        {"neuron_update": 1e-12, "dendrite": 1e-12},
    )  # fmt: skip
    b = breakdown(energy)
    assert [p.name for p in b.parts] == ["neuron updates", "dendrite"]
    assert (b.dynamic.low, b.dynamic.high) == pytest.approx((4e-12, 6e-12))
    assert b.dynamic_value == pytest.approx(5e-12) and b.static is None
