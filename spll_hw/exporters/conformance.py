"""The conformance suite of exporters: checks that an exporter registered in
``spll_hw.exporters`` keeps the protocol, for every registered exporter (as
:mod:`spll_hw.backends.conformance` does for backends)::

    from spll_hw.exporters import conformance

    conformance.check_exporter("nir-standard")       # AssertionError naming what broke
    for name, check in conformance.checks():          # one pytest case per check
        check("lava-standard")

Every check is a function ``check(target)`` that returns nothing, raises ``AssertionError``
with a message naming the broken rule, or raises ``NotApplicable`` (that of
:mod:`spll_hw.backends.conformance`: an exporter that
declares no ``read_back`` has no round trip to check). They export :data:`REFERENCE` (the
first network of the backends' reference set: 4 sPLLs, 96-486 Hz) with the exporter's defaults
into a temporary folder:

* ``writes``: the folder holds exactly the files the exporter returns, and nothing is left
  beside it (no temporary sibling).
* ``round_trip``: the folder read back (its ``read_back``) simulates spike for spike what the
  backend of the same rules simulates from the network in memory.
* ``checks_itself``: :func:`~spll_hw.exporters.folder_check.check_folder` on :data:`CHECK_DURATION`
  long reference inputs passes at the declared tolerance.
* ``hands_on_its_check``: an exporter that hands the check it ran from memory on
  (:func:`~spll_hw.exporters.hands_on_check`) hands on one, and the folder's check taken from
  it (``from_memory``) is the check of the folder simulated afresh: the same totals and
  per-sPLL errors on the same inputs.
* ``refuses_bad_dt``: a ``dt`` that is not a finite time > 0, or longer than every time
  constant, raises ``ValueError`` naming ``dt``, and leaves nothing behind.
* ``refuses_unrepresentable``: something that is not a network raises ``ValueError``; a network
  with one extreme parameter (:data:`EXTREMES`) is refused with a ``ValueError`` naming that
  parameter, leaving nothing behind, or written into a folder that passes its check.
* ``fails_cleanly``: a full disk in the middle of writing (``OSError(ENOSPC)`` from the last
  file the exporter opens for writing, after part of it is written) and Ctrl-C (at its first)
  leave nothing behind, and the ``OSError`` names the folder. The faults come through Python's
  ``open``, whatever writes the files (``spll_hw.files.atomic_folder`` is the core's way to
  write a folder whole or not at all).
"""

from __future__ import annotations

import argparse
import errno
import io
import math
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from unittest import mock

import numpy as np

from ..backends.conformance import (
    NotApplicable,
    outcomes,
    passed,
    print_outcomes,
    reference_set,
    suite,
)
from ..network import Network
from . import export_checked, get, reader
from .folder_check import check_folder

#: Run length [s] of the inputs of ``checks_itself`` (short: the suite runs every exporter).
CHECK_DURATION = 0.2
#: Extreme parameter values a target may not represent: ``(parameter, value)``.
EXTREMES = (("tau_tde_trg", 1e-8), ("tau_cco", 1e-8), ("g_tde_trg", 1e-12))
#: Time steps [s] no clocked export can run: not a finite time > 0, longer than every time
#: constant of :data:`REFERENCE`, or finer than any chip steps (outside
#: :data:`spll_hw.timestep.STEP_RANGE`: 1e-300 s once overflowed the grid's step count).
BAD_DT = (0.0, -1e-5, math.nan, math.inf, "1e-4 s", 10.0, 1e-300)

#: A check: takes an export target's name.
Check = Callable[[str], None]


def reference():
    """The network every exporter is checked on: the backends' first reference network."""
    return reference_set()[0].network


@contextmanager
def _scratch() -> Iterator[Path]:
    """An empty temporary folder (removed afterwards)."""
    with tempfile.TemporaryDirectory(prefix="spll-export-") as tmp:
        yield Path(tmp)


def _left(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir())


def check_writes(target: str) -> None:
    """The folder (made with its parents) holds exactly the files returned, each in it, and
    nothing else is left beside it."""
    with _scratch() as tmp:
        out = tmp / "deep" / "out"
        files = get(target)(reference(), out)
        assert isinstance(files, list) and files, f"returned {files!r}, not a list of files"
        for path in files:
            path = Path(path)
            assert path.parent == out, f"returned {path}, not a file in {out}"
            assert path.is_file(), f"returned {path}, which does not exist"
        assert sorted(Path(p).name for p in files) == _left(out), (
            f"{out} holds {_left(out)}, the exporter returned {[Path(p).name for p in files]}"
        )
        assert _left(tmp / "deep") == ["out"], f"left beside {out}: {_left(tmp / 'deep')}"


