"""Every shipped preset's standard exports checked on encoded real input and sPLL by sPLL.

For every preset and target (``lava-standard``, ``nir-standard``) this runs the export check
(:func:`spll_hw.exporters.check.check_run`) of what the export writes, from memory by the
backend that runs the written files spike for spike (``standard-fixed-point``, ``nir-numpy``),
at the step, gate and refractory hold the export's step ladder writes for that preset
(:data:`WRITTEN`, from docs/notes/2026-11-27-lava-standard-step-per-preset.md and
2026-11-28-nir-standard-step-per-preset.md; the ladder itself takes up to 10 minutes a preset
on 2 shared cores), on the six reference trains (of 10 s where the ladder judged the step on
them, :data:`ON_10_S`, as the folder's check then does) and on the preset's encoded inputs
(:func:`spll_hw.exporters.encoded.encoded_inputs`: four windows of held-out BioTac recordings
through the preset's encoder with ``--data``; synthetic textures through it for a VibTac
preset). Per export: the TDE-rate error on the reference trains and on the encoded inputs,
golden's own variation on the encoded inputs (golden on them 0.5 ms later), the sPLLs the
per-sPLL verdict fails and the verdict, the one ``spll-hw export --to TARGET --network PRESET
--data DIR`` gives after its ladder. One JSON line per export goes to ``--json`` as it is
measured, the Markdown table to stdout.

    python benchmarks/bench_export_real_input.py --jobs 2 \\
        --data ../shared/datasets/biotac_slide_20_50 --json export_real_input.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spll_hw import presets  # noqa: E402
from spll_hw.exporters.check_inputs import ENCODED_KINDS, REFERENCE_KINDS  # noqa: E402

TARGETS = ("lava-standard", "nir-standard")
#: What each export writes: ``(step [s] or "clock" / "graded clock", placement, levels, hold)``
#: (levels ``None``: the target's 16; hold ``None``: compensated), ``None`` where the ladder
#: refuses the preset; where the step leaves open-loop CCOs, lava-standard writes the clock per
#: sPLL if its check passes on the reference trains (mappings/lava/exporter.py).
U, B = ("uniform", None), ("band-quantile", None)
B32 = ("band-quantile", 32)
LAVA = {
    "biotac-time-scaled-lif": ("graded clock", "band-quantile", 64, None),
    "biotac-time-scaled-pacinian": ("clock", *B32, None),
    "biotac-time-scaled-peak": (5e-5, *U, None),
    "biotac-tuned-time-scaled-lif": (2.5e-5, *B32, "dithered"),
    "biotac-tuned-time-scaled-peak": (1e-5, *B, None),
    "biotac-tuned-vary-offset-lif": ("clock", *B32, None),  # 50 µs: 16 open-loop CCOs
    "biotac-tuned-vary-offset-pacinian": (5e-5, *U, None),
    "biotac-tuned-vary-offset-peak": (5e-5, *U, None),
    "biotac-vary-offset-lif": (5e-5, *U, None),
    "biotac-vary-offset-pacinian": (5e-5, *U, None),
    "biotac-vary-offset-peak": (5e-5, *U, None),
    "vibtac-time-scaled-lif": (2.5e-5, *B32, None),
    "vibtac-time-scaled-pacinian": (5e-5, *B, None),
    "vibtac-time-scaled-peak": None,
    "vibtac-vary-offset-lif": (5e-5, *U, None),
    "vibtac-vary-offset-pacinian": (5e-5, *U, None),
    "vibtac-vary-offset-peak": ("clock", *B32, None),  # 50 µs: every CCO open-loop
}
NIR = {
    "biotac-time-scaled-lif": (5e-5, *B32, None),
    "biotac-time-scaled-pacinian": (5e-5, *B, None),
    "biotac-time-scaled-peak": (1e-4, *U, None),
    "biotac-tuned-time-scaled-lif": (5e-5, *B, None),
    "biotac-tuned-time-scaled-peak": (5e-5, *B, None),
    "biotac-tuned-vary-offset-lif": (1e-4, *U, None),
    "biotac-tuned-vary-offset-pacinian": (1e-4, *U, None),
    "biotac-tuned-vary-offset-peak": (1e-4, *U, None),
    "biotac-vary-offset-lif": (1e-4, *U, None),
    "biotac-vary-offset-pacinian": (1e-4, *B32, None),
    "biotac-vary-offset-peak": (1e-4, *U, None),
    "vibtac-time-scaled-lif": (1e-4, *B, None),
    "vibtac-time-scaled-pacinian": (1e-4, *B, None),
    # 2 µs since cb6a3e5 (docs/notes/2026-12-06-export-real-input.md); the table of that note
    # measured the 1 µs of the 2026-11-28 ladder
    "vibtac-time-scaled-peak": (2e-6, *U, None),
    "vibtac-vary-offset-lif": (1e-4, *U, None),
    "vibtac-vary-offset-pacinian": (1e-4, *U, None),
    "vibtac-vary-offset-peak": (1e-4, *U, None),
}
WRITTEN = {"lava-standard": LAVA, "nir-standard": NIR}
#: The exports whose step the ladder judged on reference trains of 10 s (1 s does not resolve
#: it): their check's reference trains last 10 s, as the folder's do.
ON_10_S = {
    ("biotac-vary-offset-peak", "lava-standard"),
    ("biotac-time-scaled-peak", "lava-standard"),
    ("biotac-time-scaled-peak", "nir-standard"),
}


def backend(target: str, written: tuple):
    """The backend that runs what ``target`` writes as ``written`` (:data:`WRITTEN`)."""
    from spll_hw.backends import get

    step, placement, levels, hold = written
    gate = {"placement": placement, "levels": levels or 16}
    if target == "nir-standard":
        return get("nir-numpy", dt=step, **gate)
    hold = {"hold": hold} if hold else {}
    if isinstance(step, str):
        current = "graded" if step.startswith("graded") else "lif"
        return get("standard-fixed-point", clock="per-spll", holds=4, current=current, **gate)
    return get("standard-fixed-point", dt=step, **gate, **hold)


def measure(job: tuple[str, str, str | None]) -> dict:
    """The check of ``preset``'s ``target`` export (module docstring) as one row."""
    from spll_hw.config import read_network_file
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import LONGER, check_run
    from spll_hw.exporters.check_inputs import DURATION
    from spll_hw.exporters.encoded import encoded_inputs

    preset, target, data = job
    written = WRITTEN[target][preset]
    row = {"preset": preset, "target": target}
    if written is None:
        return row | {"refused": "by the step ladder: no step passes on the reference trains"}
    start = time.perf_counter()
    file = read_network_file(preset)
    network = file.config.build()
    inputs = encoded_inputs(file, data)
    run = FolderRun.by_backend(f"{target} as written", backend(target, written), network)
    duration = LONGER if (preset, target) in ON_10_S else DURATION
    report = check_run(run, target, network, inputs=inputs, duration=duration)
    return row | {
        "written": list(written),
        "reference_s": duration,
        "reference": report.error_of(REFERENCE_KINDS)[0],
        "encoded": report.encoded_error,
        "golden_encoded": report.error_of(ENCODED_KINDS)[1],
        "golden_reference": report.error_of(REFERENCE_KINDS)[1],
        "encoded_kind": next((x.kind for x in inputs), None),
        "total": report.tde_error,
        "limit": report.max_error,
        "failed": report.failed,
        "passed": report.passed,
        "wall_s": round(time.perf_counter() - start),
    }


