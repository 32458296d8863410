"""The import-time fix that makes lava-nc 0.10 import and run on Python 3.11."""

from __future__ import annotations

import hashlib
import importlib.util
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from mappings.lava import compat

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec("lava") is None,
    reason=f"lava-nc is not installed ({compat.INSTALL_HINT})",
)


def _python(code: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter (nothing of Lava imported yet) from the repo root."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )


def _var_model_path() -> Path:
    spec = importlib.util.find_spec("lava")  # a namespace package: no origin, only paths
    return Path(list(spec.submodule_search_locations)[0]) / "magma/compiler/var_model.py"


def test_lava_0_10_fails_on_this_python_without_the_fix():
    """The problem the shim solves is real here (otherwise the shim is not needed)."""
    out = _python("import lava.magma.core.process.process")
    assert out.returncode != 0
    assert "mutable default" in out.stderr and "ByteEncoder" in out.stderr


def test_rewrite_gives_each_instance_its_own_encoder():
    path = _var_model_path()
    tree = compat.rewrite_source(path.read_bytes(), str(path))
    namespace: dict = {"__name__": "patched_var_model"}
    sys.modules["patched_var_model"] = type(sys)("patched_var_model")  # dataclasses need it
    try:
        exec(compile(tree, str(path), "exec"), namespace)
    finally:
        del sys.modules["patched_var_model"]
    a, b = namespace["CoreEncoder"](), namespace["CoreEncoder"]()
    assert a.x == namespace["ByteEncoder"]() and a.x is not b.x
    with pytest.raises(compat.LavaImportError, match="found nothing to patch"):
        compat.rewrite_source("x = 1\n", "not_lava.py")


def test_real_network_runs_in_both_tags_after_multiprocessing_and_leaves_files_alone():
    """A Lava LIF driven by a Dense from a spike generator, in Loihi2SimCfg with both tags, in
    an interpreter that used multiprocessing before importing Lava (Lava's import-time
    ``set_start_method('fork')`` would raise there); the installed source stays byte-identical
    and no bytecode of the patched module is cached."""
    path = _var_model_path()
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    cached = set(path.parent.joinpath("__pycache__").glob("var_model.*"))
    out = _python(
        """
        import multiprocessing as mp
        with mp.Pool(1) as pool:
            pool.map(abs, [1])
        from mappings.lava import compat
        compat.import_lava()
        import numpy as np
        from lava.magma.core.run_conditions import RunSteps
        from lava.magma.core.run_configs import Loihi2SimCfg
        from lava.proc.dense.process import Dense
        from lava.proc.io.source import RingBuffer
        from lava.proc.lif.process import LIF
        for tag, w, vth in (("floating_pt", 0.5, 10.0), ("fixed_pt", 64, 1000)):
            src = RingBuffer(data=np.array([[1, 0, 0, 0, 0]]))
            dense = Dense(weights=np.array([[w]]), num_message_bits=8)
            lif = LIF(shape=(1,), du=0, dv=0, vth=vth)
            src.s_out.connect(dense.s_in)
            dense.a_out.connect(lif.a_in)
            lif.run(condition=RunSteps(num_steps=5), run_cfg=Loihi2SimCfg(select_tag=tag))
            print(tag, float(lif.u.get()[0]), float(lif.v.get()[0]))
            lif.stop()
        """
    )
    assert out.returncode == 0, out.stderr
    lines = dict(line.split(" ", 1) for line in out.stdout.splitlines())
    # Dense delays one step, so u jumps at step 2 and v integrates it for 4 steps. Float: no
    # decay (du = dv = 0). Fixed: u = 64 << 6 = 4096, then Loihi's u decay of 1/4096 per step
    # (du + 1) truncates it to 4095, 4094, 4093; v (dv = 0) sums 4096 + 4095 + 4094 + 4093.
    assert lines["floating_pt"].split() == ["0.5", "2.0"]
    assert lines["fixed_pt"].split() == ["4093.0", "16378.0"]
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before
    assert set(path.parent.joinpath("__pycache__").glob("var_model.*")) == cached


def test_a_missing_lava_names_the_install_command():
    out = _python(
        """
        import sys
        sys.modules["lava"] = None  # as if lava-nc were not installed
        from mappings.lava import compat
        try:
            compat.import_lava()
        except ValueError as exc:  # LavaImportError is an ImportError and a ValueError
            print(type(exc).__name__, exc)
        """
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("LavaImportError")
    assert "--ignore-requires-python" in out.stdout and "[lava]" in out.stdout


def test_installing_after_an_unpatched_import_is_refused():
    out = _python(
        """
        try:
            import lava.magma.compiler.var_model
        except ValueError:
            pass
        import sys
        sys.modules["lava.magma.compiler.var_model"] = type(sys)("lava.magma.compiler.var_model")
        from mappings.lava import compat
        """
    )
    assert out.returncode != 0
    assert "imported before the compatibility fix" in out.stderr
