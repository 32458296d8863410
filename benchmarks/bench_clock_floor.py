"""The floor of every clocked construction: exact integration between steps, checked as an
export is.

A clocked target (Loihi's integers, a NIR consumer's steps) puts every spike on a step's end
and holds refractory periods in whole steps. :func:`mappings.standard.dt_ladder.floor_check`
measures what that alone costs: the export check (:func:`spll_hw.exporters.check.check_run`,
its reference inputs and metric) of exact integration between steps of ``dt`` with the golden
product as gate (:func:`mappings.standard.reference.simulate_reference`), refractory holds of
rule ``--holds`` (``compensated``: ``round(t_refr/dt - 1/2)`` steps, the exports'; ``dithered``:
that fraction dithered over the spikes, exact on average). No construction on that clock, of
whatever precision, is expected to come closer to golden than this. Beside it, golden's own
variation on the same inputs 0.5 ms later (the check's resolution)::

    python benchmarks/bench_clock_floor.py --presets vibtac-time-scaled-peak \\
        --steps 1e-6,5e-7 --durations 1,10 --json benchmarks/results/clock_floor.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.bench_golden_sensitivity import durations, preset_names  # noqa: E402

#: Refractory holds measured by default (:data:`mappings.standard.reference.HOLDS`).
DEFAULT_HOLDS = ("compensated",)


def measure(preset: str, dt: float, duration: float, hold: str) -> dict:
    """One row: exact integration between steps of ``dt`` [s] (refractory hold ``hold``) of
    ``preset`` on its reference inputs of ``duration`` [s], against golden."""
    from mappings.standard.dt_ladder import floor_check
    from spll_hw.config import NetworkConfig
    from spll_hw.exporters.check import golden_resolution

    start = time.perf_counter()
    net = NetworkConfig.preset(preset).build()
    floor = floor_check(net, dt, hold=hold, duration=duration)
    row = {"preset": preset, "dt": dt, "duration": duration, "hold": hold,
           "tde_error": floor.error, "worst_spll": int(floor.spll_error.argmax()),
           "worst_spll_error": float(floor.spll_error.max()),
           "golden_shifted": golden_resolution(net, duration)}  # fmt: skip
    row["seconds"] = time.perf_counter() - start
    print(f"{preset} at {dt * 1e6:g} µs ({hold}) on {duration:g} s: {100 * floor.error:.2f} % "
          f"(golden 0.5 ms later {100 * row['golden_shifted']:.2f} %), {row['seconds']:.0f} s",
          file=sys.stderr, flush=True)  # fmt: skip
    return row


def markdown(rows: list[dict]) -> str:
    """The rows as a table: one row per preset, step and hold; one column per duration."""
    spans = sorted({r["duration"] for r in rows})
    head = [f"{d:g} s (golden 0.5 ms later)" for d in spans]
    lines = ["| preset | step | hold | " + " | ".join(head) + " |", "|---" * (len(head) + 3) + "|"]
    for key in dict.fromkeys((r["preset"], r["dt"], r["hold"]) for r in rows):
        cells = []
        for d in spans:
            row = next((r for r in rows if (r["preset"], r["dt"], r["hold"]) == key
                        and r["duration"] == d), None)  # fmt: skip
            cells.append("" if row is None else f"{100 * row['tde_error']:.2f} % "
                         f"({100 * row['golden_shifted']:.2f} %)")  # fmt: skip
        lines.append(f"| `{key[0]}` | {key[1] * 1e6:g} µs | {key[2]} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def steps(text: str) -> list[float]:
    """``--steps``: comma-separated time steps [s], each > 0."""
    try:
        out = [float(x) for x in text.split(",")]
    except ValueError:
        out = []
    if not out or not all(dt > 0 for dt in out):
        raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of steps > 0 s")
    return out


def holds(text: str) -> list[str]:
    """``--holds``: comma-separated refractory holds of the reference."""
    from mappings.standard.reference import HOLDS

    out = text.split(",")
    unknown = sorted(set(out) - set(HOLDS))
    if unknown:
        raise argparse.ArgumentTypeError(
            f"no hold {', '.join(unknown)}; choose from {', '.join(HOLDS)}"
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--presets", type=preset_names, required=True, help="comma-separated")
    parser.add_argument("--steps", type=steps, required=True, help="comma-separated steps [s]")
    parser.add_argument(
        "--durations",
        type=durations,
        default=[1.0],
        help="comma-separated input lengths [s] (default 1, the check's)",
    )
    parser.add_argument(
        "--holds",
        type=holds,
        default=list(DEFAULT_HOLDS),
        help="comma-separated refractory holds (default compensated)",
    )
    parser.add_argument("--json", type=Path, help="write the rows here")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    args = parser.parse_args(argv)
    rows = [measure(p, dt, d, h) for p in args.presets for dt in args.steps
            for h in args.holds for d in args.durations]  # fmt: skip
    table = markdown(rows)
    print(table)
    for path, text in ((args.json, json.dumps(rows, indent=1) + "\n"), (args.markdown, table)):
        if path:
            path.write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
