"""The input clock's floor: golden on its input moved onto a clocked step grid vs golden.

For every shipped preset, golden fed its input on a clocked target's step grid, against golden
on the input itself.

A clocked export (``nir-standard``, ``lava-standard``) delivers each input spike at the end of
the step it arrives in (``spll_hw.model.grid``: step ``max(1, ceil(t / dt))``, spikes after the
run's last step dropped). Whatever the construction does between steps, it cannot tell spikes
of one step apart, so where the golden model itself moves by more than the export's tolerance
when its input spikes are moved onto that grid, no export at that step can pass. This measures
that move with the export check itself (``spll_hw.exporters.check.check_run``: the network's
six reference inputs, the total TDE-rate error, the mean of ``rate_error`` over the inputs on
which golden's TDEs fire; and its per-sPLL TDE-count error), golden on the grid input being
the "export". Golden runs only: about a second per preset and step.

    nice -n 10 python benchmarks/bench_input_clock.py \\
        --json benchmarks/results/input_clock.json \\
        --markdown benchmarks/results/input_clock.md      # ~30 s on one core
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mappings.lava import dt_choice as lava_dt  # noqa: E402
from mappings.nir import dt_choice as nir_dt  # noqa: E402
from spll_hw import presets  # noqa: E402
from spll_hw.backends import get  # noqa: E402
from spll_hw.config import NetworkConfig  # noqa: E402
from spll_hw.exporters import FolderRun  # noqa: E402
from spll_hw.exporters.check import CheckReport, check_run  # noqa: E402
from spll_hw.model.grid import n_steps, spike_steps  # noqa: E402
from spll_hw.network import Network  # noqa: E402

#: Time steps [s] measured by default: both targets' ladders and 1 µs.
STEPS = (1e-4, 5e-5, 2.5e-5, 2e-5, 1e-5, 1e-6)
#: (export target, its ladder of steps [s], its declared tolerance at a step).
TARGETS = (
    ("nir-standard", nir_dt.LADDER, nir_dt.PARTS.tolerance),
    ("lava-standard", lava_dt.LADDER, lava_dt.PARTS.tolerance),
)


def on_grid(trains, duration: float, dt: float) -> list[np.ndarray]:
    """Each train's spikes [s] moved to the end of the step of ``dt`` [s] they arrive in, the
    time a clocked target delivers them; spikes after the run's last step are dropped."""
    last = n_steps(duration, dt)
    out = []
    for train in trains:
        k = spike_steps(train, dt)
        out.append(k[k <= last] * dt)
    return out


def input_clock_check(network: Network, dt: float) -> CheckReport:
    """The export check of golden fed the reference inputs on the grid of ``dt`` [s]
    (:func:`on_grid`) against golden on the inputs themselves."""
    golden = get("golden")
    run = FolderRun(
        f"golden on its input moved onto the {dt:g} s grid", golden,
        lambda trains, T: golden.simulate_batch(network, on_grid(trains, T, dt), T),
    )  # fmt: skip
    return check_run(run, "golden on the input grid", network, max_error=1.0)


def measure(name: str, steps) -> list[dict]:
    """Rows ``{preset, dt, error, inputs, worst_spll, ...}`` of preset ``name``."""
    network = NetworkConfig.load(name).build()
    rows = []
    for dt in steps:
        start = time.perf_counter()
        report = input_clock_check(network, dt)
        worst = report.worst
        rows.append({
            "preset": name, "dt": dt, "error": float(report.tde_error),
            "inputs": {x["label"]: x["tde_rate_error"] for x in report.inputs},  # None: silent
            "worst_spll": worst, "worst_spll_error": float(report.spll_tde_error[worst]),
            "worst_spll_golden_tde_spikes": int(report.spll_golden_tde_spikes[worst]),
            "wall_s": time.perf_counter() - start,
        })  # fmt: skip
        print(f"{name:36s} dt={dt * 1e6:5g} µs  TDE-rate error {100 * report.tde_error:6.2f} %",
              flush=True)  # fmt: skip
    return rows


def above_everywhere(rows: list[dict], ladder, tolerance) -> bool | None:
    """Whether the floor of ``rows`` (one preset) exceeds ``tolerance(dt)`` at every step of
    ``ladder`` [s]; ``None`` where a step of it was not measured."""
    error = {r["dt"]: r["error"] for r in rows}
    if any(dt not in error for dt in ladder):
        return None
    return all(error[dt] > tolerance(dt) for dt in ladder)


def markdown(rows: list[dict], steps) -> str:
    """One row per preset: the floor at each step, and per target whether it exceeds the
    target's tolerance at every step of its ladder."""
    head = [f"{dt * 1e6:g} µs" for dt in steps] + [f"{t}: above at every step" for t, *_ in TARGETS]
    lines = ["| preset | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for name in dict.fromkeys(r["preset"] for r in rows):
        mine = [r for r in rows if r["preset"] == name]
        error = {r["dt"]: r["error"] for r in mine}
        cells = [f"{100 * error[dt]:.1f} %" if dt in error else "-" for dt in steps]
        for _, ladder, tolerance in TARGETS:
            verdict = above_everywhere(mine, ladder, tolerance)
            cells.append("-" if verdict is None else "yes" if verdict else "no")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", default="", help="comma-separated (default: all)")
    parser.add_argument("--dt", default=",".join(f"{dt:g}" for dt in STEPS),
                        help="comma-separated time steps [s] (default: %(default)s)")  # fmt: skip
    parser.add_argument("--json", type=Path, help="write the rows here")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    args = parser.parse_args()
    names = args.presets.split(",") if args.presets else presets.names()
    unknown = sorted(set(names) - set(presets.names()))
    if unknown:
        parser.error(f"--presets: no preset {', '.join(unknown)}; choose from "
                     f"{', '.join(presets.names())}")  # fmt: skip
    try:
        steps = tuple(float(x) for x in args.dt.split(","))
    except ValueError:
        parser.error(f"--dt: {args.dt!r} is not a comma-separated list of seconds")
    if not all(dt > 0 for dt in steps):
        parser.error("--dt: every time step must be > 0 s")
    rows = [row for name in names for row in measure(name, steps)]
    table = markdown(rows, steps)
    print(table)
    if args.markdown:
        args.markdown.write_text(table)
    if args.json:
        meta = {"what": "golden on grid input vs golden, export check's total TDE-rate error",
                "targets": {t: {"ladder_s": list(ladder),
                                "tolerance": [tolerance(dt) for dt in ladder]}
                            for t, ladder, tolerance in TARGETS}}  # fmt: skip
        args.json.write_text(json.dumps({**meta, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
