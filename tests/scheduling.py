"""How pytest-xdist shares the suite between its workers (``scripts/test.sh``: ``-n auto
--dist loadfile``), so that the two cores of CI's machine finish together.

xdist's ``loadfile`` hands each worker whole test files (its module fixtures are built once)
in order of their number of tests, largest first; a file of a few minute-long tests (lava-nc
runs, compiled Brian2) then starts last and runs alone at the end. Here, under ``loadfile``:

- a **work unit** (:func:`work_unit`) is a test file, but for the backend conformance suite,
  whose cases are a unit per backend (the checks of one backend share its runs,
  ``conformance.Runs``), and the files of lava-nc runs (:data:`BY_FUNCTION`), a unit per test
  function, so that their minutes run on both workers;
- units run in order of their **cost** (:func:`order_by_cost`): a test of the slow tier
  (``tests/conftest.py``'s ``SLOW``) weighs :data:`SLOW_WEIGHT` quick ones. The longest units
  start first, and the many short ones fill in at the end.
"""

from __future__ import annotations

from collections import Counter

import pytest

#: Test-id prefixes whose cases form a work unit per parameter that follows the check's name
#: (``test_conformance[CHECK-SPEC]``: a unit per ``SPEC``); check names have no ``-``.
SPLIT = ("tests/test_backend_conformance.py::test_conformance[",)
#: Files of lava-nc runs whose module fixtures take milliseconds: a work unit per test function.
BY_FUNCTION = (
    "tests/test_standard_lava.py::",
    "tests/test_lava_backend.py::",
    "tests/test_graded_current.py::",
)
#: How many quick tests one slow test weighs (a slow one takes ~10-150 s, a quick one ~0.1-1).
SLOW_WEIGHT = 100


def work_unit(nodeid: str) -> str:
    """The work unit of test ``nodeid``: its file; for :data:`SPLIT`'s cases the prefix and
    the parameter after the check's name (``...test_conformance[brian2-cython]``); for
    :data:`BY_FUNCTION`'s its test function (``file::test_name``, every case of it)."""
    for prefix in SPLIT:
        if nodeid.startswith(prefix):
            return prefix + nodeid[len(prefix) :].partition("-")[2]
    if nodeid.startswith(BY_FUNCTION):
        return nodeid.partition("[")[0]
    return nodeid.partition("::")[0]


def order_by_cost(items: list[pytest.Item]) -> None:
    """Sort ``items`` in place, the costliest work unit first (``slow``-marked tests weigh
    :data:`SLOW_WEIGHT`, others 1); a unit's tests keep their order, and so do units of
    equal cost."""
    cost: Counter[str] = Counter()
    first: dict[str, int] = {}
    for i, item in enumerate(items):
        unit = work_unit(item.nodeid)
        cost[unit] += SLOW_WEIGHT if item.get_closest_marker("slow") else 1
        first.setdefault(unit, i)
    items.sort(key=lambda item: (-cost[work_unit(item.nodeid)], first[work_unit(item.nodeid)]))


def make_scheduler(config: pytest.Config, log):
    """xdist's scheduler for ``--dist loadfile`` with :func:`work_unit`'s units, in the order
    the workers collected them (:func:`order_by_cost`); ``None`` (xdist's own) otherwise."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class CostOrderedUnits(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    config.option.loadscopereorder = False  # keep order_by_cost's order, not the test count's
    return CostOrderedUnits(config, log)
