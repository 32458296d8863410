"""The standard sPLL on Lava's own processes: error against golden and Lava against its
bit-accurate reference.

Workload: the reference workload of ``bench_engine.py`` (50-sPLL vary-offset network, 2 s of
300 Hz Poisson input). For each ``dt`` the project's bit-accurate reference of Lava's LIF/Dense
arithmetic (``standard-fixed-point``) runs every sample; the exported folder's ``run.py``
(``spll-hw export --to lava-standard``) runs the first sample on lava-nc in a subprocess
without spll-hw on its path, and its counts are compared with the reference's.

    python benchmarks/bench_lava_standard.py --json benchmarks/results/lava_standard.json
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench_engine import golden_workload, mean_spikes, workload_arguments, write_json  # noqa: E402

from mappings.lava.exporter import export_standard  # noqa: E402
from mappings.lava.standard_backend import StandardFixedPoint  # noqa: E402
from spll_hw.harness.metrics import rate_error  # noqa: E402


def run_lava(net, x: np.ndarray, duration: float, dt: float) -> tuple[dict, float]:
    """Counts of ``run.py`` on lava-nc and its wall time [s]."""
    with tempfile.TemporaryDirectory() as tmp:
        export_standard(net, tmp, dt=dt)
        np.save(Path(tmp) / "spikes.npy", x)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        start = time.perf_counter()
        done = subprocess.run([sys.executable, "run.py", "spikes.npy", repr(duration)], cwd=tmp,
                              env=env, capture_output=True, text=True, check=True)  # fmt: skip
        return json.loads(done.stdout.strip().splitlines()[-1]), time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    workload_arguments(parser, samples=2)
    parser.add_argument("--dts", default="1e-5,5e-5", help="time steps [s], comma-separated")
    parser.add_argument("--no-lava", action="store_true", help="skip the lava-nc runs")
    args = parser.parse_args()

    net, trains, golden = golden_workload(args.samples, args.duration)
    rows = []
    for dt in (float(v) for v in args.dts.split(",")):
        start = time.perf_counter()
        ref = StandardFixedPoint(dt=dt).simulate_batch(net, trains, args.duration)
        wall = time.perf_counter() - start
        errors = [rate_error(r, g) for r, g in zip(ref, golden, strict=True)]
        tde, cco = mean_spikes(ref)
        row = {
            "dt": dt,
            "rate_error_mean": float(np.mean(errors)),
            "rate_error_std": float(np.std(errors)),
            "tde_spikes": tde,
            "cco_spikes": cco,
            "reference_s_per_batch": wall,
        }
        if not args.no_lava and importlib.util.find_spec("lava") is not None:
            lava, lava_wall = run_lava(net, trains[0], args.duration, dt)
            row["lava_s_sample0"] = lava_wall
            row["lava_equals_reference"] = bool(
                lava["tde_counts"] == ref[0].tde_counts.tolist()
                and lava["cco_counts"] == ref[0].cco_counts.tolist()
            )
        rows.append(row)
    g_tde, g_cco = mean_spikes(golden)
    print(f"workload: 50 sPLLs, {args.duration:g} s of 300 Hz Poisson, {args.samples} samples; "
          f"golden spikes/sample: TDE {g_tde:.0f}, CCO {g_cco:.0f}\n")  # fmt: skip
    print("| dt | TDE-rate error vs golden | TDE spikes | CCO spikes | reference s / batch | "
          "lava-nc s (sample 0) | lava-nc = reference |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        lava = (f"{r['lava_s_sample0']:.0f} | {'yes' if r['lava_equals_reference'] else 'NO'}"
                if "lava_s_sample0" in r else "not run | ")  # fmt: skip
        print(f"| {r['dt'] * 1e6:g} µs | {100 * r['rate_error_mean']:.2f} ± "
              f"{100 * r['rate_error_std']:.2f} % | {r['tde_spikes']:.0f} | {r['cco_spikes']:.0f} "
              f"| {r['reference_s_per_batch']:.0f} | {lava} |")  # fmt: skip
    write_json(args.json, {"samples": args.samples, "duration": args.duration,
                           "golden_tde_spikes": g_tde, "golden_cco_spikes": g_cco,
                           "rows": rows})  # fmt: skip


if __name__ == "__main__":
    main()
