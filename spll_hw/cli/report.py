"""``spll-hw report``: the main job — accuracy lost per layout × chip constraint, and how far each
backend is from the golden model for its run time, as one report folder."""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import shlex
import sys
from pathlib import Path

from ..files import write_json, write_text
from .common import (
    add_backend_argument,
    add_params_argument,
    checked_backend,
    load_network_config,
)
from .evaluate import add_dataset_arguments, load_samples, tuned_encoder_settings

DEFAULT_PARAMS = "vibtac-time-scaled-lif"


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "report",
        help="accuracy loss per layout x constraint profile and error vs run time per backend",
        description="Encode a dataset once, then classify it with the sPLL network built in "
        "every layout (time-scaled, vary-offset, grouped G) under every chip constraint profile, "
        "and report the accuracy loss against the unconstrained time-scaled network, plus an "
        "error-against-run-time table of the backends. Runs on the embedded synthetic data "
        "without arguments.",
    )
    add_dataset_arguments(p)
    add_params_argument(p, default=DEFAULT_PARAMS)
    h = p.add_argument_group("harness")
    h.add_argument(
        "--encoder",
        default="lif",
        help="encoder (default lif), with the settings of the --params file's [encoder] table "
        "when it was tuned on this encoder",
    )
    h.add_argument("--layouts", default="time-scaled,vary-offset,grouped:2,grouped:4,grouped:8",
                   help="comma-separated layouts")  # fmt: skip
    h.add_argument(
        "--profiles",
        default="none,loihi2,analog",
        help="comma-separated quantize/ profiles (names or TOML paths); none = exact",
    )
    add_backend_argument(h)
    h.add_argument(
        "--compare-backends",
        default="golden,golden-fixed-point",
        help="backends for the error-vs-run-time table (see spll-hw compare)",
    )
    h.add_argument("--phase-noise", type=float, default=5e-4, help="phase noise [s] (thesis 5e-4)")
    h.add_argument("--repeats", type=int, default=1, help="noise draws per sample (default 1)")
    h.add_argument("--folds", type=int, default=5, help="CV folds (default 5)")
    h.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    h.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="cores (default all)")
    h.add_argument("--quiet", action="store_true", help="no progress output")
    h.add_argument("--out", type=Path, default=Path("reports/harness"), help="report folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..backends import parse_specs
    from ..encoders import make_encoder, settings_table
    from ..harness.accuracy import accuracy_summary, columns, layout_accuracy
    from ..harness.workprecision import markdown_table, plot, work_precision
    from ..report.plots import plot_confusion

    layouts = [x.strip() for x in args.layouts.split(",") if x.strip()]
    profiles = [x.strip() for x in args.profiles.split(",") if x.strip()]
    specs = parse_specs(args.compare_backends)
    backend = checked_backend(args.backend)
    cols = columns(profiles, backend)  # unknown profiles and backends fail here, before any work
    config = load_network_config(args)
    for layout in layouts:  # reject a bad layout before the long run
        config.with_layout(layout)
    encoder = make_encoder(
        args.encoder,
        **tuned_encoder_settings(str(args.params), [args.encoder]).get(args.encoder, {}),
    )
    samples = load_samples(args)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    say = (lambda *a: None) if args.quiet else print
    say(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes, "
        f"encoder {encoder.name}, {len(layouts)} layouts x {len(profiles)} profiles")  # fmt: skip

    def on_cell(cell):
        result = f"{100 * cell.cv.accuracy:5.1f} %" if cell.cv else cell.report
        say(f"  {cell.layout:12s} {cell.profile:14s} {result}")

    table = layout_accuracy(
        samples, encoder, config, layouts, profiles, backend=backend, phase_noise=args.phase_noise,
        repeats=args.repeats, seed=args.seed, n_splits=args.folds, jobs=args.jobs,
        on_cell=on_cell,
    )  # fmt: skip
    figures = []
    for cell in table.cells:
        if cell.cv is None:
            continue
        label = re.sub(r"[^A-Za-z0-9_-]+", "", f"{cell.layout}_{Path(cell.profile).stem}")
        name = f"confusion_{label}.png"
        plot_confusion(cell.cv.confusion_normalized(), samples.class_names,
                       f"{cell.layout}, {cell.profile}: {100 * cell.cv.accuracy:.1f} %",
                       out / name)  # fmt: skip
        figures.append(name)
    say("error against run time:")
    network = config.build()
    rng = np.random.default_rng(args.seed)
    trains = [np.sort(rng.uniform(0, samples.duration, rng.poisson(300 * samples.duration)))
              for _ in range(2)]  # fmt: skip

    def on_row(row):
        say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample")

    rows = work_precision(specs, network, trains, samples.duration, on_row=on_row)
    plot(rows, out / "work_precision.png")
    write_text(out / "params.toml", config.to_toml() + "\n" + settings_table(encoder))
    write_json(out / "results.json", {
        "dataset": samples.name, "samples": len(samples), "encoder": encoder.name,
        "columns": {c.label: c.spec for c in cols},
        "encoder_params": dataclasses.asdict(encoder), "accuracy": accuracy_summary(table),
        "work_precision": [r.__dict__ for r in rows],
    })  # fmt: skip
    reports = "".join(
        f"\n### {c.layout} under {c.profile}\n\n{c.report}\n"
        for c in table.cells
        if c.report and c.layout == layouts[0]
    )
    command = "spll-hw " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    write_text(
        out / "summary.md",
        f"# Hardware constraints report\n\n`{command}`\n\n"
        f"Dataset `{samples.name}` ({len(samples)} samples, {samples.n_classes} classes), "
        f"encoder `{encoder}`, network `{args.params}` ({network.n_spll} sPLLs), "
        f"phase noise {args.phase_noise:g} s x {args.repeats}, {args.folds}-fold CV.\n\n"
        f"## Accuracy per layout x constraint profile\n\nMean ± sd over folds; in brackets the "
        f"change in points against the unconstrained time-scaled network. Each column's "
        f"features come from one backend:\n\n"
        + "".join(f"- {c.label}: `{c.spec}`\n" for c in cols)
        + f"\n{table.markdown()}\n\n"
        + "".join(f"![{f}]({f})\n" for f in figures)
        + f"\n## Error against run time (golden model = truth)\n\n{markdown_table(rows)}\n\n"
        f"![work-precision](work_precision.png)\n"
        + (f"\n## Quantization reports\n{reports}" if reports else ""),
    )
    say(f"report: {out / 'summary.md'}")
    return 0
