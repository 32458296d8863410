"""``spll-hw compare``: error against run time of every backend versus the golden model."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..files import write_json, write_text
from .common import add_params_argument, default_backends, load_network_config

DEFAULT_DTS = "1e-4,1e-5,1e-6"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "compare",
        help="error against run time of backends (Brian2, Lava, fixed point, USB) vs golden",
        description="Simulate the same Poisson samples on each backend and report wall time per "
        "sample against TDE-rate, TDE-count and spike-time error versus the golden model "
        "(Markdown table, JSON and a work-precision plot).",
    )
    add_params_argument(p)
    p.add_argument(
        "--backends",
        help="comma-separated backend specs, e.g. golden,brian2-cpp_standalone,lava-fixed "
        "(options after ':', e.g. brian2-numpy:dt=1e-5; spll-hw backends lists them); default: "
        "golden, golden-fixed-point and brian2-cpp_standalone where Brian2 is installed",
    )
    p.add_argument(
        "--dt",
        default=DEFAULT_DTS,
        help=f"time steps [s] of the curve of every clocked backend without its own dt "
        f"(default {DEFAULT_DTS})",
    )
    p.add_argument("--samples", type=int, default=3, help="Poisson samples (default 3)")
    p.add_argument("--rate", type=float, default=300.0, help="input rate [Hz] (default 300)")
    p.add_argument("--duration", type=float, default=2.0, help="seconds per sample (default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first sample (default 0)")
    p.add_argument("--out", type=Path, default=Path("reports/compare"), help="report folder")
    p.set_defaults(func=run)


def expand_specs(specs: list[str], dts: list[float]) -> list[str]:
    """Give every spec of a clocked backend (one with a ``dt`` option) that sets no ``dt`` one
    spec per time step: its work-precision curve."""
    from ..backends import backend_class, parse_spec

    out = []
    for spec in specs:
        name, options = parse_spec(spec)
        if "dt" in backend_class(name).OPTIONS and "dt" not in options:
            out += [f"{spec}:dt={dt:g}" for dt in dts]
        else:
            out.append(spec)
    return out


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..backends import parse_specs
    from ..harness.workprecision import markdown_table, plot, work_precision

    dts = [float(x) for x in args.dt.split(",") if x.strip()]
    specs = expand_specs(parse_specs(args.backends or default_backends()), dts)
    if args.samples < 1:
        raise ValueError("--samples must be >= 1")
    config = load_network_config(args)
    network = config.build()
    trains = []
    for k in range(args.samples):
        rng = np.random.default_rng(args.seed + k)
        n = rng.poisson(args.rate * args.duration)
        trains.append(np.sort(rng.uniform(0.0, args.duration, n)))

    def progress(row):
        print(f"  {row.spec:40s} {1e3 * row.seconds_per_sample:9.2f} ms/sample  "
              f"rate error {100 * row.rate_error:.3f} %")  # fmt: skip

    rows = work_precision(specs, network, trains, args.duration, on_row=progress)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "params.toml", config.to_toml())
    plot(rows, out / "work_precision.png")
    write_json(out / "results.json", {"rows": [row.__dict__ for row in rows]})
    warnings = sorted({w for row in rows for w in row.warnings})
    notes = "".join(f"- {w}\n" for w in warnings)
    write_text(
        out / "summary.md",
        f"# Error against run time\n\n`{args.params}` ({config.layout}, {network.n_spll} sPLLs), "
        f"{args.samples} Poisson samples of {args.rate:g} Hz, {args.duration:g} s each.\n\n"
        f"{markdown_table(rows)}\n\n![work-precision](work_precision.png)\n\n"
        + (f"## Warnings\n\n{notes}" if notes else ""),
    )
    print(f"report: {out / 'summary.md'}")
    return 0
