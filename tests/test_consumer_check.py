"""A consumer outside spll-hw checks an export folder against its ``check.json``: the folder's
``run.py --check`` on lava-nc (exactly) and ``check_consumer.py`` on Norse or snnTorch (within
the float32 tolerance), run where spll-hw cannot be imported; a tampered record fails, naming
the sPLL.

The torch consumers run where the interpreter of ``SPLL_HW_CONSUMER_PYTHON`` (default: this
one) imports torch and the consumer; the test extra installs neither (``.ci/run`` runs them in a
venv of their own)."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from spll_hw import exporters
from spll_hw.config import NetworkConfig
from spll_hw.exporters.check_files import write_check
from spll_hw.exporters.folder_check import check_folder

pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

HAS_LAVA = importlib.util.find_spec("lava") is not None
#: The interpreter that runs the torch consumers.
CONSUMER_PYTHON = os.environ.get("SPLL_HW_CONSUMER_PYTHON", sys.executable)
#: What the shadow packages raise on import.
SHADOWED = "shadowed: this test runs the folder without spll-hw"


@pytest.fixture(scope="module")
def network():
    """The default preset with 4 sPLLs (56-668 Hz)."""
    return NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).build()


@pytest.fixture(scope="module")
def without_spll_hw(tmp_path_factory) -> dict:
    """An environment in which ``spll_hw``, ``mappings`` and ``quantize`` do not import: a
    folder first on ``PYTHONPATH`` holds packages of those names that raise ImportError."""
    shadow = tmp_path_factory.mktemp("shadow")
    for name in ("spll_hw", "mappings", "quantize"):
        (shadow / name).mkdir()
        (shadow / name / "__init__.py").write_text(f"raise ImportError({SHADOWED!r})\n")
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | {"PYTHONPATH": str(shadow)}


def test_the_shadow_hides_spll_hw(without_spll_hw, tmp_path):
    """Outside the repository (a script's folder comes first on sys.path, as the folders'
    scripts run), spll-hw's packages do not import."""
    for name in ("spll_hw", "mappings"):
        done = subprocess.run([sys.executable, "-c", f"import {name}"], cwd=tmp_path,
                              env=without_spll_hw, capture_output=True, text=True,
                              timeout=60)  # fmt: skip
        assert done.returncode != 0 and SHADOWED in done.stderr


def _export(network, target: str, out: Path, dt: float, duration: float) -> dict:
    """Export ``network`` to ``out`` and check it on ``duration`` [s] long inputs; the record."""
    exporters.get(target)(network, out, dt=dt)
    write_check(out, check_folder(out, target, network, duration=duration))
    return json.loads((out / "check.json").read_text())


def _tamper(out: Path, record: dict, i: int, spll: int, by: int) -> None:
    """Add ``by`` to sPLL ``spll``'s TDE count of input ``i`` in the folder's check.json."""
    record["inputs"][i]["tde_counts"][spll] += by
    (out / "check.json").write_text(json.dumps(record))


def test_check_records_every_input_and_its_counts_per_spll(network, tmp_path):
    record = _export(network, "nir-standard", tmp_path, 1e-4, 0.1)
    with np.load(tmp_path / "check_inputs.npz") as data:
        assert [str(x) for x in data["labels"]] == [x["label"] for x in record["inputs"]]
        assert data["durations"].tolist() == [0.1] * len(record["inputs"])
        for x in record["inputs"]:
            assert data[x["train"]].size == x["n_spikes"]
            assert len(x["tde_counts"]) == len(x["cco_counts"]) == network.n_spll
            assert sum(x["tde_counts"]) == x["tde_spikes"]
            assert sum(x["cco_counts"]) == x["cco_spikes"] > 0


