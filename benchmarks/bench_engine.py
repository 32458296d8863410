"""Speed of the golden engine on the reference workload of issue 2, beside Brian2 if installed.

Workload: 50-sPLL vary-offset network, Table 6 "VibTac vary offset LIF" parameters, free
frequencies 56.2-668 Hz linear, 2 s of 300 Hz Poisson input (seed 0 for the first sample).

    python benchmarks/bench_engine.py            # golden engine only
    python benchmarks/bench_engine.py --brian2   # also Brian2 cpp_standalone at dt = 10 us

Prints events/s and ms/sample for one core (and the fixed-point reference's ms/sample, loihi2 at
dt = 10 us, beside it), the same for the README demo's network (preset vibtac-time-scaled-lif,
time-scaled layout: more TDE spikes, larger CCO synapse currents) on the same trains, the batch
speed-up over all cores, and (with --brian2) the run time of a plain Brian2 model of the same
equations (benchmarks/plain_brian2.py) and of spll-hw's own Brian2 mapping, with their TDE-count
errors against the golden model, in the same process.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from spll_hw import Network, SpllParams, backends, network_frequencies, simulate, simulate_batch
from spll_hw.config import NetworkConfig

PARAMS = SpllParams(
    tau_cco_syn=7.50e-3, tau_cco=0.314, tau_tde_trg=1.25e-3, tau_tde_fac=9.59e-3,
    tau_tde=4.52e-3, g_cco=9.84, g_tde_trg=0.271, g_tde_fac=6.15e2,
)  # fmt: skip
DURATION = 2.0
RATE = 300.0


def workload(n_samples: int) -> tuple[Network, list[np.ndarray]]:
    """The reference network and ``n_samples`` Poisson trains (seeds 0, 1, ...)."""
    net = Network.vary_offset(PARAMS, network_frequencies(56.2, 668.0, 50))
    trains = []
    for seed in range(n_samples):
        rng = np.random.default_rng(seed)
        trains.append(np.sort(rng.uniform(0.0, DURATION, rng.poisson(RATE * DURATION))))
    return net, trains


def workload_arguments(parser: argparse.ArgumentParser, samples: int) -> None:
    """``--samples`` (default ``samples``), ``--duration`` and ``--json``: the options of a
    benchmark that runs :func:`golden_workload` and writes its numbers with :func:`write_json`."""
    parser.add_argument(
        "--samples", type=int, default=samples, help=f"Poisson samples (default {samples})"
    )
    parser.add_argument("--duration", type=float, default=DURATION, help="run length [s]")
    parser.add_argument("--json", type=Path, help="write the numbers here")


def golden_workload(n_samples: int, duration: float):
    """:func:`workload`'s network and ``n_samples`` trains cut at ``duration`` [s], and the
    golden model's results on them: ``(net, trains, golden)``."""
    net, trains = workload(n_samples)
    trains = [x[x <= duration] for x in trains]
    return net, trains, simulate_batch(net, trains, duration)


def mean_spikes(results) -> tuple[float, float]:
    """TDE and CCO spikes per sample of ``results`` (summed over the sPLLs), averaged."""
    tde = float(np.mean([r.tde_counts.sum() for r in results]))
    return tde, float(np.mean([r.cco_counts.sum() for r in results]))


def write_json(path: Path | None, payload: dict) -> None:
    """``payload`` as indented JSON into ``path`` (a benchmark's ``--json``; none: nothing)."""
    if path:
        path.write_text(json.dumps(payload, indent=2))


def best_of(repeats: int, fn) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=40, help="samples per batch (default 40)")
    parser.add_argument("--repeats", type=int, default=5, help="best of N timings (default 5)")
    parser.add_argument("--brian2", action="store_true", help="also time Brian2 (needs [brian2])")
    parser.add_argument(
        "--brian2-samples", type=int, default=3, help="plain Brian2 samples (default 3)"
    )
    args = parser.parse_args()

    net, trains = workload(args.samples)
    first = simulate(net, trains[0], DURATION)
    events = int(
        trains[0].size * net.n_spll + first.tde_counts.sum() + first.cco_counts.sum()
    )  # input deliveries per sPLL + TDE spikes + CCO spikes
    cores = os.cpu_count() or 1
    print(f"machine: {platform.processor() or platform.machine()}, {cores} cores, "
          f"Python {platform.python_version()}")  # fmt: skip
    print(f"workload: 50 sPLLs, {trains[0].size} input spikes, {DURATION} s; "
          f"sample 0: {events} events, TDE spikes {first.tde_counts.sum()}")  # fmt: skip

    one = best_of(args.repeats, lambda: simulate_batch(net, trains, DURATION, threads=1))
    ms_one = one / len(trains) * 1e3
    print(f"golden, 1 core : {ms_one:7.3f} ms/sample  ({events / (ms_one / 1e3):.3g} events/s)")
    # The discrete-time fixed-point reference of the loihi2 profile (dt = 10 us), same trains.
    # Timed through the backend, so each batch also pays for quantizing the network once.
    fixed = backends.get("golden-fixed-point:profile=loihi2")
    fx = best_of(args.repeats, lambda: fixed.simulate_batch(net, trains, DURATION, threads=1))
    ms_fx = fx / len(trains) * 1e3
    print(f"fixed point loihi2 dt=10us, 1 core: {ms_fx:7.3f} ms/sample  "
          f"({ms_fx / ms_one:.2f}x golden)")  # fmt: skip
    demo = NetworkConfig.preset("vibtac-time-scaled-lif").build()
    ms_demo = best_of(args.repeats, lambda: simulate_batch(demo, trains, DURATION, threads=1))
    print(f"golden, 1 core, demo network: {ms_demo / len(trains) * 1e3:7.3f} ms/sample")
    all_cores = best_of(args.repeats, lambda: simulate_batch(net, trains, DURATION, threads=cores))
    ms_all = all_cores / len(trains) * 1e3
    print(f"golden, {cores} cores: {ms_all:7.3f} ms/sample  (speed-up {one / all_cores:.2f}x)")

    if args.brian2:
        from plain_brian2 import run_plain

        from mappings.brian2 import simulate_brian2

        golden = first.tde_counts.sum()
        plain = [run_plain(net, train, DURATION) for train in trains[: args.brian2_samples]]
        ms_plain = float(np.median([out["run_time"] for out in plain])) * 1e3
        err = abs(plain[0]["tde_counts"].sum() - golden) / golden
        print(f"plain brian2 cpp_standalone dt=10us: {ms_plain:7.1f} ms/sample (run only, median "
              f"of {len(plain)}; golden is {ms_plain / ms_one:.1f}x faster), "
              f"TDE spike count off by {100 * err:.2f} %")  # fmt: skip
        result = simulate_brian2(net, trains[0], DURATION, dt=10e-6, target="cpp_standalone")
        err = abs(result.tde_counts.sum() - golden) / golden
        print(f"spll-hw's brian2 mapping, cpp_standalone dt=10us: {result.wall_time * 1e3:7.1f} "
              f"ms/sample (run only), TDE spike count off by {100 * err:.2f} %")  # fmt: skip


if __name__ == "__main__":
    main()