def check_round_trip(target: str) -> None:
    """The folder read back simulates what its backend simulates from memory, spike for
    spike (both parts, every sPLL), on a Poisson and a periodic train of 0.2 s."""
    try:
        read_back = reader(target)
    except ValueError as exc:
        raise NotApplicable(str(exc)) from exc
    network = reference()
    rng = np.random.default_rng(3)
    trains = [np.sort(rng.uniform(0, 0.2, 80)), np.arange(1 / 300, 0.2, 1 / 300)]
    with _scratch() as tmp:
        get(target)(network, tmp / "out")
        run = read_back(tmp / "out", network)
        mine = run.simulate(trains, 0.2)
        theirs = run.backend.simulate_batch(network, trains, 0.2)
    for k, (a, b) in enumerate(zip(mine, theirs, strict=True)):
        for part in ("tde", "cco"):
            x, y = getattr(a, f"{part}_counts"), getattr(b, f"{part}_counts")
            assert np.array_equal(x, y), (
                f"train {k}: the folder read back gives {part.upper()} counts {list(x)}, "
                f"{run.backend.spec} of the network in memory {list(y)}"
            )


def check_checks_itself(target: str) -> None:
    """:func:`~spll_hw.exporters.folder_check.check_folder` of a fresh export passes at the declared
    tolerance, with a finite error for every input on which golden's TDEs fire."""
    try:
        reader(target)
    except ValueError as exc:
        raise NotApplicable(str(exc)) from exc
    with _scratch() as tmp:
        get(target)(reference(), tmp / "out")
        report = check_folder(tmp / "out", target, reference(), duration=CHECK_DURATION)
    assert report.inputs and math.isfinite(report.tde_error), f"check gave {report.to_json()}"
    assert report.passed, report.failure()


def check_hands_on_its_check(target: str) -> None:
    """A :func:`~spll_hw.exporters.hands_on_check` exporter hands on a check, and the folder's
    check taken from it equals the folder's own, simulated afresh."""
    export = get(target)
    if not getattr(export, "hands_on_check", False):
        raise NotApplicable("it does not hand on a check it ran from memory")
    network = reference()
    with _scratch() as tmp:
        _, handed = export_checked(export, network, tmp / "out")
        assert handed is not None, "it declares hands_on_check but handed on no check"
        reused = check_folder(tmp / "out", target, network, checked=handed)
        fresh = check_folder(tmp / "out", target, network)
    assert reused.from_memory and not fresh.from_memory, (
        f"the handed-on check was not taken as the folder's (from_memory {reused.from_memory!r})"
    )
    same = [(reused.tde_error, fresh.tde_error), (reused.cco_error, fresh.cco_error)]
    assert all(math.isclose(a, b, rel_tol=0, abs_tol=1e-12) for a, b in same), (
        f"the handed-on check gives TDE/CCO errors {same[0][0]}/{same[1][0]}, the folder "
        f"simulated afresh {same[0][1]}/{same[1][1]}"
    )
    assert np.array_equal(reused.spll_tde_error, fresh.spll_tde_error), (
        "the handed-on check's per-sPLL TDE errors differ from the folder's own"
    )


def _refused(call: Callable[[Path], object], out: Path, name: str, what: str) -> None:
    """``call(out)`` must raise ``ValueError`` naming ``name`` and leave nothing behind."""
    try:
        call(out)
    except ValueError as exc:
        _assert_refusal(exc, out, name, what)
    except Exception as exc:  # noqa: BLE001 - any other outcome is the failure reported
        raise AssertionError(f"{what}: raised {type(exc).__name__}, not ValueError: {exc}") from exc
    else:
        raise AssertionError(f"{what}: accepted")


def _assert_refusal(exc: ValueError, out: Path, name: str, what: str) -> None:
    assert not out.exists() and _left(out.parent) == [], (
        f"{what}: refused but left {_left(out.parent)} behind"
    )
    assert name in str(exc), f"{what}: ValueError does not name {name!r}: {exc}"


def check_refuses_bad_dt(target: str) -> None:
    """Every ``dt`` of :data:`BAD_DT` raises ``ValueError`` naming ``dt``; nothing is left."""
    export = get(target)
    for dt in BAD_DT:
        with _scratch() as tmp:
            _refused(lambda out, dt=dt: export(reference(), out, dt=dt), tmp / "out", "dt",
                     f"dt = {dt!r}")  # fmt: skip


