"""The conformance suite (spll_hw.backends.conformance) on every registered backend, and a
broken backend that must fail it.

Every registered backend name is a case (a newly registered one gets the whole suite), plus
the chip-profile configurations below; a backend that cannot run here is skipped with the
reason ``backends.listing()`` gives. The checks of one backend share its simulations (one
``conformance.Runs`` per backend, module-scoped), so the slow backends (Lava, Brian2) run the
reference set once; brian2-cpp_standalone runs on a subset of it (SUBSETS).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from spll_hw import backends
from spll_hw.backends import conformance
from spll_hw.backends.golden import GoldenBackend

#: Configurations beside each registered backend's default one.
PROFILE_SPECS = (
    "golden:profile=loihi2",
    "golden:profile=analog",
    "golden-fixed-point:profile=fixed16",
)
SPECS = tuple(backends.names()) + PROFILE_SPECS
#: Reference networks of backends too slow for all three: C++ standalone builds every call
#: (about 20 s on an idle machine for a new shape of network, 8 s for a shape built before in
#: the process), so it runs every check on the first network only; its model is brian2-numpy's,
#: checked on all three.
SUBSETS = {"brian2-cpp_standalone": (0,)}
CHECKS = tuple(conformance.checks())
#: Known failures, each a strict xfail (it turns red the day the backend passes, so the entry
#: goes). standard-fixed-point left it when lava-standard's refractory unit replaced the
#: self-inhibition stand-in (issue 33).
KNOWN_FAILURES: dict[tuple[str, str], str] = {}
#: Backends the suite does not run: lava-nc's Python runtime does ~200 steps/s, one subprocess
#: per sample; tests/test_standard_lava.py checks it bit for bit against standard-fixed-point.
SLOW = {
    "lava-standard": "lava-nc runs ~200 steps/s (one subprocess per sample): too slow for "
    "the suite; its spikes equal standard-fixed-point's bit for bit (test_standard_lava.py)"
}


@pytest.fixture(scope="module")
def runs_of():
    """``runs_of(spec)``: the shared :class:`conformance.Runs` of ``spec`` (skips an
    unavailable backend with the registry's reason)."""
    unavailable = {e.name: e.unavailable for e in backends.listing()}
    cache: dict[str, conformance.Runs] = {}

    def get(spec: str) -> conformance.Runs:
        name, _ = backends.parse_spec(spec)
        if unavailable.get(name):
            pytest.skip(f"{name} is not available here: {unavailable[name]}")
        if spec not in cache:
            cache[spec] = conformance.Runs(conformance.configure(spec), SUBSETS.get(name))
        return cache[spec]

    return get


@pytest.mark.parametrize("spec", SPECS)
@pytest.mark.parametrize(("check_name", "check"), CHECKS, ids=[name for name, _ in CHECKS])
def test_conformance(spec, check_name, check, runs_of, request):
    name, _ = backends.parse_spec(spec)
    if name in SLOW:
        pytest.skip(SLOW[name])
    if (spec, check_name) in KNOWN_FAILURES:
        request.applymarker(pytest.mark.xfail(reason=KNOWN_FAILURES[spec, check_name], strict=True))
    runs = runs_of(spec)
    try:
        check(runs.backend, runs)
    except conformance.NotApplicable as exc:
        pytest.skip(f"{check_name} does not apply to {runs.backend.spec}: {exc}")


def test_check_backend_reports_every_check():
    outcome = conformance.check_backend("golden-fixed-point:profile=fixed16")
    assert list(outcome) == [name for name, _ in CHECKS]
    assert all(v == "passed" for v in outcome.values())


def test_reference_set_is_small_and_fixed():
    cases = conformance.reference_set()
    assert [c.name for c in cases] == ["vary-offset", "time-scaled", "grouped"]
    assert {c.network.layout for c in cases} == {"vary-offset", "time-scaled", "grouped"}
    assert all(3 <= c.network.n_spll <= 5 for c in cases)
    first = cases[0]
    assert first.labels == ("poisson", "periodic", "tail", "empty")
    assert np.any(first.inputs[first.index("tail")] > conformance.REFERENCE_DURATION)
    assert first.inputs[first.index("empty")].size == 0
    # Fixed: the same trains every time (seeded), and not writable by a check.
    again = conformance.reference_trains()
    for (_, x), y in zip(again, first.inputs, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not first.inputs[0].flags.writeable


def test_conformance_options_apply_under_the_spec():
    # standard-fixed-point: a backend with CONFORMANCE_OPTIONS that every install can run.
    assert conformance.configure("standard-fixed-point").options["dt"] == 5e-5
    assert conformance.configure("standard-fixed-point:dt=1e-5").options["dt"] == 1e-5


def test_fixed_point_backends_realise_the_network_as_golden_with_their_profile():
    """The reference of golden-fixed-point:profile=P (at P's own step) is golden:profile=P."""
    net = conformance.reference_set()[0].network
    golden = backends.get("golden:profile=loihi2").realised(net)
    for spec in ("golden-fixed-point", "usb-emulator", "lava-fixed:dt=1e-5"):
        name, _ = backends.parse_spec(spec)
        if name not in backends.available():
            continue
        realised = backends.get(spec).realised(net)
        np.testing.assert_array_equal(realised.matrix(), golden.matrix(), err_msg=spec)


# ---------------------------------------------------------------------- broken backends
class _Broken(GoldenBackend):
    """The golden model with one deliberate fault (registered nowhere)."""

    name = "golden"  # its spec, as the checks compare results' ``backend`` with it


class UnsortedSpikes(_Broken):
    """Reports every sPLL's spike times backwards."""

    def _run(self, prepared, trains, duration, **kwargs):
        results = super()._run(prepared, trains, duration, **kwargs)
        for r in results:
            if r.tde_spikes is not None:
                r.tde_spikes = [s[::-1] for s in r.tde_spikes]
        return results


class IgnoresSeed(_Broken):
    """Draws phase noise from a fixed seed, whatever the caller asks for."""

    def simulate_batch(self, network, inputs, duration, *, seed=None, **kwargs):
        return super().simulate_batch(network, inputs, duration, seed=0, **kwargs)


class DeliversLateInputs(_Broken):
    """Plays its input from a ring buffer as long as the run: spikes after the end come round
    again at ``t - duration`` (its info still counts them as not delivered)."""

    def _run(self, prepared, trains, duration, **kwargs):
        wrapped = [np.sort(np.where(x > duration, x - duration, x)) for x in trains]
        results = super()._run(prepared, wrapped, duration, **kwargs)
        for r, x in zip(results, trains, strict=True):
            r.info["n_input_spikes"] = int(np.count_nonzero(x <= duration))
        return results


class Inaccurate(_Broken):
    """Loses every fourth TDE spike but declares itself exact."""

    def _run(self, prepared, trains, duration, **kwargs):
        results = super()._run(prepared, trains, duration, **kwargs)
        for r in results:
            r.tde_counts = r.tde_counts - r.tde_counts // 4
            if r.tde_spikes is not None:
                r.tde_spikes = [s[: len(s) - len(s) // 4] for s in r.tde_spikes]
        return results


class AcceptsAnything(_Broken):
    """Skips the base class's input validation."""

    def simulate_batch(self, network, inputs, duration, **kwargs):
        try:
            return super().simulate_batch(network, inputs, duration, **kwargs)
        except ValueError:
            return []


class SerialDiffers(_Broken):
    """Serial calls differ from a batch: a single sample runs a little shorter."""

    def _run(self, prepared, trains, duration, **kwargs):
        if len(trains) == 1:
            duration *= 0.9
        return super()._run(prepared, trains, duration, **kwargs)


@pytest.mark.parametrize(
    ("broken", "check_name", "message"),
    [
        (UnsortedSpikes(), "spike_times", "not sorted"),
        (IgnoresSeed(), "seeded_noise", "seed (or the noise) is ignored"),
        (DeliversLateInputs(), "inputs_after_end", "with its spikes after"),
        (Inaccurate(), "agrees_with_golden", "exceeds the declared rate_tolerance"),
        (AcceptsAnything(), "bad_input", "accepted"),
        (SerialDiffers(), "batch_equals_serial", "simulate() against sample"),
    ],
    ids=lambda x: x if isinstance(x, str) else type(x).__name__,
)
def test_broken_backends_fail_their_check(broken, check_name, message):
    check = dict(CHECKS)[check_name]
    with pytest.raises(AssertionError, match=re.escape(message)):
        check(broken, conformance.Runs(broken))
    # ... and check_backend reports it.
    with pytest.raises(AssertionError, match=check_name):
        conformance.check_backend(broken)


def test_a_correct_subclass_passes():
    verdicts = conformance.check_backend(_Broken())
    # an exact (event-driven) backend has no time grid to check
    assert verdicts.pop("input_grid").startswith("not applicable: an exact backend")
    assert set(verdicts.values()) == {"passed"}
