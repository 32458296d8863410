"""Reproduce the thesis's BioTac (11-class) accuracies and time every encoder x feature.

Runs the whole texture pipeline on BioTac_slide_20_50 (the thesis's 11 materials, every recording
found, 2-s samples): the pressure-spectrum baseline (thesis 3.1: 84.4 %), Table 1's sFFT and ISI
rows for the three encoders, and the sPLL rows with each encoder's tuned BioTac network from
Tables 6-7 (thesis Table 2; phase noise 0.5 ms, three draws, as in thesis 2.9). Prints a table and
rewrites the generated section of ``docs/pipeline_results.md`` (hand-written text outside the
markers stays), plus the raw numbers as JSON.

    python benchmarks/pipeline_thesis_table1.py --data ../shared/datasets/biotac_slide_20_50 \\
        --jobs 1 --layouts vary-offset,time-scaled

Seconds are wall time on this machine for the full 11-class dataset: encoding (all samples, one
encoder) and extraction (all samples, one feature), with ``--jobs`` processes / engine threads.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from spll_hw.datasets import load_biotac  # noqa: E402
from spll_hw.encoders import LIFEncoder, PacinianEncoder, PeakOscillatorEncoder  # noqa: E402
from spll_hw.pipeline import PipelineConfig, run_pipeline  # noqa: E402

BEGIN = "<!-- BEGIN GENERATED: benchmarks/pipeline_thesis_table1.py -->"
END = "<!-- END GENERATED -->"
ENCODERS = ("lif", "pacinian", "peak")
#: Thesis figures [%]: section 3.1, Table 1 (BioTac rows) and Table 2 (BioTac rows).
THESIS = {
    ("spectrum", None): 84.4,
    ("sfft", "lif"): 63.4, ("sfft", "pacinian"): 53.9, ("sfft", "peak"): 35.3,
    ("isi", "lif"): 38.3, ("isi", "pacinian"): 39.7, ("isi", "peak"): 21.5,
    ("spll vary-offset", "lif"): 37.1, ("spll vary-offset", "pacinian"): 53.4,
    ("spll vary-offset", "peak"): 37.2,
    ("spll time-scaled", "lif"): 47.4, ("spll time-scaled", "pacinian"): 50.7,
    ("spll time-scaled", "peak"): 37.3,
}  # fmt: skip
LABELS = {"lif": "LIF", "pacinian": "Pacinian (TouchSim)", "peak": "peak oscillator"}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--data",
        default=os.environ.get(
            "SPLL_HW_BIOTAC_DIR", str(REPO.parent / "shared/datasets/biotac_slide_20_50")
        ),
        help="BioTac_slide_20_50 folder (default $SPLL_HW_BIOTAC_DIR or ../shared/...)",
    )
    p.add_argument("--jobs", type=int, default=1, help="processes / engine threads (default 1)")
    p.add_argument("--layouts", default="vary-offset,time-scaled",
                   help="sPLL network layouts to run ('' for none)")  # fmt: skip
    p.add_argument("--phase-noise", type=float, default=5e-4, help="sPLL input jitter sd [s]")
    p.add_argument("--repeats", type=int, default=3, help="noise draws for the sPLL rows")
    p.add_argument("--doc", default=str(REPO / "docs" / "pipeline_results.md"))
    p.add_argument("--json", default=str(REPO / "benchmarks" / "results" / "pipeline_table1.json"))
    p.add_argument("--per-class", type=int, help="quick check on this many samples per class")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args()

    start = time.perf_counter()
    samples = load_biotac(args.data, "thesis11", progress=not args.quiet)
    if args.per_class:
        samples = samples.per_class(args.per_class)
    load_seconds = time.perf_counter() - start
    encoders = [LIFEncoder(), PacinianEncoder(), PeakOscillatorEncoder()]
    base = PipelineConfig(
        features=("spectrum", "sfft", "isi"), jobs=args.jobs, progress=not args.quiet
    )
    rows: dict[tuple[str, str | None], dict] = {}
    encode_seconds: dict[str, float] = {}

    def collect(result, label=None):
        for name, seconds in result.encode_seconds.items():
            encode_seconds.setdefault(name, seconds)
        for r in result.results:
            rows[(label or r.feature, r.encoder)] = {
                "accuracy": r.cv.accuracy,
                "sd": r.cv.accuracy_sd,
                "seconds": r.seconds,
                "folds": len(r.cv.fold_accuracies),
            }

    collect(run_pipeline(samples, encoders, base))
    geometric = replace(base, features=("isi",), isi_spacing="geometric")
    collect(run_pipeline(samples, encoders, geometric), "isi (geometric bins)")
    for layout in [x for x in args.layouts.split(",") if x]:
        config = replace(
            base,
            features=("spll",),
            network=f"biotac-{layout}-{{encoder}}",
            phase_noise=args.phase_noise,
            repeats=args.repeats,
        )
        collect(run_pipeline(samples, encoders, config), f"spll {layout}")

    payload = {
        "dataset": samples.summary(),
        "load_seconds": load_seconds,
        "encode_seconds": encode_seconds,
        "jobs": args.jobs,
        "phase_noise": args.phase_noise,
        "repeats": args.repeats,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}",
        "encoders": {e.name: repr(e) for e in encoders},
        "rows": [{"feature": f, "encoder": e} | v for (f, e), v in rows.items()],
    }
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(payload, indent=2) + "\n")
    generated = render(payload, rows)
    print(generated)
    write_doc(Path(args.doc), generated)
    return 0


def render(payload: dict, rows: dict) -> str:
    d = payload["dataset"]
    counts = d["class_counts"].values()
    lines = [
        BEGIN,
        "",
        f"BioTac 11 classes, {d['n_samples']} samples of {d['sample_duration_s']:g} s "
        f"({min(counts)}-{max(counts)} per class), stratified 5-fold CV, "
        "accuracy mean ± sd over folds (sPLL rows: "
        f"{payload['repeats']} phase-noise draws of {payload['phase_noise'] * 1e3:g} ms pooled, "
        f"{5 * payload['repeats']} folds). Machine: {payload['machine']}; "
        f"{payload['jobs']} worker(s).",
        "",
        "| feature | encoder | this repo | thesis | encode [s] | extract [s] |",
        "|---|---|---|---|---|---|",
    ]
    features = list(dict.fromkeys(f for f, _ in rows))
    order = [None, *ENCODERS]
    for feature, encoder in sorted(rows, key=lambda k: (features.index(k[0]), order.index(k[1]))):
        v = rows[(feature, encoder)]
        thesis = THESIS.get((feature, encoder))
        enc_s = payload["encode_seconds"].get(encoder)
        lines.append(
            f"| {feature} | {LABELS.get(encoder, 'pressure (no encoder)')} "
            f"| {100 * v['accuracy']:.1f} ± {100 * v['sd']:.1f} % "
            f"| {'' if thesis is None else f'{thesis:.1f} %'} "
            f"| {'' if enc_s is None else f'{enc_s:.1f}'} | {v['seconds']:.1f} |"
        )
    lines += [
        "",
        f"Loading the CSVs took {payload['load_seconds']:.1f} s. Encoder settings:",
        "",
    ]
    lines += [f"- `{r}`" for r in payload["encoders"].values()]
    lines += ["", END]
    return "\n".join(lines)


def write_doc(path: Path, generated: str) -> None:
    text = path.read_text() if path.exists() else f"# Pipeline results\n\n{BEGIN}\n{END}\n"
    if BEGIN not in text or END not in text:
        raise ValueError(f"{path}: markers {BEGIN!r} ... {END!r} not found")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(head + generated + tail)


if __name__ == "__main__":
    sys.exit(main())
