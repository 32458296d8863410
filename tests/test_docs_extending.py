"""docs/extending.md's example backend, installed the way the page says (its module in a package
and its line of the ``spll_hw.backends`` entry-point group, read from the page's
``pyproject.toml``), passes the backend conformance suite and prints what the page quotes.

The package is written into a temporary folder with the ``.dist-info`` metadata that ``pip
install -e .`` would write (``entry_points.txt``), so ``spll_hw.backends`` finds it through
``importlib.metadata`` as it finds any installed backend.
"""

from __future__ import annotations

import importlib
import re
import sys
import tomllib
from pathlib import Path

import pytest

from spll_hw import backends
from spll_hw.backends import conformance

DOC = Path(__file__).resolve().parents[1] / "docs" / "extending.md"
SECTION = "## 1. A backend"


def _section(heading: str) -> str:
    """The text of ``heading``'s section of the page, up to the next ``## `` heading."""
    text = DOC.read_text()
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start : end if end > 0 else None]


def _blocks(section: str, lang: str) -> list[str]:
    """The fenced ``lang`` code blocks of ``section``, in order."""
    return re.findall(rf"```{lang}\n(.*?)```", section, re.S)


def _example() -> tuple[str, dict[str, str]]:
    """The section's first Python block (the backend's module) and its entry points
    ``{name: "module:attr"}`` from the section's ``pyproject.toml``."""
    section = _section(SECTION)
    project = tomllib.loads(_blocks(section, "toml")[0])
    return _blocks(section, "python")[0], project["project"]["entry-points"][backends.GROUP]


def _module_of(code: str, name: str):
    """``code`` executed as a fresh module ``name`` (not registered anywhere)."""
    module = type(sys)(name)
    exec(compile(code, f"{DOC}:{name}", "exec"), module.__dict__)
    return module


@pytest.fixture
def installed(tmp_path):
    """The example package installed in ``tmp_path`` (module and entry points), found by the
    backend registry; removed again afterwards."""
    code, entries = _example()
    modules = {target.partition(":")[0] for target in entries.values()}
    assert len(modules) == 1, f"the page's backends live in one module, got {modules}"
    (module,) = modules
    package, _, leaf = module.partition(".")
    (tmp_path / package).mkdir()
    (tmp_path / package / "__init__.py").write_text("")
    (tmp_path / package / f"{leaf}.py").write_text(code)
    dist = tmp_path / f"{package}-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\nVersion: 0.1\n")
    lines = [f"[{backends.GROUP}]", *(f"{k} = {v}" for k, v in entries.items())]
    (dist / "entry_points.txt").write_text("\n".join(lines) + "\n")
    sys.path.insert(0, str(tmp_path))
    importlib.invalidate_caches()
    backends._entry_points.cache_clear()
    backends._configured.cache_clear()
    try:
        yield entries
    finally:
        sys.path.remove(str(tmp_path))
        for name in [m for m in sys.modules if m == package or m.startswith(package + ".")]:
            del sys.modules[name]
        importlib.invalidate_caches()
        backends._entry_points.cache_clear()
        backends._configured.cache_clear()


def test_the_example_backend_passes_the_conformance_suite(installed):
    (name,) = installed
    assert name == "clocked-input" and name in backends.names()
    outcome = conformance.check_backend(name)  # AssertionError naming every failed check
    assert outcome == {check: "passed" for check, _ in conformance.checks()}
    assert backends.get(f"{name}:dt=1e-3").capabilities.dt == 1e-3


def test_the_page_quotes_what_the_suite_prints(installed, capsys):
    bash = _blocks(_section(SECTION), "bash")
    (commands,) = [b for b in bash if "spll_hw.backends.conformance" in b]
    quoted = re.search(r"# (clocked-input: rate error mean .*)", commands).group(1)
    assert conformance.main(["--errors-only", "clocked-input"]) == 0
    assert capsys.readouterr().out.splitlines()[0] == quoted
    coarse = re.search(r"--errors-only (clocked-input:\S+)\s+# mean (\S+)", commands)
    assert conformance.main(["--errors-only", coarse.group(1)]) == 0
    assert f"rate error mean {coarse.group(2)}," in capsys.readouterr().out


def test_binning_by_ceil_instead_of_the_grid_fails_the_input_grid_check():
    """What the page's rule is for: the same backend with ``np.ceil(x / dt) * dt`` puts the
    spikes that lie an ulp above a step's end a step late, and the suite says so."""
    code, _ = _example()
    grid = "spike_steps(x, dt) * dt"
    assert code.count(grid) == 1, "the example bins its input with spike_steps"
    ceil = "import numpy as np\n" + code.replace(grid, "np.ceil(x / dt) * dt")
    backend = _module_of(ceil, "clocked_input_by_ceil").ClockedInput()
    with pytest.raises(AssertionError, match="on step ends"):
        conformance.check_input_grid(backend)
    conformance.check_input_grid(_module_of(code, "clocked_input_by_grid").ClockedInput())


def test_the_example_exporter_passes_the_exporter_conformance_suite(monkeypatch):
    """The page's CSV exporter, registered as the page registers it, passes every check of the
    exporter conformance suite that applies to a folder with no reader, by what it writes and
    returns alone."""
    from importlib.metadata import EntryPoint

    from spll_hw import exporters
    from spll_hw.exporters import conformance as exporter_conformance

    section = _section("## 3. An exporter")
    code = _blocks(section, "python")[0]
    target, entry = re.search(r'`(\w+) = "([\w.:]+)"` in the `spll_hw.exporters` group',
                              section).groups()  # fmt: skip
    module, _, function = entry.partition(":")
    monkeypatch.setitem(sys.modules, module, _module_of(code, module))
    point = EntryPoint(target, entry, exporters.GROUP)
    monkeypatch.setattr(exporters, "_entry_points", lambda: {target: point})
    outcome = exporter_conformance.check_exporter(target)
    assert {k for k, v in outcome.items() if v == "passed"} == {
        "writes", "refuses_bad_dt", "refuses_unrepresentable", "fails_cleanly"
    }  # fmt: skip
    assert function == "export_csv"
