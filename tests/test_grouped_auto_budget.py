"""`fit --layouts grouped:auto` on a chip with a circuit budget starts at the budget: every G
above it built a grouped layout (quadratic in n) only to be refused, so a 200-sPLL network on
DYNAP-SE2 ran past 5 minutes in silence before saying grouped:1 (issue 62: progress on every
command past ~10 s, and a limit no layout can meet refused before the work)."""

from __future__ import annotations

import pytest

from spll_hw import chips
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
