"""``spll-hw evaluate``: run the texture pipeline on a dataset and write a report folder."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from ...encoders import make_encoder
from ...files import atomic_folder
from ...pipeline import PipelineConfig, run_pipeline
from ...report import write_report
from ...report.markdown import accuracy_table, percent
from ..arguments import split_list
from ..inputs import (
    checked_backend,
    command_line,
    encoder_overrides,
    jobs,
    load_split,
    read_network_files,
    tuned_encoder_settings,
    tuned_input_level,
)


def run(args: argparse.Namespace) -> int:
    names = split_list(args.encoders)
    overrides = encoder_overrides(args.set, names)
    features = tuple(split_list(args.features))
    files = read_network_files(args.network, names) if "spll" in features else {}
    tuned = tuned_encoder_settings(files, names)
    level = tuned_input_level(files, names)
    encoders = [make_encoder(n, **(tuned.get(n, {}) | overrides[n])) for n in names]
    config = PipelineConfig(
        features=features,
        phase_noise=args.phase_noise,
        repeats=args.repeats,
        seed=args.seed,
        n_splits=args.folds,
        cv=args.cv,
        alpha=args.alpha,
        isi_spacing=args.isi_spacing,
        network=args.network,
        backend=checked_backend(args.backend) if "spll" in features else "golden",
        jobs=jobs(args),
        progress=not args.quiet,
    )
    networks = {name: f.config.build() for name, f in files.items()}  # before the long run
    samples, test = load_split(args)
    result = run_pipeline(samples, encoders, config, test, networks, input_level=level)
    out = Path(args.out or os.path.join("reports", samples.name))
    with atomic_folder(out) as stage:  # a full disk or Ctrl-C leaves no half a folder
        summary = out / write_report(result, stage, command_line()).name
    print(f"{samples.name}: {len(samples)} samples, {samples.n_classes} classes")
    for feature, row in accuracy_table(result).items():
        print(f"  {feature:8s} " + "  ".join(f"{enc}: {percent(*acc)}" for enc, acc in row.items()))
    print(f"report: {summary}")
    return 0
