"""Shared fixtures: the thesis's tuned parameter sets and input trains."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from spll_hw import SpllParams

#: Table 6, "VibTac vary offset LIF" (the benchmark's reference workload).
VIBTAC_VARY_OFFSET_LIF = SpllParams(
    tau_cco_syn=7.50e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=6.15e2,
)  # fmt: skip

#: Table 6, "BioTac time-scaled TouchSim".
BIOTAC_TIME_SCALED_TOUCHSIM = SpllParams(
    tau_cco_syn=0.178, tau_cco=0.463, tau_tde_trg=2.36e-3, tau_tde_fac=7.47e-3,
    tau_tde=2.89e-3, g_cco=7.28, g_tde_trg=0.227, g_tde_fac=3.78e4,
)  # fmt: skip


def poisson_train(rate: float, duration: float, seed: int) -> np.ndarray:
    """Sorted Poisson spike times [s] at ``rate`` [Hz] on ``[0, duration)``."""
    rng = np.random.default_rng(seed)
    return np.sort(rng.uniform(0.0, duration, rng.poisson(rate * duration)))


@pytest.fixture
def base_params() -> SpllParams:
    return VIBTAC_VARY_OFFSET_LIF


@pytest.fixture
def full_disk(tmp_path):
    """A real 64 kB filesystem, empty, to write onto until it is full (a tmpfs: mounting it
    needs root, so a test that uses it is skipped, with the reason, where that is not
    permitted)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if shutil.which("mount") is None:
        pytest.skip("no mount command")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)],
                          capture_output=True, text=True)  # fmt: skip
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {done.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)
