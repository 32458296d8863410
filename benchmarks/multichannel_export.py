"""The multichannel network and its spiking readout on the chip's terms (issues 59 and 60): the
``nir-standard`` export of ``spll-hw export --network MULTICHANNEL --readout FILE``, run on
held-out recordings 33-40 (20 materials, the opening 4 s of each recording) by spll-hw's numpy
executor, against the golden engine's exact decisions, and by a NIR consumer outside spll-hw
through the folder's own ``run_multichannel.py``.

Stages (from the repository root, the data in ``SPLL_HW_BIOTAC_DIR``)::

    spll-hw slide --network biotac-multichannel-lif --train-recordings 1-32 \\
        --holdout-recordings 33-40 --windows 4 --readout --readout-train staged \\
        --readout-bits 8 --jobs 2 --out reports/slide-staged
    spll-hw export --network biotac-multichannel-lif --to nir-standard \\
        --readout reports/slide-staged/readouts/all20-8-bit.npz --threshold 0.75 \\
        --data $SPLL_HW_BIOTAC_DIR --out reports/multichannel-export/folder
    python3 benchmarks/multichannel_export.py heldout --export reports/multichannel-export/folder \\
        --out reports/multichannel-export
    python3 benchmarks/multichannel_export.py subset --recording 33
    # a venv with torch, Norse 1.1 and nir (no spll-hw):
    VENV/bin/python reports/multichannel-export/folder/run_multichannel.py norse \\
        reports/multichannel-export/consumer_inputs.npz \\
        reports/multichannel-export/consumer_decisions.json

``heldout`` writes ``heldout_inputs.npz`` (every channel's encoded spikes, as the readout sees
them), ``heldout_decisions.json`` (the executor's and golden's decision of every recording, in
``decisions.json``'s format), ``heldout_costs.json`` (the exported network's cost per decision
on a chip, :mod:`mappings.nir.multichannel_cost`, one entry per chunk of recordings) and
``summary.md``: accuracy of both with 95 % intervals (bootstrap over recordings), their paired
difference, the mean time to decision, how many decisions are the same, and the energy per
decision.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mappings.nir import multichannel_standard as mcs  # noqa: E402
from mappings.nir.multichannel_cost import decision_costs  # noqa: E402
from spll_hw.datasets.biotac_channels import load_biotac_channels  # noqa: E402
from spll_hw.multichannel.config import MultichannelConfig  # noqa: E402
from spll_hw.multichannel.readout import causal_trains  # noqa: E402
from spll_hw.stats import bootstrap_ci  # noqa: E402

HELDOUT = range(33, 41)
DURATION = 4.0
#: Recordings the executor runs side by side in one worker (memory: a few GB).
CHUNK = 20


def heldout(args: argparse.Namespace) -> None:
    folder, out = Path(args.export), Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    config = MultichannelConfig.load(folder / "multichannel.toml")
    manifest = json.loads((folder / mcs.MANIFEST).read_text())
    saved, threshold = mcs.folder_readout(folder)
    levels = dict(zip(saved.channels, map(float, saved.levels), strict=True))
    recordings = [int(r) for r in args.recordings.split(",")]
    if not set(recordings) <= set(HELDOUT):
        raise SystemExit(f"--recordings {args.recordings}: held-out recordings are 33-40")
    samples = load_biotac_channels(args.data, config.channels, "all", recordings, DURATION)
    samples = samples.openings()
    n = len(samples)
    trains = {c: causal_trains(samples, g, c, levels[c], args.jobs)
              for g in config.groups for c in g.channels}  # fmt: skip
    t0 = time.perf_counter()
    chunks = [range(a, min(a + CHUNK, n)) for a in range(0, n, CHUNK)]
    tasks = [(folder, config, manifest, {c: [t[r] for r in rows] for c, t in trains.items()},
              len(rows)) for rows in chunks]  # fmt: skip
    with ProcessPoolExecutor(args.jobs) as pool:
        done = list(pool.map(_decided, tasks))
    mine = [d for made, _ in done for d in made]
    executor_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    golden = mcs.golden_decisions(samples, config, saved, threshold, levels, DURATION)
    golden_s = time.perf_counter() - t0
    dt = manifest["readout"]["dt"]
    records = mcs.decision_records(samples, saved.readout.class_names, mine, golden, dt)
    costs = [decision_costs(parts, records[rows.start : rows.stop], DURATION)
             for (_, parts), rows in zip(done, chunks, strict=True)]  # fmt: skip
    np.savez(out / "heldout_inputs.npz", **mcs.input_arrays(trains, n, DURATION))
    (out / "heldout_decisions.json").write_text(json.dumps({
        "duration_s": DURATION, "dt": dt, "threshold": threshold,
        "recordings": f"{args.recordings} of every material",
        "decisions": records,
    }, indent=1))  # fmt: skip
    (out / "heldout_costs.json").write_text(json.dumps(costs, indent=1))
    (out / "summary.md").write_text(summary(records, samples.recordings, executor_s, golden_s,
                                            folder, threshold, costs))  # fmt: skip
    print((out / "summary.md").read_text())


def _decided(task) -> tuple[list, list]:
    """The executor's decisions of one chunk of recordings (a worker's share) and its runs of
    every part, every neuron counted (:mod:`mappings.nir.multichannel_cost`)."""
    folder, config, manifest, trains, n = task
    parts = []
    made = mcs.executor_decisions(folder, config, manifest, trains, n, DURATION, parts)[0]
    return made, parts


def summary(records, recordings, executor_s, golden_s, folder, threshold, costs) -> str:
    right = {who: np.array([d[who]["class"] == d["class"] for d in records], float)
             for who in ("exported", "golden")}  # fmt: skip
    groups = np.asarray(recordings)
    rows = []
    for who, label in (("golden", "golden engine (exact)"), ("exported", "exported graphs")):
        ci = bootstrap_ci(right[who], groups)
        mean_t = np.mean([d[who]["time_s"] for d in records])
        fired = np.mean([d[who]["fired"] for d in records])
        rows.append(f"| {label} | {100 * right[who].mean():.1f} [{100 * ci.low:.1f}, "
                    f"{100 * ci.high:.1f}] | {mean_t:.2f} s | {100 * fired:.0f} % |")  # fmt: skip
    diff = bootstrap_ci(right["exported"] - right["golden"], groups)
    same = sum(d["exported"]["label"] == d["golden"]["label"] for d in records)
    apart = np.array([d["exported"]["time_s"] - d["golden"]["time_s"] for d in records
                      if d["exported"]["label"] == d["golden"]["label"]])  # fmt: skip
    change = 100 * (right["exported"].mean() - right["golden"].mean())
    lines = [
        f"# The exported multichannel network and readout on held-out recordings ({folder})",
        "",
        f"{len(records)} recordings (of 33-40, 20 materials, first {DURATION:g} s), threshold "
        f"{threshold:g} score·s; accuracy % [95 % CI, bootstrap over recordings].",
        "",
        "| decided by | accuracy | mean time to decision | fired |",
        "|---|---|---|---|",
        *rows,
        "",
        f"Exported minus golden: {change:+.1f} [{100 * diff.low:+.1f}, {100 * diff.high:+.1f}] "
        f"points (paired). The same class in {same} of {len(records)} recordings; where the "
        f"same, the exported decision is {1e3 * np.median(apart):+.1f} ms (median) after "
        f"golden's, within [{1e3 * np.min(apart):+.1f}, {1e3 * np.max(apart):+.1f}] ms.",
        "",
        f"Wall time: the executor {executor_s:.0f} s, golden {golden_s:.0f} s (2-core machine).",
        "",
        *_cost_lines(costs),
    ]
    return "\n".join(lines) + "\n"


def _cost_lines(costs: list[dict]) -> list[str]:
    """The exported network's cost per decision over every chunk's recordings."""
    runs = [d for c in costs for d in c["decisions"]]
    energy = np.array([[d["per_decision"]["value"], *d["per_decision"]["range"]] for d in runs])
    power = np.array([[d["dynamic_w"]["value"], *d["dynamic_w"]["range"]] for d in runs])
    value, low, high = energy.mean(axis=0)
    return [
        f"On {costs[0]['profile']} ({costs[0]['cores']} cores; `heldout_costs.json`): dynamic "
        f"power {power[:, 0].mean() * 1e3:.2f} mW [{power[:, 1].mean() * 1e3:.2f}, "
        f"{power[:, 2].mean() * 1e3:.2f}], energy per decision {value * 1e3:.2f} mJ "
        f"[{low * 1e3:.2f}, {high * 1e3:.2f}] (mean over the {len(runs)} recordings; the run's "
        "power times its time to decision; static power apart).",
    ]


def subset(args: argparse.Namespace) -> None:
    """``consumer_inputs.npz`` and ``consumer_decisions.json``: the held-out files cut to the
    recordings of number ``--recording`` (one per material), for a consumer run that would take
    hours on all 160 (Norse steps the pac group's 80 000 steps of 50 µs a run)."""
    out = Path(args.out)
    made = json.loads((out / "heldout_decisions.json").read_text())
    keep = [r for r, d in enumerate(made["decisions"])
            if d["recording"].split()[0].endswith(f"_{args.recording}_bio.csv")]  # fmt: skip
    with np.load(out / "heldout_inputs.npz") as data:
        arrays = {"duration": data["duration"]}
        for new, r in enumerate(keep):
            arrays |= {f"r{new}/{k.split('/')[1]}": data[k] for k in data.files
                       if k.startswith(f"r{r}/")}  # fmt: skip
    np.savez(out / "consumer_inputs.npz", **arrays)
    made["decisions"] = [made["decisions"][r] for r in keep]
    made["recordings"] = f"recording {args.recording} of every material"
    (out / "consumer_decisions.json").write_text(json.dumps(made, indent=1))
    print(f"{len(keep)} recordings: {out / 'consumer_inputs.npz'}, consumer_decisions.json")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="stage", required=True)
    h = sub.add_parser("heldout", help="decide recordings 33-40 (executor and golden)")
    h.add_argument("--export", required=True, help="the nir-standard multichannel export folder")
    h.add_argument("--out", default="reports/multichannel-export")
    data = os.environ.get("SPLL_HW_BIOTAC_DIR", "../shared/datasets/biotac_slide_20_50")
    h.add_argument("--data", default=data)
    h.add_argument("--jobs", type=int, default=2)
    every = ",".join(map(str, HELDOUT))
    h.add_argument("--recordings", default=every, help="held-out recording numbers, comma-"
                   "separated (every material's)")  # fmt: skip
    c = sub.add_parser("subset", help="cut heldout's files to one recording per material")
    c.add_argument("--out", default="reports/multichannel-export")
    c.add_argument("--recording", type=int, default=33)
    args = p.parse_args(argv)
    {"heldout": heldout, "subset": subset}[args.stage](args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
