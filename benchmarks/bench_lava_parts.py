"""lava-nc running an exported network whole against in its independent parts (``run.py``).

A layout with several sets of decays (``vibtac-time-scaled-lif`` as ``grouped:6``: 6 sets,
235 Lava processes whole) exported by ``lava-standard`` at 50 µs; the folder's own ``run.py``
runs 1000 steps of 300 Hz Poisson either whole (``run_part`` on the whole network, what
``run.py`` did before 2026-11-28) or in parts (``run``: one per set, 40-41 processes each),
in this process without spll-hw importable, and prints the wall time and the TDE and CCO
totals (equal in both modes). Time the two pair by pair:

    python benchmarks/bench_lava_parts.py --folder /tmp/parts --export
    farm-bench -n 3 --warmup 0 --timeout 1500 \\
        --vs 'python benchmarks/bench_lava_parts.py --folder /tmp/parts --mode whole' \\
        -- python benchmarks/bench_lava_parts.py --folder /tmp/parts --mode split
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

DT = 5e-5
STEPS = 1000


def export(folder: Path) -> None:
    """Write the benchmark's folder (needs spll-hw, not lava-nc)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from mappings.lava.export import write_standard
    from mappings.lava.standard import lava_standard
    from spll_hw.config import NetworkConfig

    net = NetworkConfig.preset("vibtac-time-scaled-lif").with_layout("grouped:6").build()
    params = lava_standard(net, dt=DT)
    write_standard(params, folder)
    print(f"{folder}: {params.n_processes} Lava processes")


def run(folder: Path, mode: str) -> None:
    """Run the folder's ``run.py`` over the benchmark's input, whole or in parts."""
    import numpy as np

    for name in ("spll_hw", "mappings", "quantize"):
        sys.modules[name] = None  # the folder runs without the project
    sys.path.insert(0, str(folder))
    import run as folder_run

    params = folder_run.load_params(folder / "params.npz")
    rng = np.random.default_rng(0)
    spikes = np.sort(rng.uniform(0.0, STEPS * DT, rng.poisson(300.0 * STEPS * DT)))
    counts = folder_run.input_counts(spikes, STEPS * DT, DT)
    start = time.perf_counter()
    if mode == "whole":
        rasters = folder_run.run_part(params, counts[None])[0]
    else:
        rasters = np.stack(folder_run.run(params, counts))
    tde, cco = (int(r.sum()) for r in rasters)
    print(f"{mode}: {time.perf_counter() - start:.1f} s, TDE {tde}, CCO {cco} spikes")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, required=True, help="the exported folder")
    parser.add_argument("--export", action="store_true", help="write the folder first")
    parser.add_argument("--mode", choices=("split", "whole"), help="run it in parts or whole")
    args = parser.parse_args()
    if args.export:
        export(args.folder)
    if args.mode:
        run(args.folder, args.mode)


if __name__ == "__main__":
    main()
