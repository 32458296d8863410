"""simulate_batch releases the GIL; frequency_response shows the thesis's lock-in signature."""

from __future__ import annotations

import threading
import time

import numpy as np

from spll_hw import frequency_response, simulate_batch
from spll_hw.config import NetworkConfig

from .conftest import poisson_train


def test_batch_runs_with_the_gil_released():
    network = NetworkConfig.preset("vibtac-vary-offset-lif").build()
    inputs = [poisson_train(300, 2.0, seed) for seed in range(16)]
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1

    counter = threading.Thread(target=count)
    counter.start()
    start = time.perf_counter()
    simulate_batch(network, inputs, 2.0, threads=1)
    elapsed = time.perf_counter() - start
    done.set()
    counter.join()
    # A thread holding the GIL for the whole call would leave the counter at almost zero.
    assert elapsed > 0.02
    assert ticks > 1000, f"only {ticks} Python ticks during {elapsed:.3f} s of simulation"


def test_frequency_response_locks_in_above_the_free_running_frequency():
    """Thesis Figure 8a: a local minimum at the free-running frequency, then a steep rise
    while the CCO is pulled along (lock-in), then a drop when the lock is lost."""
    params = NetworkConfig.preset("vibtac-time-scaled-peak").spll
    freqs = np.array([20.0, 50.0, 51.0, 52.0, 53.0, 70.0])
    rates = frequency_response(params, 50.0, freqs, 2.0)
    at = dict(zip(freqs, rates, strict=True))
    assert at[50.0] < 2.0
    assert at[51.0] < at[52.0] < at[53.0]
    assert at[53.0] > 20.0 > at[70.0]
    assert at[20.0] < 10.0
