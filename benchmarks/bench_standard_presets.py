"""The standard construction on every shipped preset: TDE-rate error of its exports.

For every preset (``spll_hw/presets/*.toml``), each clocked export of the standard-neuron sPLL
(``nir-standard`` through its numpy executor ``nir-numpy``, ``lava-standard`` through its
bit-accurate numpy reference ``standard-fixed-point``; each is bit-identical to its export) runs
at the target's default time step and a finer one, on two inputs of 1 s:

* ``poisson``: 300 Hz Poisson (seed 0), the rate the gate levels are placed for;
* ``biotac``: the first 1 s of recording 1 of two BioTac materials (``--materials``), encoded by
  the preset's encoder (its ``[encoder]`` table, else the encoder its name ends in with default
  settings); the larger error of the two samples is reported.

The error is ``spll_hw.harness.metrics.rate_error`` against golden on the same train. The
declared tolerances of the construction's clocked backends (``mappings/nir/standard_backend.py``,
``mappings/lava/standard_backend.py``) come from this table.

    python benchmarks/bench_standard_presets.py \\
        --json benchmarks/results/standard_presets.json \\
        --markdown benchmarks/results/standard_presets.md      # ~15 min on one core
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mappings.lava.standard_backend import StandardFixedPoint  # noqa: E402
from mappings.nir.standard_backend import NirNumpy  # noqa: E402
from spll_hw import presets, simulate_batch  # noqa: E402
from spll_hw.config import NetworkConfig, read_encoder_table  # noqa: E402
from spll_hw.datasets.biotac import load_biotac  # noqa: E402
from spll_hw.encoders import make_encoder  # noqa: E402
from spll_hw.harness.metrics import rate_error  # noqa: E402

#: Run length [s] of every input.
DURATION = 1.0
#: Poisson rate [Hz].
RATE = 300.0
#: (export, backend class, time steps [s]: the target's default first).
TARGETS = (
    ("nir-standard", NirNumpy, (1e-4, 2e-5)),
    ("lava-standard", StandardFixedPoint, (5e-5, 1e-5)),
)
DATASET = Path(__file__).resolve().parent.parent.parent / "shared/datasets/biotac_slide_20_50"


def encoder_of(name: str):
    """The preset's encoder: its ``[encoder]`` table, else the one its name ends in."""
    table = read_encoder_table(name)
    if table is not None:
        return make_encoder(table[0], **table[1])
    return make_encoder(name.rsplit("-", 1)[1])


def inputs(name: str, biotac) -> dict[str, list[np.ndarray]]:
    """The input trains of preset ``name``: one Poisson train and the BioTac samples."""
    rng = np.random.default_rng(0)
    poisson = np.sort(rng.uniform(0.0, DURATION, rng.poisson(RATE * DURATION)))
    trains = encoder_of(name).encode(biotac.signals, biotac.fs)
    return {"poisson": [poisson], "biotac": [np.asarray(x)[np.asarray(x) <= DURATION]
                                             for x in trains]}  # fmt: skip


def measure(name: str, biotac, targets) -> list[dict]:
    """Rows ``{preset, target, dt, input, error, ...}`` of one preset."""
    net = NetworkConfig.preset(name).build()
    rows = []
    for kind, trains in inputs(name, biotac).items():
        golden = simulate_batch(net, trains, DURATION)
        for target, backend, dts in targets:
            for dt in dts:
                start = time.perf_counter()
                try:
                    res = backend(dt=dt).simulate_batch(net, trains, DURATION)
                except ValueError as exc:  # a network the target cannot represent at dt
                    rows.append({"preset": name, "target": target, "dt": dt, "input": kind,
                                 "error": None, "refused": str(exc)})  # fmt: skip
                    continue
                errors = [rate_error(r, g) for r, g in zip(res, golden, strict=True)]
                rows.append({
                    "preset": name, "target": target, "dt": dt, "input": kind,
                    "error": float(np.max(errors)), "errors": [float(e) for e in errors],
                    "golden_tde_rate": float(np.mean([g.tde_counts.sum() for g in golden])),
                    "wall_s": time.perf_counter() - start,
                })  # fmt: skip
                print(f"{name:36s} {target:14s} dt={dt:g} {kind:8s} "
                      f"error {100 * rows[-1]['error']:6.2f} %", flush=True)  # fmt: skip
    return rows


def markdown(rows: list[dict], targets) -> str:
    """The table: one row per preset, one column per target x dt x input."""
    cols = [(t, dt, kind) for t, _, dts in targets for dt in dts for kind in ("poisson", "biotac")]
    head = [f"{t} {dt * 1e6:g} µs {kind}" for t, dt, kind in cols]
    lines = ["| preset | " + " | ".join(head) + " |", "|---" * (len(cols) + 1) + "|"]
    cell = {(r["preset"], r["target"], r["dt"], r["input"]): r for r in rows}
    for name in dict.fromkeys(r["preset"] for r in rows):
        values = []
        for t, dt, kind in cols:
            r = cell.get((name, t, dt, kind))
            values.append("-" if r is None else "refused" if r["error"] is None
                          else f"{100 * r['error']:.1f} %")  # fmt: skip
        lines.append(f"| {name} | " + " | ".join(values) + " |")
    worst = {t: max(r["error"] for r in rows if r["target"] == t and r["error"] is not None)
             for t, _, _ in targets}  # fmt: skip
    lines.append("")
    lines.append("Largest error: " + ", ".join(f"{t} {100 * e:.1f} %" for t, e in worst.items()))
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presets", default="", help="comma-separated (default: all)")
    parser.add_argument("--materials", default="mat1,mat2", help="BioTac materials, one sample "
                        "(recording 1, first second) each")  # fmt: skip
    parser.add_argument("--targets", default="nir-standard,lava-standard", help="exports")
    parser.add_argument("--dataset", type=Path, default=DATASET, help="BioTac dataset folder")
    parser.add_argument("--json", type=Path, help="write the rows here")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    args = parser.parse_args()
    names = args.presets.split(",") if args.presets else presets.names()
    classes = args.materials.split(",")
    biotac = load_biotac(args.dataset, classes=classes, recordings=[1])
    first = [int(np.flatnonzero(biotac.labels == c)[0]) for c in range(len(classes))]
    biotac = type(biotac)(biotac.signals[first], biotac.fs, biotac.labels[first],
                          biotac.class_names, tuple(biotac.sources[i] for i in first))  # fmt: skip
    targets = [t for t in TARGETS if t[0] in args.targets.split(",")]
    rows = [row for name in names for row in measure(name, biotac, targets)]
    table = markdown(rows, targets)
    print(table)
    if args.markdown:
        args.markdown.write_text(table)
    if args.json:
        meta = {"duration_s": DURATION, "poisson_rate_hz": RATE, "biotac": list(biotac.sources)}
        args.json.write_text(json.dumps({**meta, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
