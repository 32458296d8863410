"""The exporters' conformance suite (spll_hw.exporters.conformance) on every registered
exporter, and broken exporters that must fail it.

Every registered export target is a case (a newly registered one gets the whole suite); one
that does not load here (a missing extra) is skipped with the registry's reason.
"""

from __future__ import annotations

from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

from spll_hw import exporters
from spll_hw.exporters import conformance

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

TARGETS = tuple(exporters.names())
CHECKS = tuple(conformance.checks())
#: Known failures, each a strict xfail (it turns red the day the exporter passes, so the entry
#: goes). lava-standard left it when its refractory unit replaced the self-inhibition stand-in
#: (issue 33).
KNOWN_FAILURES: dict[tuple[str, str], str] = {}


@pytest.mark.parametrize("target", TARGETS)
@pytest.mark.parametrize(("check_name", "check"), CHECKS, ids=[name for name, _ in CHECKS])
def test_conformance(target, check_name, check, request):
    try:
        exporters.get(target)
    except ValueError as exc:
        pytest.skip(str(exc))
    if (target, check_name) in KNOWN_FAILURES:
        request.applymarker(
            pytest.mark.xfail(reason=KNOWN_FAILURES[target, check_name], strict=True)
        )
    try:
        check(target)
    except conformance.NotApplicable as exc:
        pytest.skip(f"{check_name} does not apply to {target}: {exc}")


def sloppy_export(network, out, *, profile=None, dt=None):
    """A broken exporter: writes with plain files (not atomically) and takes any dt."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "network.txt"
    path.write_text(f"{network!r} dt={dt}")
    return [path]


def tidy_export(network, out, *, profile=None, dt=None):
    """A third-party exporter that knows nothing of mappings/: its folder written whole or not
    at all through the core's :func:`spll_hw.files.atomic_folder`."""
    from spll_hw.files import atomic_folder

    with atomic_folder(out) as stage:
        (stage / "network.txt").write_text(repr(network))
        (stage / "dt.txt").write_text(repr(dt))
    return [Path(out) / "network.txt", Path(out) / "dt.txt"]


def misread_export(network, out, *, profile=None, dt=None):
    """A broken exporter: the exact NIR export, read back as another network."""
    from mappings.nir import export_folder

    return export_folder(network, out, profile=profile, dt=dt)


def _misread(folder, network):
    from dataclasses import replace

    from mappings.nir.check import read_exact
    from spll_hw.network import Network

    run = read_exact(folder, network)
    other = Network(tuple(replace(p, g_tde_trg=2 * p.g_tde_trg) for p in network.spll))
    golden = run.backend
    return exporters.FolderRun(
        run.runs, golden, lambda trains, t: golden.simulate_batch(other, trains, t)
    )


misread_export.read_back = _misread


@exporters.hands_on_check
def stale_export(network, out, *, profile=None, dt=None, checked=None):
    """A broken exporter: nir-standard, handing on its check with the error wiped out."""
    from dataclasses import replace

    from mappings.nir import export_standard

    def wiped(check):
        checked(replace(check, report=replace(check.report, target="stale", tde_error=0.0)))

    return export_standard(network, out, profile=profile, dt=dt, checked=wiped)


def _stale_read_back(folder, network):
    from mappings.nir.check import read_standard

    return read_standard(folder, network)


stale_export.read_back = _stale_read_back


@pytest.fixture
def broken(monkeypatch):
    """The registry with the exporters of this module beside the real ones."""
    points = {
        name: EntryPoint(name, f"tests.test_exporter_conformance:{name.replace('-', '_')}_export",
                         exporters.GROUP)
        for name in ("sloppy", "tidy", "misread", "stale")
    }  # fmt: skip
    monkeypatch.setattr(exporters, "_entry_points", lambda: points)


def test_a_sloppy_exporter_fails_the_suite(broken):
    with pytest.raises(AssertionError) as exc:
        conformance.check_exporter("sloppy")
    message = str(exc.value)
    assert "refuses_bad_dt: dt = 0.0: accepted" in message
    assert "refuses_unrepresentable: a parameter matrix: accepted" in message
    assert "fails_cleanly: OSError at file 1 of 1: left ['parent']" in message
    assert "writes:" not in message  # what it does write, it lists


def test_an_exporter_outside_the_project_can_pass_the_writing_checks(broken):
    """The suite judges what an exporter writes and returns, not how: one that writes through
    the core's atomic folder alone passes ``writes`` and ``fails_cleanly``."""
    conformance.check_writes("tidy")
    conformance.check_fails_cleanly("tidy")


def test_a_reader_that_reads_another_network_fails_the_round_trip(broken):
    with pytest.raises(AssertionError, match="the folder read back gives TDE counts"):
        conformance.check_round_trip("misread")
    with pytest.raises(AssertionError, match="misread export is off"):
        conformance.check_checks_itself("misread")


def test_an_exporter_that_hands_on_another_check_fails_the_suite(broken):
    with pytest.raises(AssertionError, match="the handed-on check gives TDE/CCO errors 0.0/"):
        conformance.check_hands_on_its_check("stale")
