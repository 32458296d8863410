"""Rate errors of backends against the golden model on the reference workload of issue 2.

Workload (``bench_engine.workload``): 50-sPLL vary-offset network, 2 s of 300 Hz Poisson input.
Each backend is compared with the golden model of the network as it realises it
(``Backend.realised``), as ``capabilities.rate_tolerance`` is defined; the conformance
reference set (``python -m spll_hw.backends.conformance --errors-only SPEC``) is what the
tolerances are declared on, this is the context.

    python benchmarks/rate_errors.py golden-fixed-point golden-fixed-point:profile=fixed16
    python benchmarks/rate_errors.py --samples 1 brian2-cython:dt=1e-5
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from bench_engine import DURATION, workload

from spll_hw import backends
from spll_hw.harness.metrics import rate_error


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("specs", nargs="+", help="backend specs (their own options, as given)")
    parser.add_argument("--samples", type=int, default=4, help="Poisson samples (default 4)")
    args = parser.parse_args()
    net, trains = workload(args.samples)
    golden = backends.get("golden")
    for spec in args.specs:
        backend = backends.get(spec)
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results = backend.simulate_batch(net, trains, DURATION)
        wall = time.perf_counter() - start
        reference = golden.simulate_batch(backend.realised(net), trains, DURATION)
        errors = [rate_error(r, g) for r, g in zip(results, reference, strict=True)]
        print(
            f"{backend.spec}: rate error mean {np.mean(errors):.4f}, max {np.max(errors):.4f} "
            f"over {len(errors)} samples (declared {backend.capabilities.rate_tolerance:.4f}; "
            f"{wall:.1f} s)"
        )


if __name__ == "__main__":
    main()
