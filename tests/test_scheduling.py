"""How the suite is shared between pytest-xdist's workers (tests/scheduling.py)."""

from __future__ import annotations

from dataclasses import dataclass

from tests.scheduling import SLOW_WEIGHT, order_by_cost, work_unit


@dataclass
class Case:
    """What order_by_cost reads of a collected test: its id and whether it is ``slow``."""

    nodeid: str
    slow: bool = False

    def get_closest_marker(self, name: str):
        return name == "slow" and self.slow or None


def test_a_file_is_a_unit_but_the_conformance_suite_and_lava_runs_are_split():
    assert work_unit("tests/test_stats.py::test_a[1]") == "tests/test_stats.py"
    suite = "tests/test_backend_conformance.py::test_conformance["
    cpp, loihi2 = "brian2-cpp_standalone]", "golden:profile=loihi2]"
    assert work_unit(suite + "seeded_noise-" + cpp) == suite + cpp
    assert work_unit(suite + "results-" + loihi2) == suite + loihi2
    other = "tests/test_backend_conformance.py::test_reference_set_is_small_and_fixed"
    assert work_unit(other) == "tests/test_backend_conformance.py"
    lava = "tests/test_standard_lava.py::test_run_py_on_lava_matches"
    assert work_unit(lava + "[vary-offset]") == work_unit(lava + "[grouped:3]") == lava


def test_the_costliest_unit_runs_first_and_each_keeps_its_order():
    quick = [Case(f"tests/test_quick.py::test_{i}") for i in range(SLOW_WEIGHT - 1)]
    lava = [Case("tests/test_lava.py::test_a"), Case("tests/test_lava.py::test_b", slow=True)]
    more = [Case(f"tests/test_more.py::test_{i}") for i in range(SLOW_WEIGHT + 5)]
    items = [*quick, *lava, *more]
    order_by_cost(items)
    # test_more (105 quick) > test_lava (1 + 100) > test_quick (99); each file's own order kept
    assert items == [*more, *lava, *quick]
    lava[0].slow = True
    order_by_cost(items)
    assert items == [*lava, *more, *quick]
