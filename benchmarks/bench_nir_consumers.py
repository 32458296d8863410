"""The standard sPLL's NIR file in real consumers: snnTorch and Norse against the golden model.

Workload: the reference workload of ``bench_engine.py`` (50-sPLL vary-offset network, 2 s of
300 Hz Poisson input). The network is exported with ``spll-hw export --to nir-standard``'s
function (K = 8 uniform levels, dt = 100 µs, self-inhibition for refractory periods), read back
from the file by each consumer's own NIR import and stepped over the samples in one batch
(:mod:`mappings.nir.consumers`); the numpy executor runs the same file by the same rules.

    python benchmarks/bench_nir_consumers.py                      # 2 samples
    python benchmarks/bench_nir_consumers.py --json benchmarks/results/nir_consumers.json

Needs ``nir``; snnTorch and Norse need torch (``pip install torch snntorch nirtorch`` and
``pip install --no-deps norse``); a consumer that is not installed is reported as such. torch
from PyPI brings its CUDA libraries (about 4 GB, 3 minutes here), which is why the test suite
runs the numpy executor and this script records the torch consumers.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench_engine import golden_workload, mean_spikes, workload_arguments, write_json  # noqa: E402

from mappings.nir import export_standard  # noqa: E402
from mappings.nir.consumers import CONSUMERS, run_consumer  # noqa: E402
from spll_hw.harness.metrics import rate_error  # noqa: E402


def _version(module: str) -> str:
    try:
        from importlib.metadata import version

        return version(module)
    except Exception:  # noqa: BLE001 - a missing version is reported, not fatal
        return "?"


def _label(row: dict) -> str:
    if row["consumer"] == "numpy":
        return f"numpy executor (nir {row['version']})"
    return f"{row['consumer']} {row['version']}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    workload_arguments(parser, samples=2)
    args = parser.parse_args()

    net, trains, golden = golden_workload(args.samples, args.duration)
    g_tde, g_cco = mean_spikes(golden)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        path = export_standard(net, tmp)[0]
        counts = {}
        for consumer, modules in CONSUMERS.items():
            missing = [m for m in modules if importlib.util.find_spec(m) is None]
            if missing:
                rows.append({"consumer": consumer, "missing": missing})
                continue
            start = time.perf_counter()
            res = run_consumer(consumer, path, trains, args.duration)
            wall = time.perf_counter() - start
            counts[consumer] = res
            errors = [rate_error(r, g) for r, g in zip(res, golden, strict=True)]
            tde, cco = mean_spikes(res)
            rows.append(
                {
                    "consumer": consumer,
                    "version": _version(modules[0]),
                    "rate_error_mean": float(np.mean(errors)),
                    "rate_error_std": float(np.std(errors)),
                    "tde_spikes": tde,
                    "cco_spikes": cco,
                    "wall_s_per_sample": wall / len(trains),
                    # Spikes per sample that differ from the numpy executor's (float32 vs 64).
                    "spikes_differing_from_numpy": (
                        float(
                            np.mean(
                                [
                                    np.abs(a.tde_counts - b.tde_counts).sum()
                                    + np.abs(a.cco_counts - b.cco_counts).sum()
                                    for a, b in zip(res, counts["numpy"], strict=True)
                                ]
                            )
                        )
                        if "numpy" in counts
                        else None
                    ),
                }
            )
    print(
        f"workload: 50 sPLLs, {args.duration:g} s of 300 Hz Poisson, {args.samples} samples; "
        f"golden spikes/sample: TDE {g_tde:.0f}, CCO {g_cco:.0f}\n"
    )
    print("| consumer | TDE-rate error vs golden | TDE spikes | CCO spikes | s / sample | "
          "spikes ≠ numpy executor |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for r in rows:
        if "missing" in r:
            print(f"| {r['consumer']} | not installed ({', '.join(r['missing'])}) | | | | |")
            continue
        print(
            f"| {_label(r)} | {100 * r['rate_error_mean']:.2f} ± "
            f"{100 * r['rate_error_std']:.2f} % | {r['tde_spikes']:.0f} | {r['cco_spikes']:.0f} "
            f"| {r['wall_s_per_sample']:.1f} | {r['spikes_differing_from_numpy']:.0f} |"
        )
    write_json(args.json, {"samples": args.samples, "duration": args.duration,
                           "golden_tde_spikes": g_tde, "golden_cco_spikes": g_cco,
                           "rows": rows})  # fmt: skip


if __name__ == "__main__":
    main()