def check_refuses_unrepresentable(target: str) -> None:
    """A parameter matrix instead of a network raises ``ValueError``; each extreme network of
    :data:`EXTREMES` is refused naming its parameter (nothing left) or written into a folder
    that passes its check."""
    export = get(target)
    with _scratch() as tmp:
        _refused(lambda out: export(reference().matrix(), out), tmp / "out", "Network",
                 "a parameter matrix")  # fmt: skip
    for name, value in EXTREMES:
        network = Network(tuple(replace(p, **{name: value}) for p in reference().spll))
        with _scratch() as tmp:
            out = tmp / "out"
            try:
                export(network, out)
            except ValueError as exc:
                _assert_refusal(exc, out, name, f"{name} = {value}")
                continue
            try:
                reader(target)
            except ValueError:
                continue  # written, and nothing to check it by
            report = check_folder(out, target, network, duration=CHECK_DURATION)
            assert report.passed, f"{name} = {value}: written, but {report.failure()}"


#: Modes of ``open`` that write a file.
_WRITES = set("wax+")


class _Fault:
    """Stands in for ``open`` (``builtins.open`` and ``io.open``, which ``pathlib``,
    ``shutil`` and ``json`` use) while an export runs: counts the files opened for writing
    under ``root`` and makes the ``at``-th (``at`` 0: none) write a few bytes and raise ``exc``
    (a full disk half-way through a file, or Ctrl-C). Files are what an exporter writes, however
    it writes them in Python; nothing of a particular class is assumed."""

    def __init__(self, root: Path, at: int = 0, exc: BaseException | None = None) -> None:
        self.root, self.at, self.exc, self.calls, self.original = root, at, exc, 0, io.open

    def __call__(self, file, mode="r", *args, **kwargs):
        writes = isinstance(file, str | bytes | os.PathLike) and bool(_WRITES & set(mode))
        if writes and Path(os.fsdecode(file)).resolve().is_relative_to(self.root):
            self.calls += 1
            if self.calls == self.at:
                with self.original(file, "wb") as half:
                    half.write(b"\x89HDF half")
                raise self.exc
        return self.original(file, mode, *args, **kwargs)

    @contextmanager
    def patched(self) -> Iterator[_Fault]:
        with mock.patch("builtins.open", self), mock.patch("io.open", self):
            yield self


def check_fails_cleanly(target: str) -> None:
    """A full disk while the last file is written, and Ctrl-C while the first is, leave
    nothing behind (no folder, no temporary sibling, no parent made for it); the ``OSError``
    names the folder. Not applicable to an exporter that writes no file through Python's
    ``open`` (a native writer's full disk cannot be made here)."""
    export = get(target)
    with _scratch() as tmp, _Fault(tmp.resolve()).patched() as counted:
        export(reference(), tmp / "count")
    n_files = counted.calls
    if not n_files:
        raise NotApplicable("it writes no file through Python's open")
    faults = (
        (n_files, OSError(errno.ENOSPC, "No space left on device")),
        (1, KeyboardInterrupt()),
    )
    for at, exc in faults:
        with _scratch() as tmp:
            out = tmp / "parent" / "out"
            with _Fault(tmp.resolve(), at, exc).patched() as fault:
                try:
                    export(reference(), out)
                except type(exc) as raised:
                    message = str(raised)
                else:
                    raise AssertionError(
                        f"{type(exc).__name__} at file {at} of {n_files}: not raised (the "
                        f"exporter opened {fault.calls} files for writing)"
                    )
            what = f"{type(exc).__name__} at file {at} of {n_files}"
            assert _left(tmp) == [], f"{what}: left {_left(tmp)} in {tmp}"
            if isinstance(exc, OSError):
                assert str(out) in message, f"{what}: the error does not name {out}: {message}"


#: Every check as ``(name, function)`` (:func:`~spll_hw.backends.conformance.suite`).
checks = suite(check_writes, check_round_trip, check_checks_itself, check_hands_on_its_check,
               check_refuses_bad_dt, check_refuses_unrepresentable,
               check_fails_cleanly)  # fmt: skip


def check_exporter(target: str) -> dict[str, str]:
    """Run every check on ``target``.

    Returns:
        ``{check name: "passed" or "not applicable: <why>"}``.

    Raises:
        AssertionError: listing every check that failed and why.
    """
    return passed(f"exporter {target!r}", checks(), lambda check: check(target))


def main(argv: list[str] | None = None) -> int:
    """``python -m spll_hw.exporters.conformance TARGET ...``: check each export target."""
    parser = argparse.ArgumentParser(description="conformance suite of spll-hw exporters")
    parser.add_argument("targets", nargs="+", help="export targets, e.g. nir-standard")
    args = parser.parse_args(argv)
    failed = 0
    for target in args.targets:
        done, failures = outcomes(checks(), lambda check: check(target))  # noqa: B023
        print_outcomes(f"{target} ", done, failures)
        failed += len(failures)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
