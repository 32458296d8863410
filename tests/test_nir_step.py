"""nir-standard's time step (issue 59): the graph's step guard and the folder's loader. At its
own step the guard changes nothing; at another, every output spikes in every step in the numpy
executor and in Norse, and the shipped ``load_consumer.py`` refuses a wrong step naming the
file's; ``spll-hw export`` prints ``standard.json``'s consumer table."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys

import numpy as np
import pytest

from spll_hw import Network, network_frequencies
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig

from .conftest import VIBTAC_VARY_OFFSET_LIF, poisson_train

nir = pytest.importorskip("nir", reason="the [nir] extra (pip install -e '.[nir]') is missing")

from mappings.nir.consumers import folder_consumers  # noqa: E402
from mappings.nir.executor import input_steps, neuron_nodes, run_nir, step_nir  # noqa: E402
from mappings.nir.files import LOADER_FILE, write_folder  # noqa: E402
from mappings.nir.loader import StepGuardTripped, guard_check  # noqa: E402
from mappings.nir.standard import NODE_NAMES, to_standard_nir  # noqa: E402
from mappings.nir.step_guard import STEP_TOLERANCE  # noqa: E402

DURATION = 0.1
HAS_TORCH = {m: importlib.util.find_spec(m) is not None for m in ("norse", "snntorch", "torch")}


@pytest.fixture(scope="module")
def network():
    return Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 6))


@pytest.fixture(scope="module")
def train():
    return poisson_train(300.0, DURATION, 0)


def _folder(network, dt, path):
    built = to_standard_nir(network, dt=dt)
    write_folder(path, built.graph, info=built.info(), readme=built.readme())
    return path


def _loader(folder):
    """The folder's own load_consumer.py, imported from the folder."""
    spec = importlib.util.spec_from_file_location(
        f"load_consumer_{id(folder)}", folder / LOADER_FILE
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _loaded(network, train, path, consumer):
    """``consumer``'s module of the 100 us folder written to ``path``, loaded by the folder's
    own load_consumer.py: the folder, the loader, the module, its step and ``train``'s input
    steps at it."""
    folder = _folder(network, 1e-4, path)
    loader = _loader(folder)
    module, dt = loader.load(consumer, folder=folder)
    return folder, loader, module, dt, input_steps(train, DURATION, dt)[:, None]


@pytest.mark.parametrize("dt", [1e-4, 5e-5])
def test_at_its_own_step_no_guard_neuron_fires(network, train, dt):
    graph = to_standard_nir(network, dt=dt).graph
    counts: dict = {}
    out = np.array(list(step_nir(graph, input_steps(train, DURATION, dt)[:, None, None], dt,
                                 counts)))  # fmt: skip
    n = network.n_spll
    assert out.sum() > 0
    guard_check(out, dt)  # no StepGuardTripped
    level, gate = counts[NODE_NAMES["level"]][0], counts[NODE_NAMES["gate"]][0]
    assert level[-1] == 0 and gate[-1] == 0  # the fast row and its relay
    assert gate[-2] == 1  # the start pulse, in step 1 only
    assert counts[NODE_NAMES["spll"]][0][4 * n] == 0  # the latch
    assert neuron_nodes(graph)  # every neuron node counted


@pytest.mark.parametrize(
    "ratio", [1e-2, 0.5, 1 - 2 * STEP_TOLERANCE, 1 + 2 * STEP_TOLERANCE, 2, 10]
)
def test_another_step_makes_every_output_spike_in_every_step(network, train, ratio):
    dt = 1e-4
    graph = to_standard_nir(network, dt=dt).graph
    out = run_nir(graph, input_steps(train, DURATION, dt * ratio)[:, None], dt * ratio)
    every = out.all(axis=1)  # every output spiked
    first = int(np.argmax(every))
    assert every[first:].mean() >= (1.0 if ratio > 1 else 0.9)  # from the latch on
    assert first <= (1 if ratio > 0.5 else 2 / ratio)
    with pytest.raises(
        StepGuardTripped, match=r"two successive steps.*step guard fired.*another dt"
    ):
        guard_check(out[:, None, :], dt * ratio)


@pytest.mark.parametrize("ratio", [1 - STEP_TOLERANCE / 4, 1 + STEP_TOLERANCE / 4])
def test_a_step_within_the_tolerance_runs_as_written(network, train, ratio):
    dt = 1e-4
    graph = to_standard_nir(network, dt=dt).graph
    steps = input_steps(train, DURATION, dt)[:, None]
    exact, near = run_nir(graph, steps, dt), run_nir(graph, steps, dt * ratio)
    assert not near.all(axis=1).any()
    assert abs(near.sum() - exact.sum()) <= 0.02 * exact.sum()


def test_the_shipped_loader_refuses_a_wrong_step_naming_the_files(network, tmp_path):
    folder = _folder(network, 1e-4, tmp_path / "nir")
    loader = _loader(folder)
    assert loader.checked_step("norse", None, folder) == 1e-4
    assert loader.checked_step("norse", 1e-4, folder) == 1e-4
    with pytest.raises(ValueError, match=r"written for dt = 0\.0001 s.*got dt = 5e-05 s"):
        loader.checked_step("norse", 5e-5, folder)
    run = subprocess.run([sys.executable, LOADER_FILE, "norse", "1e-3"], cwd=folder,
                         capture_output=True, text=True, check=False)  # fmt: skip
    assert run.returncode == 2
    assert "dt = 0.0001 s" in run.stderr and "dt = 0.001 s" in run.stderr


def test_the_loader_refuses_snntorch_on_a_file_of_another_step_with_the_tables_reason(
    network, tmp_path
):
    folder = _folder(network, 5e-5, tmp_path / "nir")
    reason = json.loads((folder / "standard.json").read_text())["consumers"]["snntorch"]
    assert reason.startswith("cannot run it")
    with pytest.raises(
        ValueError, match="snntorch cannot run it: its NIR import assumes dt = 0.0001"
    ):
        _loader(folder).checked_step("snntorch", None, folder)


def test_printed_consumers_are_standard_jsons_table(network, tmp_path):
    folder = _folder(network, 1e-4, tmp_path / "nir")
    table = json.loads((folder / "standard.json").read_text())["consumers"]
    head, *lines = folder_consumers(folder).splitlines()
    assert "standard.json" in head
    printed = dict(line.strip().split(None, 1) for line in lines)
    assert printed == table
    assert printed["spyx"].startswith("cannot run it") and "loops" in printed["spyx"]
    assert [name for name in printed if printed[name].startswith("runs it")] == [
        "nir-numpy", "norse", "snntorch"
    ]  # fmt: skip
    assert folder_consumers(tmp_path) == ""  # a folder without the table: nothing


def test_export_prints_the_folders_consumer_table(tmp_path, capsys):
    network = tmp_path / "four.toml"
    network.write_text(NetworkConfig.preset("vibtac-vary-offset-lif").with_n(4).to_toml())
    out = tmp_path / "nir"
    args = ["export", "--network", str(network), "--to", "nir-standard", "--out", str(out)]
    assert main([*args, "--dt", "1e-4", "--check-duration", "0.3"]) == 0
    printed = capsys.readouterr().out
    table = json.loads((out / "standard.json").read_text())["consumers"]
    assert folder_consumers(out) in printed and (out / LOADER_FILE).is_file()
    block = printed.split("(standard.json):\n", 1)[1].splitlines()[: len(table)]
    assert dict(line.strip().split(None, 1) for line in block) == table


@pytest.mark.skipif(not (HAS_TORCH["norse"] and HAS_TORCH["torch"]), reason="needs torch and Norse")
def test_norse_given_a_wrong_step_trips_the_guard_and_the_loader_says_so(network, train, tmp_path):
    folder, loader, module, dt, steps = _loaded(network, train, tmp_path / "nir", "norse")
    right = loader.run(module, steps, dt)
    assert np.array_equal(right[:, 0], run_nir(nir.read(folder / "network.nir"), steps, dt))
    for wrong in (5e-5, 1e-3):
        graph = nir.read(folder / "network.nir")
        module = loader.load_module("norse", graph, wrong)  # as a user who passes another dt
        with pytest.raises(loader.StepGuardTripped, match="step guard fired"):
            loader.run(module, input_steps(train, DURATION, wrong)[:, None], wrong)


@pytest.mark.skipif(not (HAS_TORCH["snntorch"] and HAS_TORCH["torch"]), reason="needs snnTorch")
def test_snntorch_through_the_loader_runs_the_100us_file_as_the_executor(network, train, tmp_path):
    folder, loader, module, dt, steps = _loaded(network, train, tmp_path / "nir", "snntorch")
    out = loader.run(module, steps, dt)
    expected = run_nir(nir.read(folder / "network.nir"), steps, dt)
    assert abs(out.sum() - expected.sum()) <= 0.01 * expected.sum()
