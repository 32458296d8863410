"""The standard construction (mappings/standard/) knows neither of its targets: importing every
module of it loads nothing of mappings/nir/ or mappings/lava/ (the targets import it, never the
other way round), checked in a fresh interpreter."""

import subprocess
import sys

CODE = """
import importlib, pkgutil, sys
import mappings.standard as package
names = [m.name for m in pkgutil.walk_packages(package.__path__, "mappings.standard.")]
for name in names:
    importlib.import_module(name)
print(len(names))
print(" ".join(sorted(m for m in sys.modules if m.startswith(("mappings.nir", "mappings.lava")))))
"""


def test_the_standard_construction_imports_neither_target():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True)
    count, *targets = out.stdout.split("\n")
    assert int(count) >= 4  # backend, construction, reference, the step ladder
    assert not "".join(targets).strip(), f"mappings.standard imported {targets}"