def test_a_folder_written_without_its_check_says_so(network, without_spll_hw, tmp_path):
    """check_consumer.py in a folder the writer made without the check (no check.json, no
    check_inputs.npz) exits 2 saying so and how to add them, not with a traceback."""
    exporters.get("nir-standard")(network, tmp_path, dt=1e-4)
    done = subprocess.run([sys.executable, "check_consumer.py", "norse"], cwd=tmp_path,
                          env=without_spll_hw, capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert "no check.json or check_inputs.npz, so there is nothing to compare" in done.stderr
    assert "spll-hw export --check FOLDER --to TARGET" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.skipif(not HAS_LAVA, reason="lava-nc is not installed (the [lava] extra)")
def test_lava_run_py_check_gives_check_json_counts_without_spll_hw(network, tmp_path,
                                                                   without_spll_hw):  # fmt: skip
    """run.py --check runs lava-nc on every input of the folder, inputs of one length as
    copies of the network in one Lava network, and prints its totals beside check.json's
    (which the numpy reference ran an input at a time); one input chosen by number whose
    record was tampered with fails naming the sPLL; a number past the inputs is refused.
    Inputs of 30 ms (600 steps, 29 TDE spikes over the six): lava-nc's steps are most of the
    test's time, and its agreement with the numpy reference over longer runs is
    tests/test_standard_lava.py's."""
    record = _export(network, "lava-standard", tmp_path, 5e-5, 0.03)
    assert sum(x["tde_spikes"] for x in record["inputs"]) > 10

    def check(*which):
        return subprocess.run([sys.executable, "run.py", "--check", *which], cwd=tmp_path,
                              env=without_spll_hw, capture_output=True, text=True,
                              timeout=900)  # fmt: skip

    done = check()
    assert done.returncode == 0, done.stderr[-3000:]
    assert "as check.json does, exactly" in done.stdout
    assert "inputs at once" in done.stderr, done.stderr
    for x in record["inputs"]:  # the table: Lava's totals and check.json's, 0 sPLLs off
        assert f"{x['tde_spikes']} / {x['tde_spikes']}" in done.stdout
    fired = max(range(len(record["inputs"])), key=lambda i: record["inputs"][i]["tde_spikes"])
    _tamper(tmp_path, record, fired, 2, 1)
    done = check(str(fired))
    assert done.returncode == 1
    label = record["inputs"][fired]["label"]
    assert f"{label}: sPLL 2 TDE" in done.stderr and "differs from check.json" in done.stderr
    assert check("99").returncode == 2


def _runs(consumer: str) -> bool:
    code = f"import torch, nir, {consumer}"
    return subprocess.run([CONSUMER_PYTHON, "-c", code], capture_output=True,
                          timeout=300).returncode == 0  # fmt: skip


@pytest.mark.parametrize("consumer", ["norse", "snntorch"])
def test_torch_consumer_gives_check_json_counts_without_spll_hw(network, tmp_path, consumer,
                                                                without_spll_hw):  # fmt: skip
    if not _runs(consumer):
        pytest.skip(f"{CONSUMER_PYTHON} cannot import torch and {consumer}")
    record = _export(network, "nir-standard", tmp_path, 1e-4, 0.2)

    def check():
        return subprocess.run([CONSUMER_PYTHON, "check_consumer.py", consumer], cwd=tmp_path,
                              env=without_spll_hw, capture_output=True, text=True,
                              timeout=900)  # fmt: skip

    done = check()
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    assert "as check.json does, within the tolerance" in done.stdout
    _tamper(tmp_path, record, 5, 1, 50)
    done = check()
    assert done.returncode == 1 and f"{record['inputs'][5]['label']}: " in done.stderr
    assert "sPLL 1 TDE" in done.stderr


def _refused(folder: Path, consumer: str, env: dict) -> subprocess.CompletedProcess:
    """``check_consumer.py consumer`` in ``folder`` (``env``: spll-hw not importable), which
    must exit 2 (it refuses before importing torch); the finished process."""
    done = subprocess.run([sys.executable, "check_consumer.py", consumer], cwd=folder, env=env,
                          capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 2, done.stdout + done.stderr[-3000:]
    return done


def test_a_consumer_that_cannot_run_the_files_dt_is_refused(network, tmp_path, without_spll_hw):
    _export(network, "nir-standard", tmp_path, 5e-5, 0.02)
    assert "python check_consumer.py snntorch" not in (tmp_path / "README.md").read_text()
    assert "python check_consumer.py norse" in (tmp_path / "README.md").read_text()
    done = _refused(tmp_path, "snntorch", without_spll_hw)
    assert "snntorch cannot run it: its NIR import assumes dt = 0.0001 s" in done.stderr
    assert "this folder's consumers: norse" in done.stderr


def test_below_norses_finest_step_no_torch_consumer_is_named(
    network, tmp_path, without_spll_hw, monkeypatch
):
    """Below NORSE_MIN_DT (the finest step measured, 1 µs; raised here to 20 µs so that the
    export at 10 µs stays quick) Norse is listed as unable to run the file, with why; the
    README feeds spll-hw's executor instead and names no check command, and check_consumer.py
    refuses Norse by name."""
    from mappings.nir import consumers
    from mappings.nir.dt_choice import LADDER

    assert consumers.NORSE_MIN_DT == min(LADDER)  # the ladder's finest, where it was measured
    monkeypatch.setattr(consumers, "NORSE_MIN_DT", 2e-5)
    _export(network, "nir-standard", tmp_path, 1e-5, 0.01)
    readme = (tmp_path / "README.md").read_text()
    assert "python check_consumer.py" not in readme and "norse.torch.from_nir" not in readme
    assert "spikes = run_nir(graph, counts.astype(float), dt)" in readme
    assert "* norse: cannot run it at dt = 1e-05 s: below 2e-05 s its loader's float64" in readme
    done = _refused(tmp_path, "norse", without_spll_hw)
    assert "norse cannot run it at dt = 1e-05 s: below 2e-05 s its loader's" in done.stderr
    assert "this folder's consumers: none that check_consumer.py runs" in done.stderr
