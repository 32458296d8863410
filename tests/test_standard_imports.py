"""The tree's layers (issue 61): the core (``spll_hw/``, its command line included, and
``quantize/``) imports no mapping folder (it reaches them through the registries' entry
points), and no mapping folder imports another (``mappings/nir/``
never loads ``mappings/lava/`` and the other way round), each checked in a fresh interpreter
by importing every module of the package."""

import subprocess
import sys

import pytest

CODE = """
import importlib, pkgutil, sys
package = importlib.import_module(sys.argv[1])
skip = tuple(sys.argv[3:])
names = [m.name for m in pkgutil.walk_packages(package.__path__, package.__name__ + ".")
         if not m.name.startswith(skip)]
for name in names:
    importlib.import_module(name)
print(len(names))
forbidden = tuple(sys.argv[2].split(","))
print(" ".join(sorted(m for m in sys.modules if m.startswith(forbidden))))
"""

#: (package, the packages it must not load, modules not imported: ``python -m spll_hw`` runs
#: the command line, and the rest need an optional extra: Lava, torch)
LAYERS = [
    ("spll_hw", "mappings", ("spll_hw.__main__",)),
    ("quantize", "mappings", ()),
    ("mappings.nir", "mappings.lava", ("mappings.nir.consumers",)),
    ("mappings.lava", "mappings.nir", ("mappings.lava.processes",)),
]


@pytest.mark.parametrize(("package", "forbidden", "skip"), LAYERS, ids=[p for p, *_ in LAYERS])
def test_a_layer_imports_nothing_of_the_layers_above_or_beside_it(package, forbidden, skip):
    argv = [sys.executable, "-c", CODE, package, forbidden, *skip]
    out = subprocess.run(argv, capture_output=True, text=True, check=True)
    count, *loaded = out.stdout.split("\n")
    assert int(count) >= 4
    assert not "".join(loaded).strip(), f"{package} imported {loaded}"


def test_the_standard_construction_and_step_ladder_live_in_the_core():
    """The construction, its exact backend and the export's step ladder moved out of
    ``mappings/standard/``, which is gone."""
    import importlib.util

    assert importlib.util.find_spec("mappings.standard") is None
    for name in ("spll_hw.construction.gate", "spll_hw.construction.reference",
                 "spll_hw.backends.standard_exact", "spll_hw.exporters.dt_ladder"):  # fmt: skip
        assert importlib.util.find_spec(name) is not None, name
