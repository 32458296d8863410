"""How far golden is from itself: the export check's error between golden and golden on inputs
moved by amounts no clocked target could be blamed for.

An export's check (:func:`spll_hw.exporters.check.check_run`) compares the counts of one run of
each reference input against golden's. On a network whose TDE counts hang on the exact phase
between its inputs and its CCOs, one run is a sample: golden itself, on the same input moved a
little, is that far off. This runs the check with golden in the export's place on each
preset's reference inputs (:func:`~spll_hw.exporters.check.reference_inputs`) moved by:

* ``shift``: every spike ``--shift`` later (default 0.5 ms, spikes past the end dropped: what
  every export's check reports as its resolution, ``CheckReport.resolution``);
* ``scale``: every spike time divided by 1.001 (the input's rate 0.1 % higher);
* ``jitter``: every spike moved by up to ``--jitter`` (default 5 µs) either way, at random.

Each cell is the check's own total TDE-rate error (mean over the inputs of
``sum |c - c_golden| / sum c_golden``), the metric the export's limit judges::

    python benchmarks/bench_golden_sensitivity.py --durations 1,10 \\
        --json benchmarks/results/golden_sensitivity.json \\
        --markdown benchmarks/results/golden_sensitivity.md     # ~40 s on 2 cores
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spll_hw.exporters.check_inputs import shifted  # noqa: E402

#: The perturbations, in the table's order.
MOVES = ("shift", "scale", "jitter")
#: The time scaling of ``scale``.
SCALE = 1.001


def moved(train: np.ndarray, how: str, duration: float, shift: float, jitter: float,
          rng: np.random.Generator) -> np.ndarray:  # fmt: skip
    """``train`` (sorted spike times [s]) moved as ``how`` (one of :data:`MOVES`) says, sorted,
    within ``[0, duration]``."""
    if how == "shift":
        return shifted(train, shift, duration)  # the check's own resolution at 0.5 ms
    if how == "scale":
        out = train / SCALE
    else:
        out = train + rng.uniform(-jitter, jitter, train.shape)
    return np.sort(out[(out >= 0) & (out <= duration)])


def measure(preset: str, duration: float, shift: float, jitter: float) -> dict:
    """One row: the check's TDE-rate error of golden on each move of ``preset``'s reference
    inputs of ``duration`` [s] against golden on the inputs themselves."""
    from spll_hw.backends import get
    from spll_hw.config import NetworkConfig
    from spll_hw.exporters import FolderRun
    from spll_hw.exporters.check import check_run

    start = time.perf_counter()
    net = NetworkConfig.preset(preset).build()
    golden = get("golden")
    row = {"preset": preset, "duration": duration, "shift": shift, "jitter": jitter}
    for how in MOVES:
        rng = np.random.default_rng(0)

        def simulate(trains, length, how=how, rng=rng):
            trains = [moved(np.asarray(x, float), how, length, shift, jitter, rng) for x in trains]
            return golden.simulate_batch(net, trains, length)

        report = check_run(FolderRun(how, golden, simulate), "golden", net, duration=duration)
        row[how] = report.tde_error
        row[f"{how}_per_input"] = [x["tde_rate_error"] for x in report.inputs]
    row["seconds"] = time.perf_counter() - start
    print(f"{preset} {duration:g} s: " + ", ".join(f"{how} {100 * row[how]:.1f} %"
                                                   for how in MOVES),
          file=sys.stderr, flush=True)  # fmt: skip
    return row


def markdown(rows: list[dict]) -> str:
    """The rows as the docs' table: one row per preset, one column per move and duration."""
    durations = sorted({r["duration"] for r in rows})
    head = [f"{how} ({d:g} s)" for d in durations for how in MOVES]
    lines = ["| preset | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for preset in dict.fromkeys(r["preset"] for r in rows):
        cells = []
        for d in durations:
            row = next(r for r in rows if r["preset"] == preset and r["duration"] == d)
            cells += [f"{100 * row[how]:.1f} %" for how in MOVES]
        lines.append(f"| `{preset}` | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def names_of(kind: str, known: Callable[[], Sequence[str]]) -> Callable[[str], list[str]]:
    """An ``argparse`` type: comma-separated names, each one of ``known()`` (``kind`` names
    them in the error)."""

    def parse(text: str) -> list[str]:
        names = text.split(",")
        unknown = sorted(set(names) - set(known()))
        if unknown:
            raise argparse.ArgumentTypeError(
                f"no {kind} {', '.join(unknown)}; choose from {', '.join(known())}"
            )
        return names

    return parse


def _presets() -> list[str]:
    from spll_hw import presets

    return presets.names()


#: ``--presets``: comma-separated names of shipped presets.
preset_names = names_of("preset", _presets)


def numbers_of(
    convert: Callable[[str], float], valid: Callable[[float], bool], what: str
) -> Callable[[str], list]:
    """An ``argparse`` type: comma-separated numbers, each read by ``convert`` and ``valid``
    (``what`` names them in the error)."""

    def parse(text: str) -> list:
        try:
            out = [convert(x) for x in text.split(",")]
        except ValueError:
            out = []
        if not out or not all(valid(x) for x in out):
            raise argparse.ArgumentTypeError(f"{text!r} is not a comma-separated list of {what}")
        return out

    return parse


#: ``--durations``: comma-separated input lengths [s], each > 0.
durations = numbers_of(float, lambda d: d > 0, "seconds > 0")


def seconds(text: str) -> float:
    """``--shift``, ``--jitter``: a time [s], >= 0."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a time in seconds >= 0")
    return value


def report(rows: list[dict], table: str, json_path: Path | None, markdown_path: Path | None):
    """Print ``table`` (the rows as Markdown) and write the rows as JSON to ``json_path`` and
    the table to ``markdown_path``, each where given."""
    print(table)
    for path, text in ((json_path, json.dumps(rows, indent=1) + "\n"), (markdown_path, table)):
        if path:
            path.write_text(text)


def main(argv: list[str] | None = None) -> int:
    from spll_hw import presets

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--presets", type=preset_names, help="comma-separated presets (default: every preset)"
    )
    parser.add_argument(
        "--durations",
        type=durations,
        default=[1.0],
        help="comma-separated input lengths [s] (default 1, the check's)",
    )
    parser.add_argument("--shift", type=seconds, default=5e-4, help="the shift [s] (default 5e-4)")
    parser.add_argument(
        "--jitter",
        type=seconds,
        default=5e-6,
        help="the largest jitter [s] either way (default 5e-6)",
    )
    parser.add_argument("--json", type=Path, help="write the rows here")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    args = parser.parse_args(argv)
    names = args.presets or presets.names()
    rows = [measure(p, d, args.shift, args.jitter) for p in names for d in args.durations]
    report(rows, markdown(rows), args.json, args.markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
