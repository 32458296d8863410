"""What the standard-neuron sPLL costs: TDE-rate error of the K-level gate against the golden model.

Workload: the reference workload of ``bench_engine.py`` (50-sPLL vary-offset network, 2 s of
300 Hz Poisson input, samples with seeds 0, 1, ...). Each gate (K = 2, 4, 8, 16 levels, uniform
and quantile placement, :mod:`spll_hw.construction.gate`) runs on the fine-clocked
reference (:mod:`spll_hw.construction.reference`, exact integration between steps of ``--dt``)
beside the golden product on the same clock, so the table separates the two errors:

* ``vs golden``: relative L1 error of the TDE-rate vector against the golden (event-driven)
  model, mean ± std over samples (``spll_hw.harness.metrics.rate_error``);
* ``vs product``: the same against the reference with the golden product on the same clock: the
  construction's own error, without the time grid's.

    python benchmarks/bench_standard.py                 # 4 samples, dt = 5 us (a few minutes)
    python benchmarks/bench_standard.py --samples 2 --dt 1e-5 --json out.json

Prints a Markdown table (the one in docs/backends.md) and, with ``--json``, writes the numbers.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench_engine import golden_workload, workload_arguments, write_json  # noqa: E402

from spll_hw.construction import PLACEMENTS, gate_levels  # noqa: E402
from spll_hw.construction.reference import DEFAULT_DT, simulate_reference  # noqa: E402
from spll_hw.harness.metrics import rate_error  # noqa: E402

LEVELS = (2, 4, 8, 16)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    workload_arguments(parser, samples=4)
    parser.add_argument("--dt", type=float, default=DEFAULT_DT, help="reference step [s]")
    args = parser.parse_args()

    net, trains, golden = golden_workload(args.samples, args.duration)
    variants = [(None, 0)] + [(p, k) for p in PLACEMENTS for k in LEVELS]
    gates = [None if p is None else gate_levels(net, k, p) for p, k in variants]
    start = time.perf_counter()
    results = simulate_reference(net, trains, args.duration, gates, dt=args.dt)
    wall = time.perf_counter() - start
    product = results[0]

    rows = []
    for (placement, k), res in zip(variants, results, strict=True):
        vs_golden = [rate_error(r, g) for r, g in zip(res, golden, strict=True)]
        vs_product = [rate_error(r, g) for r, g in zip(res, product, strict=True)]
        tde = np.mean([r.tde_counts.sum() for r in res])
        rows.append(
            {
                "placement": placement or "golden product",
                "levels": k,
                "vs_golden_mean": float(np.mean(vs_golden)),
                "vs_golden_std": float(np.std(vs_golden)),
                "vs_product_mean": float(np.mean(vs_product)),
                "vs_product_std": float(np.std(vs_product)),
                "tde_spikes": float(tde),
            }
        )
    golden_tde = float(np.mean([g.tde_counts.sum() for g in golden]))
    print(
        f"workload: 50 sPLLs, {args.duration:g} s of 300 Hz Poisson, {args.samples} samples; "
        f"reference dt = {args.dt:g} s ({wall:.0f} s wall); golden TDE spikes/sample "
        f"{golden_tde:.0f}\n"
    )
    print("| gate | K | TDE-rate error vs golden | vs golden product (same clock) | TDE spikes |")
    print("|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['placement']} | {r['levels'] or '-'} | "
            f"{100 * r['vs_golden_mean']:.2f} ± {100 * r['vs_golden_std']:.2f} % | "
            f"{100 * r['vs_product_mean']:.2f} ± {100 * r['vs_product_std']:.2f} % | "
            f"{r['tde_spikes']:.0f} |"
        )
    write_json(args.json, {"dt": args.dt, "samples": args.samples, "duration": args.duration,
                           "golden_tde_spikes": golden_tde, "wall_s": wall,
                           "rows": rows})  # fmt: skip


if __name__ == "__main__":
    main()
