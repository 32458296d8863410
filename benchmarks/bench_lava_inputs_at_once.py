"""lava-nc running an export check's inputs one at a time against at once (``run.py --check``).

The folder's own ``run.py`` (spll-hw unimportable) counts its check inputs, cut to
``--duration`` seconds, with ``BATCH_NEURONS`` = 1 (each part runs an input at a time, as
before 2026-12-07) and then with each ``--limit`` (a part runs as one Lava network with a copy
per input, up to that many neurons), prints the wall time of each and whether every sPLL's
counts are the same. ``--parts P`` keeps each clock's first ``P`` parts (a tuned network has 50).
Write a folder with its check first, e.g.::

    spll-hw export --to lava-standard --network biotac-tuned-vary-offset-lif --dt 5e-5 \\
        --out /tmp/tuned
    python benchmarks/bench_lava_inputs_at_once.py --folder /tmp/tuned --duration 0.05 --parts 2
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, required=True, help="a lava-standard export")
    parser.add_argument("--duration", type=float, default=0.05, help="input length [s]")
    parser.add_argument("--limit", type=int, nargs="+", default=[4096],
                        help="BATCH_NEURONS to time beside 1")  # fmt: skip
    parser.add_argument("--parts", type=int, help="each clock's first PARTS parts only")
    args = parser.parse_args()
    for name in ("spll_hw", "mappings", "quantize"):
        sys.modules[name] = None  # the folder runs without the project
    sys.path.insert(0, str(args.folder))
    import check_counts
    import run as folder_run

    record = check_counts.read_check(args.folder)
    inputs = [(spikes[spikes <= args.duration], args.duration)
              for _, spikes, _ in check_counts.read_inputs(args.folder, record)]  # fmt: skip
    clocks = folder_run.load_clocks(args.folder / "params.npz")
    if args.parts:
        whole = folder_run.split
        folder_run.split = lambda params: whole(params)[: args.parts]
    counts = {}
    for limit in [1, *args.limit]:
        folder_run.BATCH_NEURONS = limit
        start = time.perf_counter()
        counts[limit] = folder_run.count_all(clocks, inputs)
        print(f"BATCH_NEURONS = {limit}: {time.perf_counter() - start:.1f} s for "
              f"{len(inputs)} inputs of {args.duration:g} s", flush=True)  # fmt: skip
    same = all(out == counts[1] for out in counts.values())
    print("every sPLL's counts the same:", same)


if __name__ == "__main__":
    main()
