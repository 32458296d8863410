"""Where an exported lava-standard folder's ``run.py`` spends its time, and the README's estimate.

Writes a folder (``--export``: ``lava_standard`` at ``--dt``, no check, so a tuned network is
written in seconds; ``--n``: the preset with that many sPLLs) with a 300 Hz Poisson input of
``--duration`` seconds (``spikes.npy``, seed 0), and prints what the README's model
(:func:`mappings.lava.standalone_run.seconds`) estimates for the folder's ``run.py`` on
``--duration`` seconds of it (without ``--export``: of the folder's input, which may be
longer): its parts, their Lava processes and neurons, and the seconds for ``--jobs`` 1 and 2.
``--peer`` writes ``run.py`` as it was before 2026-12-06 (``git show REV:...``) beside it as
``run_peer.py``, to time both in the same call. Time the folder's own ``run.py`` from outside
(its start-up, split and every part's compile included), e.g. on biotac-tuned-vary-offset-lif::

    python benchmarks/bench_lava_runtime.py --folder /tmp/tuned \\
        --network biotac-tuned-vary-offset-lif --duration 0.01 --export --peer f6b5351
    /usr/bin/time -v python /tmp/tuned/run.py /tmp/tuned/spikes.npy 0.01 --jobs 1
    /usr/bin/time -v python /tmp/tuned/run_peer.py /tmp/tuned/spikes.npy 0.01

``--part K --steps S`` instead runs part ``K`` of the folder alone over ``S`` steps of the
input in this process (spll-hw unimportable) and prints its load-and-split and
compile-and-run seconds: the difference of two ``S`` (1 and 2000) is the model's per-step
cost of that part (its Lava processes and neurons printed with it).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: Input rate [Hz] of the benchmark's Poisson train.
RATE = 300.0


def export(
    folder: Path, network: str, dt: float, duration: float, peer: str | None, n: int | None = None
) -> None:
    """Write the benchmark's folder and its input (needs spll-hw, not lava-nc): ``network``
    with ``n`` sPLLs (default: the preset's) at the step ``dt`` [s], ``duration`` [s] of input."""
    sys.path.insert(0, str(ROOT))
    import numpy as np

    from mappings.lava.export import write_standard
    from mappings.lava.standard import lava_standard
    from spll_hw.config import NetworkConfig

    config = NetworkConfig.preset(network)
    params = lava_standard((config if n is None else config.with_n(n)).build(), dt=dt)
    write_standard(params, folder)
    rng = np.random.default_rng(0)
    np.save(folder / "spikes.npy", np.sort(rng.uniform(0, duration, rng.poisson(RATE * duration))))
    if peer is not None:
        old = subprocess.run(["git", "show", f"{peer}:mappings/lava/standalone_run.py"],
                             cwd=ROOT, capture_output=True, text=True, check=True)  # fmt: skip
        (folder / "run_peer.py").write_text(old.stdout)


def estimate(folder: Path, duration: float) -> None:
    """Print the README's model of ``run.py`` on the folder's input of ``duration`` [s]."""
    sys.path.insert(0, str(ROOT))
    from mappings.lava import standalone_run
    from mappings.lava.standard import lava_gb

    parts, neurons, costs = [], [], []
    for params in standalone_run.load_clocks(folder / "params.npz"):
        steps = round(duration / params["dt"])
        for piece in standalone_run.split(params):
            parts.append(standalone_run.n_processes(piece))
            neurons.append(standalone_run.n_neurons(piece))
            costs.append(standalone_run.part_seconds(parts[-1], neurons[-1], steps))
    print(f"{len(parts)} parts, {sum(parts)} Lava processes (at most {max(parts)} in a part), "
          f"{sum(neurons)} neurons (at most {max(neurons)} in a part); estimate: "
          + ", ".join(f"--jobs {j}: {standalone_run.seconds(costs, j):.1f} s, "
                      f"{lava_gb(parts, j):.2f} GB" for j in (1, 2)))  # fmt: skip


def run_part(folder: Path, k: int, steps: int) -> None:
    """Run part ``k`` of the folder over the first ``steps`` steps of its input, alone."""
    import numpy as np

    for name in ("spll_hw", "mappings", "quantize"):
        sys.modules[name] = None  # the folder runs without the project
    sys.path.insert(0, str(folder))
    import run as folder_run

    start = time.perf_counter()
    params = folder_run.load_clocks(folder / "params.npz")[0]
    part = folder_run.split(params)[k]
    spikes = np.load(folder / "spikes.npy")
    counts = folder_run.input_counts(spikes, steps * params["dt"], params["dt"])
    ready = time.perf_counter()
    rasters = folder_run.run_part(part, counts[None])[0]
    done = time.perf_counter()
    print(f"part {k}: {folder_run.n_processes(part)} Lava processes, "
          f"{folder_run.n_neurons(part)} neurons, "
          f"{steps} steps: load and "
          f"split {ready - start:.2f} s, run {done - ready:.2f} s, TDE {int(rasters[0].sum())}, "
          f"CCO {int(rasters[1].sum())} spikes")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", type=Path, required=True, help="the exported folder")
    parser.add_argument("--network", default="biotac-tuned-vary-offset-lif", help="preset")
    parser.add_argument("--dt", type=float, default=5e-5, help="step [s] (default 50 µs)")
    parser.add_argument("--duration", type=float, default=0.01, help="input [s]")
    parser.add_argument("--n", type=int, help="the preset with this many sPLLs (with --export)")
    parser.add_argument("--export", action="store_true", help="write the folder first")
    parser.add_argument("--peer", metavar="REV", help="also write REV's run.py as run_peer.py")
    parser.add_argument("--part", type=int, help="run this part alone (with --steps)")
    parser.add_argument("--steps", type=int, default=1, help="steps of --part's run")
    args = parser.parse_args()
    if args.part is not None:
        run_part(args.folder, args.part, args.steps)
        return
    if args.export:
        export(args.folder, args.network, args.dt, args.duration, args.peer, args.n)
    estimate(args.folder, args.duration)


if __name__ == "__main__":
    main()
