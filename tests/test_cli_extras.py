"""A missing optional extra's package names the extra to install (issue 61): the command line's
table of extras (:data:`spll_hw.cli.main.OPTIONAL_EXTRAS`) against pyproject.toml, and the one
line a command prints when scikit-learn is missing."""

import re
import sys
import tomllib
from pathlib import Path

import pytest

from spll_hw.cli import main as cli_main
from spll_hw.cli.main import OPTIONAL_EXTRAS, install_hint, main

PYPROJECT = Path(__file__).resolve().parents[1] / "pyproject.toml"
#: Extras that gather others rather than name a package of their own.
GATHERING = {"all", "test"}


def _declared() -> dict[str, set[str]]:
    """pyproject.toml's extras: ``extra -> {distribution names, normalised}``."""
    extras = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]
    return {extra: {_normal(re.match(r"[A-Za-z0-9._-]+", r).group()) for r in reqs}
            for extra, reqs in extras.items()}  # fmt: skip


def _normal(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


@pytest.mark.parametrize("package", sorted(OPTIONAL_EXTRAS))
def test_every_package_of_the_table_is_declared_in_its_extra(package):
    extra, distribution = OPTIONAL_EXTRAS[package]
    declared = _declared()
    assert extra in declared, f"pyproject.toml declares no extra {extra!r}"
    assert _normal(distribution) in declared[extra], (package, extra, declared[extra])


def test_every_extra_of_pyproject_has_a_package_in_the_table():
    named = {extra for extra, _ in OPTIONAL_EXTRAS.values()}
    assert set(_declared()) - GATHERING <= named


def test_the_hint_names_the_extra_of_a_missing_package_and_only_that():
    missing = ModuleNotFoundError("No module named 'sklearn'", name="sklearn")
    assert install_hint(missing) == "pip install 'spll-hw[pipeline]'"
    submodule = ModuleNotFoundError("No module named 'optuna.storages'", name="optuna.storages")
    assert install_hint(submodule) == "pip install 'spll-hw[tune]'"
    assert "--ignore-requires-python" in install_hint(ModuleNotFoundError(name="lava"))
    assert install_hint(ModuleNotFoundError("No module named 'numpy'", name="numpy")) is None
    assert install_hint(ImportError("something else")) is None
    hinted = ImportError("nir is missing: pip install -e '.[nir]'", name="nir")
    assert install_hint(hinted) is None  # the error says it already


def test_a_command_without_scikit_learn_says_which_extra_to_install(monkeypatch, tmp_path, capsys):
    """The job's import fails as it would without scikit-learn installed; the command prints
    one line naming the extra and exits 2."""

    def job(self, args):
        import sklearn.linear_model  # noqa: F401

    monkeypatch.setitem(sys.modules, "sklearn", None)  # import sklearn: ModuleNotFoundError
    monkeypatch.setattr(cli_main.Job, "__call__", job)
    assert main(["simulate", "--duration", "0.2", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("spll-hw simulate: error: ")
    assert err.endswith("install the optional extra: pip install 'spll-hw[pipeline]'"), err
    assert "\n" not in err
