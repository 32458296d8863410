"""``lava-standard`` with a clock per sPLL: how far Loihi's integers are from golden when each
sPLL runs at its own step, chosen so that its refractory period is exactly ``R + 1/2`` steps.

One Loihi clock cannot hold a time-scaled network: a step fine enough for the fast sPLLs'
refractory periods leaves the slow sPLLs' long time constants few of the 12 decay bits and
their feedback kicks few units of ``u`` (docs/notes/2026-11-27-lava-standard-step-per-preset.md). A
time-scaled sPLL is its base sPLL with every time constant scaled, so at a step scaled alike
every sPLL has the same integers. This measures that construction at any ``R``
(:func:`~mappings.lava.clocks.clocked_standard`; the export's last rung is ``R`` = 4): sPLL
``j`` at ``dt_j = min(t_tde_refr, t_cco_refr)_j / (R + 1/2)``, where the compensated hold of
``round(t_refr/dt - 1/2) = R`` steps is exact on average; each set of sPLLs of one step written
with its rows of the whole network's gate (band-quantile, as the export places it) and run by
``standard-fixed-point``'s executor on the export check's reference inputs
(:func:`spll_hw.exporters.check.reference_inputs`), its input binned at its own step
(:func:`~mappings.lava.clocks.run_clocked`). Beside the integers, on the same clocks: exact
integration between steps with golden's product (``floor``) and with the same gate (``gate``)
(:func:`~spll_hw.construction.reference.simulate_reference`, compensated hold). Each cell is the
export check's own total TDE-rate error (:func:`~spll_hw.exporters.check.check_run`: the mean
over the inputs of ``sum |c - c_golden| / sum c_golden``), the metric its limit judges::

    python benchmarks/bench_clock_per_spll.py --holds 4,8 \\
        --json benchmarks/results/clock_per_spll.json \\
        --markdown benchmarks/results/clock_per_spll.md

With ``--current graded`` each CCO's current is a ``GradedVec``'s
(:mod:`mappings.lava.graded_current`), the export's very last rung with ``--levels 64``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

#: The presets ``spll-hw export --to lava-standard`` refuses at every step of its ladder.
REFUSED = (
    "biotac-time-scaled-lif",
    "biotac-time-scaled-pacinian",
    "biotac-time-scaled-peak",
    "vibtac-time-scaled-peak",
)


def measure(preset: str, holds: float, levels: int, hold: str, current: str = "lif") -> dict:
    """One row: ``preset`` with each set of sPLLs at its own step
    (:func:`~mappings.lava.clocks.clocked_standard`), ``levels`` band-quantile gate levels,
    Loihi's refractory ``hold``, each CCO's current kept as ``current`` says
    (:data:`~mappings.lava.standard.CURRENTS`); each column scored by the export check itself
    (:func:`~spll_hw.exporters.check.check_run`)."""
    from mappings.lava.clocks import (
        CLOCKED_GATE,
        clocked_standard,
        run_clocked,
        spll_steps,
        sub_network,
    )
    from spll_hw.backends import get
    from spll_hw.config import NetworkConfig
    from spll_hw.construction.reference import simulate_reference
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run
    from spll_hw.result import SimulationResult

    start = time.perf_counter()
    net = NetworkConfig.preset(preset).build()
    steps = spll_steps(net, holds)
    row = {"preset": preset, "holds": holds, "levels": levels, "hold": hold,
           "current": current, "refused": [],
           "dt_us": [float(steps.min() * 1e6), float(steps.max() * 1e6)]}  # fmt: skip
    try:
        gate = replace(CLOCKED_GATE, levels=levels)
        clocked = clocked_standard(net, holds, gate, hold=hold, current=current)
    except ValueError as exc:
        row["refused"] = [str(exc)]
        print(f"{preset} R={holds:g}: refused: {exc}", file=sys.stderr, flush=True)
        return row

    def exact(gated: bool):
        """Exact integration between steps on the same clocks, with each part's gate or
        golden's product: ``simulate(trains, duration)``, TDE counts only."""

        def simulate(trains, duration):
            tde = np.zeros((len(trains), net.n_spll), np.int64)
            for part in clocked.parts:
                gate = part.params.gate if gated else None
                runs = simulate_reference(sub_network(net, part.spll), trains, duration, (gate,),
                                          dt=part.params.dt, hold="compensated")[0]  # fmt: skip
                tde[:, part.spll] = [r.tde_counts for r in runs]
            return [SimulationResult(tde_counts=t, cco_counts=np.zeros_like(t),
                                     duration=duration) for t in tde]  # fmt: skip

        return simulate

    backend = get("standard-fixed-point")  # its declared tolerance: the verdict's limit
    columns = {
        "integers": lambda trains, duration: run_clocked(clocked, trains, duration),
        "gate": exact(True),
        "floor": exact(False),
    }
    for what, simulate in columns.items():
        report = check_run(FolderRun(what, backend, simulate), "lava-standard", net)
        row[what] = report.tde_error
        row[f"{what}_per_input"] = [x["tde_rate_error"] for x in report.inputs
                                    if x["tde_rate_error"] is not None]  # fmt: skip
    row["seconds"] = time.perf_counter() - start
    print(f"{preset} R={holds:g}: integers {100 * row['integers']:.1f} %, gate "
          f"{100 * row['gate']:.1f} %, floor {100 * row['floor']:.1f} % "
          f"({row['seconds']:.0f} s)", file=sys.stderr, flush=True)  # fmt: skip
    return row


def markdown(rows: list[dict]) -> str:
    """The rows as the docs' table."""
    lines = [
        "| preset | R | steps [µs] | integers | same gate, exact integration | golden product, "
        "exact integration | per input (integers) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if r["refused"]:
            lines.append(f"| {r['preset']} | {r['holds']:g} | | refused: {r['refused'][0]} | | | |")
            continue
        per = " / ".join(f"{100 * x:.1f}" for x in r["integers_per_input"])
        lines.append(
            f"| {r['preset']} | {r['holds']:g} | {r['dt_us'][0]:.0f}–{r['dt_us'][1]:.0f} | "
            f"{100 * r['integers']:.1f} % | {100 * r['gate']:.1f} % | "
            f"{100 * r['floor']:.1f} % | {per} |"
        )
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--presets",
        default=",".join(REFUSED),
        help="comma-separated presets (default: the four lava-standard refuses)",
    )
    parser.add_argument(
        "--holds",
        default="4,8",
        help="comma-separated R: refractory steps of every sPLL (default 4,8)",
    )
    parser.add_argument("--levels", type=int, default=32, help="gate levels (default 32)")
    parser.add_argument(
        "--hold",
        default="compensated",
        choices=("compensated", "dithered"),
        help="Loihi's refractory hold (default compensated)",
    )
    parser.add_argument(
        "--current",
        default="lif",
        choices=("lif", "graded"),
        help="each CCO's current: its LIF's u, or a GradedVec's (default lif)",
    )
    parser.add_argument("--jobs", type=int, default=2, help="processes (default 2)")
    parser.add_argument("--json", type=Path, help="write the rows here")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    args = parser.parse_args(argv)
    cases = [(p, float(r), args.levels, args.hold, args.current)
             for p in args.presets.split(",") for r in args.holds.split(",")]  # fmt: skip
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        rows = list(pool.map(measure, *zip(*cases, strict=True)))
    table = markdown(rows)
    print(table)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    if args.markdown:
        args.markdown.write_text(table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