def _pct(x) -> str:
    return "–" if x is None or x != x else f"{100 * x:.1f} %"


def _step(written: list, reference_s: float) -> str:
    step, placement, levels, hold = written
    where = step if isinstance(step, str) else f"{step * 1e6:g} µs"
    where += " (reference trains of 10 s)" if reference_s != 1 else ""
    gate = f"{levels or 16} {placement}"
    return f"{where}, {gate}" + (f", {hold}" if hold else "")


def markdown(rows: list[dict]) -> str:
    """The table of the note."""
    lines = [
        "| preset | target | written | reference trains | encoded input | golden's own "
        "variation (reference / encoded) | sPLLs failed | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "refused" in r:
            lines.append(f"| `{r['preset']}` | {r['target']} | | | | | | refused "
                         f"{r['refused']} |")  # fmt: skip
            continue
        kind = " (synthetic)" if r["encoded_kind"] == "synthetic-encoded" else ""
        failed = ", ".join(str(x["spll"]) for x in r["failed"])
        verdict = "passes" if r["passed"] else "**refused**"
        lines.append(
            f"| `{r['preset']}` | {r['target']} | {_step(r['written'], r['reference_s'])} | "
            f"{_pct(r['reference'])} | {_pct(r['encoded'])}{kind} | "
            f"{_pct(r['golden_reference'])} / {_pct(r['golden_encoded'])} | {len(r['failed'])}"
            f"{f' ({failed})' if failed else ''} | {verdict} (limit {_pct(r['limit'])}) |"
        )
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--presets", help="comma list (default: every shipped preset)")
    p.add_argument("--targets", default=",".join(TARGETS))
    p.add_argument("--data", help="BioTac_slide_20_50 folder, for the biotac presets")
    p.add_argument("--jobs", type=int, default=1, help="checks at once (processes)")
    p.add_argument("--json", type=Path, help="append one JSON line per export here")
    args = p.parse_args()
    names = args.presets.split(",") if args.presets else presets.names()
    jobs = [(name, target, args.data if name.startswith("biotac") else None)
            for name in names for target in args.targets.split(",")]  # fmt: skip
    rows = []
    with ProcessPoolExecutor(args.jobs) as pool:
        for row in pool.map(measure, jobs):
            rows.append(row)
            if args.json:
                with args.json.open("a") as f:
                    f.write(json.dumps(row) + "\n")
            print(f"{row['preset']} {row['target']}: {row}", file=sys.stderr, flush=True)
    print(markdown(rows))


if __name__ == "__main__":
    main()
