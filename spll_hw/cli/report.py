"""``spll-hw report``: the main job — accuracy lost per layout × chip constraint, and how far each
backend is from the golden model for its run time, as one report folder."""

from __future__ import annotations

import argparse
import dataclasses
import functools
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
from .evaluate import add_dataset_arguments, load_split, tuned_encoder_settings

DEFAULT_PARAMS = "vibtac-time-scaled-lif"
#: Samples of the dataset whose cost on each chip is averaged.
COSTED_SAMPLES = 3
#: Time steps [s] of the work-precision curves of clocked backends.
REPORT_DTS = ("1e-4", "3e-5", "1e-5")


def register(sub: argparse._SubParsersAction) -> None:
    from .. import chips

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
        help="comma-separated chip profiles (names or TOML paths; none = exact): "
        f"{', '.join(chips.names())} (default: none,loihi2,analog)",
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
    h.add_argument(
        "--cv-repeats",
        type=int,
        default=10,
        help="CV repeats with fresh fold shuffles, the same for every cell (default 10)",
    )
    h.add_argument(
        "--cv",
        choices=("samples", "recordings"),
        default="samples",
        help="folds of samples (default) or of whole recordings (no recording in "
        "both the training and the test fold)",
    )
    h.add_argument(
        "--constructions", default="", metavar="SPECS",
        help="backends that approximate the exact sPLL on purpose, comma-separated (e.g. "
        "standard-exact:levels=4,standard-exact:levels=8: the standard-neuron gate with K "
        "levels): each scores every layout x profile again, paired with the exact cell",
    )  # fmt: skip
    h.add_argument("--chip-draws", type=int, default=5,
                   help="mismatch draws pooled per analog-profile cell (default 5)")  # fmt: skip
    h.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    h.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="cores (default all)")
    h.add_argument("--quiet", action="store_true", help="no progress output")
    h.add_argument("--out", type=Path, default=Path("reports/harness"), help="report folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from ..backends import parse_specs
    from ..encoders import make_encoder, settings_table, train_duration
    from ..harness import construction
    from ..harness.accuracy import accuracy_summary, columns, layout_accuracy
    from ..harness.accuracy_plots import plot_accuracy, plot_change_heatmap
    from ..harness.costs import auto_groups, layout_costs, plot_accuracy_energy
    from ..harness.costs import markdown as cost_markdown
    from ..harness.workprecision import markdown_table, plot, work_precision
    from ..pipeline import encode_samples
    from ..report.plots import plot_confusion
    from .compare import expand_specs

    layouts = [x.strip() for x in args.layouts.split(",") if x.strip()]
    profiles = [x.strip() for x in args.profiles.split(",") if x.strip()]
    specs = expand_specs(parse_specs(args.compare_backends), [float(x) for x in REPORT_DTS])
    backend = checked_backend(args.backend)
    # Labelled as typed (a canonical spec drops default options such as levels=8).
    constructions = [x.strip() for x in args.constructions.split(",") if x.strip()]
    # Unknown profiles and backends (constructions included) fail here, before any work.
    cols = columns(profiles, backend, chip_draws=args.chip_draws)
    for spec in constructions:
        columns(profiles, spec, chip=False, chip_draws=args.chip_draws)
    config = load_network_config(args)
    say = (lambda *a: None) if args.quiet else print
    if "grouped:auto" in layouts:  # the largest grouped layout the first chip profile holds
        chip = next((p for p in profiles if p != "none"), None)
        if chip is None:
            raise ValueError("--layouts grouped:auto needs a chip profile in --profiles")
        auto = f"grouped:{auto_groups(config, chip)}"
        say(f"grouped:auto on {chip}: {auto}")
        layouts = [auto if layout == "grouped:auto" else layout for layout in layouts]
    for layout in layouts:  # reject a bad layout before the long run
        config.with_layout(layout)
    encoder = make_encoder(
        args.encoder,
        **tuned_encoder_settings(str(args.params), [args.encoder]).get(args.encoder, {}),
    )
    samples, test = load_split(args)
    out = args.out
    say(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes, "
        f"encoder {encoder.name}, {len(layouts)} layouts x {len(profiles)} profiles")  # fmt: skip

    def on_cell(cell):
        result = f"{100 * cell.cv.accuracy:5.1f} %" if cell.cv else cell.report
        say(f"  {cell.layout:12s} {cell.profile:14s} {result}")

    score = functools.partial(
        layout_accuracy, samples, encoder, config, layouts, profiles, phase_noise=args.phase_noise,
        repeats=args.repeats, seed=args.seed, n_splits=args.folds, cv_repeats=args.cv_repeats,
        by_recording=args.cv == "recordings", test=test, chip_draws=args.chip_draws, jobs=args.jobs,
    )  # fmt: skip
    table = score(backend=backend, on_cell=on_cell)
    costed_constructions = []
    if constructions:
        say("constructions against exact:")

        def on_construction(row):
            change = f"{100 * row.change.mean:+5.1f} points" if row.change else "does not fit"
            say(f"  {row.construction} {row.cell.layout:12s} {row.cell.profile:14s} {change}")

        costed_constructions = construction.construction_cost(
            table, constructions, lambda spec: score(backend=spec, chip=False),
            on_construction,
        )  # fmt: skip
    out.mkdir(parents=True, exist_ok=True)
    pictures = ["accuracy.png"]
    if costed_constructions:
        construction.plot_cost(costed_constructions, out / "construction.png")
    plot_accuracy(table, out / "accuracy.png", chance=1 / samples.n_classes)
    if table.has_reference:
        plot_change_heatmap(table, out / "change.png")
        pictures.append("change.png")
    # What each layout costs on each chip, on a few of the dataset's own samples.
    costed = samples.normalized().subset(np.arange(min(COSTED_SAMPLES, len(samples))))
    window = train_duration(encoder, samples.duration)
    costs = layout_costs(config, layouts, cols, encode_samples(encoder, costed), window)
    if plot_accuracy_energy(table, costs, out / "accuracy_energy.png"):
        pictures.append("accuracy_energy.png")
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
              for _ in range(3)]  # fmt: skip

    def on_row(row):
        say(f"  {row.spec}: {1e3 * row.seconds_per_sample:.2f} ms/sample")

    rows = work_precision(specs, network, trains, samples.duration, on_row=on_row)
    plot(rows, out / "work_precision.png")
    write_text(out / "params.toml", config.to_toml() + "\n" + settings_table(encoder))
    write_json(out / "results.json", {
        "dataset": samples.name, "samples": len(samples), "encoder": encoder.name,
        "columns": {c.label: list(c.specs) for c in cols},
        "cv": {"scheme": args.cv, "n_splits": args.folds, "repeats": args.cv_repeats,
               "noise_draws": args.repeats, "chip_draws": args.chip_draws, "seed": args.seed,
            "test_recordings": args.test_recordings},
        "encoder_params": dataclasses.asdict(encoder), "accuracy": accuracy_summary(table),
        "work_precision": [r.__dict__ for r in rows],
        "costs": [{"layout": c.layout, "column": c.column} | c.to_dict() for c in costs],
        "constructions": [c.to_dict() for c in costed_constructions],
    })  # fmt: skip
    reports = "".join(
        f"\n### {c.layout} under {c.profile}\n\n{c.report}\n"
        for c in table.cells
        if c.report and c.layout == layouts[0]
    )
    command = "spll-hw " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    if test is not None:
        scheme = (
            f"trained on these samples and tested once on {len(test)} samples of the held-out "
            f"recordings {args.test_recordings} (intervals: bootstrap over test recordings)"
        )
    else:
        scheme = (
            f"{args.cv_repeats} x {args.folds}-fold CV of {args.cv}, the same folds for every cell"
        )
    write_text(
        out / "summary.md",
        f"# Hardware constraints report\n\n`{command}`\n\n"
        f"Dataset `{samples.name}` ({len(samples)} samples, {samples.n_classes} classes), "
        f"encoder `{encoder}`, network `{args.params}` ({network.n_spll} sPLLs), "
        f"phase noise {args.phase_noise:g} s x {args.repeats} draw(s), {scheme}.\n\n"
        f"## Accuracy per layout x constraint profile\n\n"
        + "".join(f"![{f}]({f})\n\n" for f in pictures)
        + "Accuracy: mean ± half-width of its 95 % CI. In brackets: the change in points against "
        "the unconstrained time-scaled network, paired (fold by fold under CV: corrected "
        "resampled t, which accounts for overlapping training folds; sample by sample on held-out "
        "recordings: bootstrap over recordings), with its 95 % CI; "
        "**bold** changes are distinguishable from zero, the others are ties. Each column's "
        "features come from one backend"
        + (
            f" (analog profiles: {args.chip_draws} mismatch draws pooled)"
            if any(c.draws for c in cols)
            else ""
        )
        + ":\n\n"
        + "".join(f"- {c.label}: `{c.spec}`\n" for c in cols)
        + f"\n{table.markdown()}\n\n"
        + (
            "## What the construction costs\n\n![construction](construction.png)\n\n"
            "Each construction (a backend that approximates the exact sPLL on purpose) scored "
            "on the same samples, folds and draws as the exact table; in brackets its paired "
            "change against the exact cell of the same layout and profile, in points, with "
            f"its 95 % CI (**bold**: distinguishable from zero).\n\n"
            f"{construction.markdown(costed_constructions)}\n\n"
            if costed_constructions
            else ""
        )
        + (
            f"## Chips: fit, cores, energy and latency\n\nEach layout mapped onto the chip of "
            f"every column with chip tables, costed on {COSTED_SAMPLES} of the dataset's samples "
            f"simulated on the column's backend (`spll-hw chips` lists every figure and its "
            f"source; `*`: rests on assumed figures).\n\n{cost_markdown(costs)}\n\n"
            if costs
            else ""
        )
        + f"## Error against run time (golden model = truth)\n\n{markdown_table(rows)}\n\n"
        f"![work-precision](work_precision.png)\n"
        + (f"\n## Quantization reports\n{reports}" if reports else "")
        + "\n## Appendix: confusion matrices\n\n"
        + "".join(f"![{f}]({f})\n" for f in figures),
    )
    say(f"report: {out / 'summary.md'}")
    return 0
