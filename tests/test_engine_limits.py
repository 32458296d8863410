"""What the engine refuses up front, and how: thread counts and memory."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np
import pytest

from spll_hw import Network, _engine, backends, limits, network_frequencies, simulate
from spll_hw.cli.main import main
from spll_hw.config import NetworkConfig
from spll_hw.simulate import simulate_batch

from .conftest import VIBTAC_VARY_OFFSET_LIF

P = VIBTAC_VARY_OFFSET_LIF.with_free_frequency(100.0)
NET = Network.vary_offset(VIBTAC_VARY_OFFSET_LIF, network_frequencies(56.2, 668.0, 50))
GIB = 1 << 30


@pytest.fixture
def sixteen_gib(monkeypatch):
    """Memory estimates measured against 16 GiB available (refused above a quarter of it), so
    what is refused does not depend on the machine."""
    monkeypatch.setattr(limits, "available_memory", lambda: 16 * GIB)


def quick(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``, asserted to return or raise within 2 s (refusals allocate
    nothing and start nothing)."""
    start = time.perf_counter()
    try:
        return fn(*args, **kwargs)
    finally:
        assert time.perf_counter() - start < 2.0


# ------------------------------------------------------------------------------------- threads
@pytest.mark.parametrize("threads", [10_000, limits.max_threads() + 1])
def test_thread_counts_beyond_the_cap_are_refused_before_any_start(threads):
    with pytest.raises(ValueError, match=f"threads = {threads} is more than this machine"):
        quick(simulate_batch, P, [[0.1]], 1.0, threads=threads)
    with pytest.raises(ValueError, match="threads"):
        quick(backends.get("golden-fixed-point").simulate_batch, P, [[0.1]], 1.0, threads=threads)


def test_the_bindings_cap_threads_themselves():
    """The Rust core refuses on its own, when the Python checks are bypassed."""
    matrix = Network.single(P).matrix()
    with pytest.raises(ValueError, match="more than this machine can use"):
        quick(_engine.simulate_batch, matrix, [np.array([0.1])], 1.0, False, 10**6)
    fixed = np.zeros((1, len(_engine.FIXED_PARAM_NAMES)), dtype=np.int64)
    fixed[0, _engine.FIXED_PARAM_NAMES.index("cco_threshold")] = 1000
    fixed[0, _engine.FIXED_PARAM_NAMES.index("tde_threshold")] = 1000
    with pytest.raises(ValueError, match="more than this machine can use"):
        quick(_engine.simulate_fixed_point, fixed, [np.array([0.1])], 1e-4, 1.0, 24, 12, False,
              10**6)  # fmt: skip
    assert simulate_batch(P, [[0.1]], 1.0, threads=np.int64(2))[0].duration == 1.0


# -------------------------------------------------------------------------------------- memory
def test_a_recording_bigger_than_memory_allows_is_refused(sixteen_gib):
    # 50 sPLLs for 10^4 s: up to 2 x 10^7 spikes per sPLL, 7.5 GiB of spike times.
    with pytest.raises(ValueError, match=r"recording the spikes of 50 sPLLs for 10000 s .* would "
                       r"need about 7.\d+ GiB.*record_spikes=False"):  # fmt: skip
        quick(simulate, NET, [], 1e4)
    with pytest.raises(ValueError, match="recording the spikes of 50 sPLLs for 1000 s in 10"):
        quick(simulate_batch, NET, [[]] * 10, 1e3, record_spikes=True)
    # A short recording fits.
    assert len(quick(simulate, NET, [], 0.01).cco_spikes) == 50


def test_probe_traces_bigger_than_memory_allows_are_refused(sixteen_gib):
    wide = Network((P,) * 2000)
    with pytest.raises(ValueError, match=r"probing the state of 2000 sPLLs at 100000 times "
                       r"would need about 14.9 GiB"):  # fmt: skip
        quick(simulate, wide, [], 1.0, probe_times=np.linspace(0, 1, 100_000))


def test_inputs_bigger_than_the_engine_can_copy_are_refused(monkeypatch):
    monkeypatch.setattr(limits, "available_memory", lambda: GIB // 2)
    x = np.linspace(0, 1, 10_000_000)
    with pytest.raises(ValueError, match="simulating 10000000 input spikes"):
        quick(simulate, NET, x, 1.0, record_spikes=False)


def test_network_size_must_be_a_positive_integer_and_fit(tmp_path, sixteen_gib):
    base = NetworkConfig.preset("vibtac-vary-offset-lif")
    for n in (0, -3, 2.5, True, "50", float("nan")):
        with pytest.raises(ValueError, match=r"n \(the number of sPLLs\) must be an integer >= 1"):
            replace(base, n=n)
    assert replace(base, n=np.int64(3)).n == 3
    path = tmp_path / "net.toml"
    path.write_text(base.to_toml().replace("n = 50", "n = 10.5"))
    with pytest.raises(ValueError, match=r"net.toml \[network\]: n \(the number"):
        NetworkConfig.from_toml(path)
    with pytest.raises(ValueError, match=r"building a network of 10000000000 sPLLs would need"):
        quick(replace(base, n=10**10).build)


def test_cli_refuses_what_would_exhaust_memory_before_any_work(tmp_path, sixteen_gib, capsys):
    out = tmp_path / "report"
    # (The first call also imports every sub-command: it is not timed.)
    assert main(["simulate", "--periodic", "1e9", "--out", str(out)]) == 2
    assert "(2e+09 spikes) would need about 14.9 GiB" in capsys.readouterr().err
    assert quick(main, ["simulate", "--poisson", "1e12", "--out", str(out)]) == 2
    assert "a Poisson input of 1e+12 Hz for 2 s (2e+12 spikes)" in capsys.readouterr().err
    # Refused before the 10^6 sPLLs are built (which would take a minute).
    path = tmp_path / "big.toml"
    base = NetworkConfig.preset("vibtac-vary-offset-lif")
    path.write_text(base.to_toml().replace("n = 50", "n = 1000000"))
    assert quick(main, ["simulate", "--params", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("spll-hw simulate: error: probing the state of 1000000 sPLLs")
    assert "use fewer sPLLs (n in the [network] table)" in err
    assert not out.exists()
