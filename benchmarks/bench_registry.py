"""What going through the backend registry costs on top of the engine.

Workload: the reference workload of ``bench_engine.py`` (50-sPLL vary-offset network, 2 s of
300 Hz Poisson input). For each backend spec it times, in ms per sample on one thread:

* ``engine``: the engine call alone, on what the backend prepared (realised integers for
  ``golden-fixed-point``, the network for ``golden``);
* ``run, 1 sample``: ``backends.run(spec, ...)`` once per sample, as ``compare`` and
  ``stability`` used to call it;
* ``batch of 8``: ``backends.get(spec).simulate_batch`` of 8 samples;
* ``fresh, 1 sample``: a newly configured backend per sample (what every ``backends.run`` cost
  before the registry kept configurations: parsing, loading the profile, preparing);
* ``first call``: the first ``backends.run`` of a fresh process's spec, which parses the spec,
  loads the profile and prepares the network (once per network per workload since the
  registry keeps configured backends and what they prepared).

    python benchmarks/bench_registry.py            # about 20 s
    python benchmarks/bench_registry.py --repeats 5

Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench_engine import DURATION, workload  # noqa: E402

from mappings.fixed_point.backend import MAX_STEPS  # noqa: E402
from spll_hw import _engine, backends  # noqa: E402
from spll_hw.simulate import DEFAULT_MAX_EVENTS  # noqa: E402

SPECS = ("golden", "golden-fixed-point:profile=loihi2")


def _ms(seconds: float, samples: int) -> float:
    return 1e3 * seconds / samples


def engine_call(spec: str, net, trains):
    """The engine call alone on what ``spec`` prepared for ``net`` (a closure)."""
    sim = backends.get(spec)
    prepared = sim.prepared(net)
    if spec == "golden":
        matrix = np.ascontiguousarray(prepared.matrix())
        return lambda: _engine.simulate_batch(
            matrix, trains, DURATION, False, 1, DEFAULT_MAX_EVENTS, None
        )
    fixed = prepared.fixed
    matrix = np.ascontiguousarray(fixed.matrix, dtype=np.int64)
    return lambda: _engine.simulate_fixed_point(
        matrix, trains, fixed.dt, DURATION, fixed.state_bits, fixed.decay_bits, False, 1, MAX_STEPS
    )


def median_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per figure (median)")
    args = parser.parse_args(argv)
    net, trains = workload(8)
    print("| backend | first call | engine | run, 1 sample | batch of 8 | fresh, 1 sample |")
    print("|---|---|---|---|---|---|")
    for spec in SPECS:
        start = time.perf_counter()
        backends.run(spec, net, trains[0], DURATION, threads=1, record_spikes=False)
        first = time.perf_counter() - start
        engine = median_time(engine_call(spec, net, trains), args.repeats)
        single = median_time(
            lambda s=spec: [
                backends.run(s, net, x, DURATION, threads=1, record_spikes=False) for x in trains
            ],
            args.repeats,
        )  # fmt: skip
        batch = median_time(
            lambda s=spec: backends.get(s).simulate_batch(net, trains, DURATION, threads=1),
            args.repeats,
        )
        name, options = backends.parse_spec(spec)
        fresh = median_time(
            lambda name=name, options=options: [
                backends.backend_class(name)(**options).simulate(
                    net, x, DURATION, threads=1, record_spikes=False
                )
                for x in trains
            ],
            args.repeats,
        )  # fmt: skip
        print(
            f"| `{spec}` | {1e3 * first:.1f} ms | {_ms(engine, 8):.2f} | {_ms(single, 8):.2f} "
            f"({single / engine:.2f}x) | {_ms(batch, 8):.2f} ({batch / engine:.2f}x) | "
            f"{_ms(fresh, 8):.2f} ({fresh / engine:.2f}x) |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
