"""quantize() keeps its last realisations, keyed on what a realisation depends on: a report that
places a network at the ends of its profile's placement ranges, costs it and simulates it
realised a 2000-sPLL network 17 times for 4 profiles (8.8 s of `spll-hw chips`' 13.5 s;
issue 62). A repeated call gets the same realisation; anything the realisation reads that
differs gets a new one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from quantize import core
from quantize.profiles import load_profile
from spll_hw.config import NetworkConfig


@pytest.fixture
def counted(monkeypatch):
    """How many realisations quantize() computes anew (the real ones, counted)."""
    calls = []
    realised = core._realised

    def counting(*args):
        calls.append(args)
        return realised(*args)

    monkeypatch.setattr(core, "_kept", type(core._kept)())
    monkeypatch.setattr(core, "_realised", counting)
    return calls


def same_network(a, b) -> bool:
    """Equal parameters, layout, scales and groups (a Network's own ``==`` compares its arrays
    field by field on Python 3.13, which no array answers with one bool)."""
    arrays = all(np.array_equal(getattr(a, f), getattr(b, f)) for f in ("scales", "groups"))
    return a.spll == b.spll and a.layout == b.layout and arrays


def test_the_ends_of_a_profiles_placement_ranges_share_one_realisation(counted):
    net = NetworkConfig.preset("vibtac-time-scaled-lif").with_n(12).build()
    profile = load_profile("loihi2")
    variants = [replace(profile, chip=chip) for chip in profile.chip.placements()]
    assert len(variants) == 3
    found = [core.quantize(net, p) for p in variants]
    assert len(counted) == 1
    for q, p in zip(found, variants, strict=True):
        assert q.profile is p and q.requested is net  # each caller's own, as before
        assert q.network is found[0].network and q.fixed is found[0].fixed
    core._kept.clear()
    fresh = core.quantize(net, profile)
    assert len(counted) == 2 and same_network(fresh.network, found[0].network)
    assert np.array_equal(fresh.fixed.matrix, found[0].fixed.matrix)
    assert fresh.report_markdown() == found[0].report_markdown()


def test_what_a_realisation_reads_is_its_key(counted, monkeypatch):
    net = NetworkConfig.preset("vibtac-time-scaled-lif").with_n(12).build()
    core.quantize(net, "loihi2")
    core.quantize(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(12).build(), "loihi2")
    assert len(counted) == 1  # an equal network built again
    core.quantize(net, "loihi2", retune_offset=False)
    core.quantize(net, "loihi1")
    core.quantize(NetworkConfig.preset("vibtac-time-scaled-lif").with_n(13).build(), "loihi2")
    core.quantize(replace(net, scales=net.scales * 2), "loihi2")
    assert len(counted) == 5
    offsets = NetworkConfig.preset("vibtac-vary-offset-lif").with_n(12).build()
    first, other = core.quantize(offsets, "analog"), core.quantize(offsets, "analog", seed=7)
    assert len(counted) == 7 and not same_network(first.network, other.network)  # a new draw
    assert len(core._kept) == 7
    monkeypatch.setattr(core, "KEPT", 2)
    core.quantize(net, "spinnaker")
    assert len(core._kept) == 2 and len(counted) == 8
    core.quantize(offsets, "analog", seed=7)
    assert len(counted) == 8  # one of the two most recent: kept
    core.quantize(net, "loihi2")
    assert len(counted) == 9  # an older one: let go
