"""``spll-hw compare``: error against run time of every backend versus the golden model."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..files import atomic_folder, write_results, write_text
from .arguments import DEFAULT_DTS, add_network_argument, default_backends, split_list
from .inputs import expand_specs, read_network

#: The command's line in ``spll-hw --help``.
HELP = "error against run time of backends (Brian2, Lava, fixed point, USB) vs golden"
#: What ``spll-hw compare --help`` says first.
DESCRIPTION = (
    "Simulate the same Poisson samples on each backend and report wall time per "
    "sample against TDE-rate, TDE-count and spike-time error versus the golden model "
    "(Markdown table, JSON and a work-precision plot)."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_network_argument(p)
    p.add_argument(
        "--backends",
        help="comma-separated backend specs, e.g. golden,brian2-cpp_standalone,lava-fixed "
        "(options after ':', e.g. brian2-numpy:dt=1e-5; spll-hw backends lists them) (default: "
        "golden, golden-fixed-point and brian2-cpp_standalone where Brian2 is installed)",
    )
    p.add_argument(
        "--dt",
        default=DEFAULT_DTS,
        help="time steps [s] of the curve of every clocked backend without its own dt",
    )
    p.add_argument("--samples", type=int, default=3, help="Poisson samples")
    p.add_argument("--rate", type=float, default=300.0, help="input rate [Hz]")
    p.add_argument("--duration", type=float, default=2.0, help="seconds per sample")
    p.add_argument("--seed", type=int, default=0, help="seed of the first sample")
    p.add_argument("--out", type=Path, default=Path("reports/compare"), help="report folder")


def run(args: argparse.Namespace) -> int:
    from ..backends import parse_specs
    from ..harness.workprecision import markdown_table, plot, work_precision
    from ..simulate import poisson_trains

    dts = [float(x) for x in split_list(args.dt)]
    specs = expand_specs(parse_specs(args.backends or default_backends()), dts)
    if args.samples < 1:
        raise ValueError("--samples must be >= 1")
    config = read_network(args).config
    network = config.build()
    trains = poisson_trains(args.rate, args.duration, args.samples, args.seed)

    def progress(row):
        print(f"  {row.spec:40s} {1e3 * row.seconds_per_sample:9.2f} ms/sample  "
              f"rate error {100 * row.rate_error:.3f} %")  # fmt: skip

    failed = []
    rows = work_precision(specs, network, trains, args.duration, on_row=progress, failed=failed)
    with atomic_folder(args.out) as out:
        write_text(out / "params.toml", config.to_toml())
        plot(rows, out / "work_precision.png")
        write_results(out / "results.json", {
            "rows": [row.__dict__ for row in rows], "failed": [row.__dict__ for row in failed],
        })  # fmt: skip
        warnings = sorted({w for row in rows for w in row.warnings})
        notes = "".join(f"- {w}\n" for w in warnings)
        failures = "".join(f"- `{row.spec}`: {row.error}\n" for row in failed)
        write_text(
            out / "summary.md",
            f"# Error against run time\n\n`{args.network}` ({config.layout}, "
            f"{network.n_spll} sPLLs), "
            f"{args.samples} Poisson samples of {args.rate:g} Hz, {args.duration:g} s each.\n\n"
            + (f"**Failed while running** (not in the table):\n\n{failures}\n" if failures else "")
            + f"{markdown_table(rows)}\n\n![work-precision](work_precision.png)\n\n"
            + (f"## Warnings\n\n{notes}" if notes else ""),
        )
    print(f"report: {args.out / 'summary.md'}")
    if failed:
        raise ValueError(
            f"{len(failed)} backend(s) failed while running; the others are in "
            f"{args.out / 'summary.md'}: " + "; ".join(f"{row.spec}: {row.error}" for row in failed)
        )
    return 0
