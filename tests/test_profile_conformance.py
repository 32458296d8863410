"""The profile conformance suite (spll_hw.profile_conformance) on every bundled profile and the
documented variant, a broken profile that must fail it, and profile providers: every registered
one counts, and two that bundle the same name are an error."""

from __future__ import annotations

from pathlib import Path

import pytest

import quantize
from quantize.registry import PROFILES, Profiles
from spll_hw import chips
from spll_hw import profile_conformance as conformance

ROOT = Path(__file__).resolve().parents[1]
# The bundled profiles of the installed package (source tree or wheel).
BUNDLED = Path(quantize.__file__).resolve().parent / "profiles"
SOURCES = (*chips.names(), str(ROOT / "docs" / "profiles" / "loihi2-80us.toml"))


@pytest.mark.parametrize("source", SOURCES, ids=[Path(s).stem for s in SOURCES])
@pytest.mark.parametrize(
    ("check_name", "check"), conformance.CHECKS, ids=[n for n, _ in conformance.CHECKS]
)
def test_profile_conformance(source, check_name, check):
    check(source)


def test_a_broken_profile_fails_the_suite_naming_the_problem(tmp_path):
    text = (BUNDLED / "fixed16.toml").read_text()
    broken = tmp_path / "broken.toml"
    broken.write_text(text.replace("state_bits = 16", "state_bits = 1"))
    verdicts = conformance.check_profile(str(broken))
    assert verdicts["loads"].startswith("FAIL") and "state_bits" in verdicts["loads"]
    assert conformance.main([str(broken)]) == 1


def test_capabilities_not_kinds():
    assert chips.describe("loihi2").clocked and not chips.describe("loihi2").mismatch
    assert chips.describe("analog").mismatch and not chips.describe("analog").clocked
    assert chips.describe("loihi2").energy


class _OneMore(Profiles):
    """A second, real provider: quantize's profiles machinery serving one more file."""

    def __init__(self, path: Path, name: str):
        self.path, self.name = path, name

    def names(self):
        return [self.name]

    def describe(self, source):
        return super().describe(str(self.path) if source == self.name else source)

    def realise(self, network, source, seed=None):
        return super().realise(network, str(self.path) if source == self.name else source, seed)


class _EntryPoint:
    def __init__(self, name, obj):
        self.name, self._obj = name, obj

    def load(self):
        return self._obj


@pytest.fixture
def registered(monkeypatch):
    def register(*providers):
        eps = [_EntryPoint(f"p{i}", p) for i, p in enumerate(providers)]
        monkeypatch.setattr(chips, "entry_points", lambda group: eps)
        chips.providers.cache_clear()

    yield register
    chips.providers.cache_clear()


def test_every_registered_provider_counts(registered, tmp_path):
    extra = tmp_path / "mychip.toml"
    extra.write_text(
        (BUNDLED / "fixed16.toml").read_text().replace('name = "fixed16"', 'name = "mychip"')
    )
    registered(PROFILES, _OneMore(extra, "mychip"))
    assert "mychip" in chips.names() and "loihi2" in chips.names()
    assert chips.describe("mychip").name == "mychip"
    assert chips.describe("loihi2").name == "loihi2"


def test_two_providers_of_one_name_are_an_error(registered):
    registered(PROFILES, Profiles())
    with pytest.raises(ValueError, match=r"'\w+' is bundled by two providers.*'p0' and 'p1'"):
        chips.names()


class _NoReadout:
    """A provider of the core interface only: it places no readout."""

    def __init__(self):
        self._inner = Profiles()

    def names(self):
        return self._inner.names()

    def describe(self, source):
        return self._inner.describe(source)


def test_a_provider_without_a_readout_says_so(registered):
    registered(_NoReadout())
    with pytest.raises(ValueError, match="provider of chip profile 'loihi2' does not place a"):
        chips.readout_resources(chips.OnChip(None, "loihi2"), 3)
