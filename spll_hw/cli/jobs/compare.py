"""``spll-hw compare``: error against run time of every backend versus the golden model."""

from __future__ import annotations

import argparse

from ...backends import parse_specs
from ...files import atomic_folder, write_results, write_text
from ...harness.workprecision import markdown_table, plot, work_precision
from ...simulate import poisson_trains
from ..arguments import split_list
from ..inputs import default_backends, expand_specs, read_network


def run(args: argparse.Namespace) -> int:
    dts = [float(x) for x in split_list(args.dt)]
    specs = expand_specs(parse_specs(args.backends or default_backends()), dts)
    if args.samples < 1:
        raise ValueError("--samples must be >= 1")
    config = read_network(args).config
    network = config.build()
    trains = poisson_trains(args.rate, args.duration, args.samples, args.seed)

    def progress(row):
        print(f"  {row.name:44s} {1e3 * row.seconds_per_sample:9.2f} ms/sample  "
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
