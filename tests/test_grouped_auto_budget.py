"""`fit --layouts grouped:auto` on a chip with a circuit budget starts at the budget: every G
above it built a grouped layout (quadratic in n) only to be refused, so a 200-sPLL network on
DYNAP-SE2 ran past 5 minutes in silence before saying grouped:1 (issue 62: progress on every
command past ~10 s, and a limit no layout can meet refused before the work)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from spll_hw import chips, layouts
from spll_hw.config import NetworkConfig
from spll_hw.harness import costs


@pytest.mark.parametrize(("profile", "budget"), [("dynapse2", 4), ("analog", 8), ("loihi2", None)])
def test_a_profile_says_its_circuit_budget(profile, budget):
    assert chips.describe(profile).max_circuits == budget


def test_grouped_auto_tries_no_more_groups_than_the_chip_holds(monkeypatch):
    config = NetworkConfig.preset("vibtac-time-scaled-lif").with_n(12)
    tried: list[str] = []
    with_layout = NetworkConfig.with_layout

    def record(self, layout):
        tried.append(layout)
        return with_layout(self, layout)

    monkeypatch.setattr(NetworkConfig, "with_layout", record)
    assert costs.auto_groups(config, "analog") == 8
    assert tried == ["grouped:8"]
    tried.clear()
    assert costs.auto_groups(config, "dynapse2") == 1  # 4 circuits, but one group per core
    assert tried == ["grouped:4", "grouped:3", "grouped:2", "grouped:1"]
    tried.clear()
    assert costs.auto_groups(config, "loihi2") == 12  # no circuit budget: from n
    assert tried == ["grouped:12"]


def test_a_2000_spll_grouped_layout_builds_in_seconds():
    """`fit --layouts grouped:32` of a 2000-sPLL network ran about 4 minutes in silence, all but
    seconds of it in the partition's loop over every start of every group (224 s); with a
    group's starts taken at once the layout builds in about 1.5 s (issue 62)."""
    config = NetworkConfig.preset("vibtac-time-scaled-lif").with_n(2000)
    start = time.perf_counter()
    network = config.with_layout("grouped:32").build()
    assert time.perf_counter() - start < 30
    assert network.n_spll == 2000 and np.unique(network.groups).size == 32


def test_a_long_partition_shows_its_progress(monkeypatch, capsys):
    values = np.geomspace(1.0, 10.0, 50)
    quiet = layouts.partition(values, 4)
    assert capsys.readouterr().err == ""  # little work: no bar
    monkeypatch.setattr(layouts, "PROGRESS_WORK", 0)
    shown = layouts.partition(values, 4)
    assert "partition of 50 values into 4 groups" in capsys.readouterr().err
    assert np.array_equal(shown.boundaries, quiet.boundaries)
