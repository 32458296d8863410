"""Every shipped preset's standard exports checked on encoded real input and sPLL by sPLL.

For every preset and target (``lava-standard``, ``nir-standard``) this runs the export command
itself, ``spll-hw export --to TARGET --network PRESET --data DIR --allow-error`` (the step
ladder, then the folder's check on the six reference trains and on four windows of held-out
BioTac recordings encoded by the preset's encoder, :mod:`spll_hw.exporters.encoded`; synthetic
textures through that encoder for a VibTac preset), each in its own process, and reads the
folder's ``check.json``: the TDE-rate error on the reference trains and on the encoded inputs,
golden's own variation on the encoded inputs (golden on them 0.5 ms later), the sPLLs the
per-sPLL verdict fails, the verdict (``--allow-error`` keeps a failing export so that its
numbers are there; without it the export is refused with :meth:`CheckReport.failure`'s
message) and the step written. One JSON line per export goes to ``--json`` as it is measured,
the Markdown table to stdout.

    SPLL_HW_BIOTAC_DIR=../shared/datasets/biotac_slide_20_50 \\
        python benchmarks/bench_export_real_input.py --jobs 2 \\
        --json benchmarks/results/export_real_input.jsonl
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from spll_hw import presets  # noqa: E402
from spll_hw.exporters.check import ENCODED_KINDS, REFERENCE_KINDS  # noqa: E402

TARGETS = ("lava-standard", "nir-standard")


def measure(preset: str, target: str, data: str | None) -> dict:
    """One export of ``preset`` to ``target`` (module docstring): its ``check.json``'s numbers,
    or the export's own refusal where it wrote nothing."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "export"
        command = [sys.executable, "-m", "spll_hw", "export", "--to", target, "--network",
                   preset, "--out", str(out), "--allow-error"]  # fmt: skip
        if data:
            command += ["--data", data]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, cwd=REPO)
        row = {"preset": preset, "target": target, "wall_s": round(time.perf_counter() - start)}
        if not (out / "check.json").is_file():
            lines = done.stderr.strip().splitlines()
            return row | {"refused": lines[-1] if lines else f"exit {done.returncode}"}
        record = json.loads((out / "check.json").read_text())
        step = json.loads((out / "standard.json").read_text()).get("dt")
    inputs = record["inputs"]
    return row | {
        "dt_s": step,
        "reference": _mean(inputs, REFERENCE_KINDS, "tde_rate_error"),
        "encoded": _mean(inputs, ENCODED_KINDS, "tde_rate_error"),
        "golden_encoded": _mean(inputs, ENCODED_KINDS, "golden_shifted_tde_rate_error"),
        "encoded_kind": next((x["kind"] for x in inputs if x["kind"] in ENCODED_KINDS), None),
        "total": record["total"]["tde_rate_error"],
        "limit": record["max_error"],
        "failed": record["failed_splls"]["splls"],
        "passed": record["passed"],
    }


def _mean(inputs: list[dict], kinds, key: str) -> float | None:
    values = [x[key] for x in inputs if x["kind"] in kinds and x["golden_tde_spikes"] > 0]
    return sum(values) / len(values) if values else None


def _pct(x) -> str:
    return "–" if x is None else f"{100 * x:.1f} %"


def markdown(rows: list[dict]) -> str:
    """The table of the note and docs/backends.md."""
    lines = [
        "| preset | target | step | reference trains | encoded input | golden's own variation "
        "| sPLLs failed | verdict |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "refused" in r:
            lines.append(f"| `{r['preset']}` | {r['target']} | | | | | | refused: "
                         f"{r['refused'][:160]} |")  # fmt: skip
            continue
        step = "a clock per sPLL" if r["dt_s"] is None else f"{r['dt_s'] * 1e6:g} µs"
        kind = " (synthetic)" if r["encoded_kind"] == "synthetic-encoded" else ""
        failed = ", ".join(str(x["spll"]) for x in r["failed"])
        verdict = "passed" if r["passed"] else "**refused**"
        lines.append(
            f"| `{r['preset']}` | {r['target']} | {step} | {_pct(r['reference'])} | "
            f"{_pct(r['encoded'])}{kind} | {_pct(r['golden_encoded'])} | "
            f"{len(r['failed'])}{f' ({failed})' if failed else ''} | {verdict} "
            f"(limit {_pct(r['limit'])}) |"
        )
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--presets", help="comma list (default: every shipped preset)")
    p.add_argument("--targets", default=",".join(TARGETS))
    p.add_argument("--data", default=os.environ.get("SPLL_HW_BIOTAC_DIR"),
                   help="BioTac_slide_20_50 folder (default $SPLL_HW_BIOTAC_DIR)")  # fmt: skip
    p.add_argument("--jobs", type=int, default=1, help="exports at once")
    p.add_argument("--json", type=Path, help="append one JSON line per export here")
    args = p.parse_args()
    names = args.presets.split(",") if args.presets else presets.names()
    jobs = [(name, target) for name in names for target in args.targets.split(",")]

    def one(job):
        name, target = job
        data = args.data if name.startswith("biotac") else None
        row = measure(name, target, data)
        if args.json:
            with args.json.open("a") as f:
                f.write(json.dumps(row) + "\n")
        print(f"{name} {target}: {row}", file=sys.stderr, flush=True)
        return row

    with ThreadPoolExecutor(args.jobs) as pool:
        rows = list(pool.map(one, jobs))
    print(markdown(rows))


if __name__ == "__main__":
    main()
