"""Record the golden engine's calls of a real spll-hw run, then replay them on two engine builds.

A speed change measured on one workload can hide a regression on another: the lockstep engine
was 15 % faster on ``bench_engine.py`` and 1.5x slower on every network of the README demo.
This records each ``simulate`` / ``simulate_batch`` call that a CLI command makes (its arguments,
pickled: the README demo makes 1 331 calls, 180 MB), and replays all of them on two builds of
the engine, alternating A and B call by call, with the same thread count. It prints, per
network (parameter matrix) and duration, the time on each build, their ratio and whether the
outputs are identical (every array bit for bit; else whether the spike counts are).

    python benchmarks/replay_engine_calls.py record calls/ -- report --out /tmp/demo
    cp spll_hw/_engine*.so /tmp/a.so    # then rebuild the engine with the change
    python benchmarks/replay_engine_calls.py compare calls/ /tmp/a.so spll_hw/_engine*.so

``record`` runs ``spll-hw`` in this process with the engine wrapped; ``compare`` loads the two
shared libraries (``maturin develop``/``cargo build --release --features python`` output, any
path) side by side.
"""

from __future__ import annotations

import argparse
import collections
import hashlib
import importlib.util
import itertools
import pickle
import time
from pathlib import Path

import numpy as np

CALLS = ("simulate", "simulate_batch")


def record(folder: Path, cli_args: list[str]) -> int:
    """Run ``spll-hw cli_args`` with every engine call's arguments pickled into ``folder``."""
    from spll_hw import _engine
    from spll_hw.cli.main import main as cli_main

    folder.mkdir(parents=True, exist_ok=True)
    counter = itertools.count()

    def recorded(name: str):
        call = getattr(_engine, name)

        def wrapper(*args):
            out = call(*args)
            with open(folder / f"{next(counter):06d}.pkl", "wb") as f:
                pickle.dump((name, args), f)
            return out

        return wrapper

    for name in CALLS:
        setattr(_engine, name, recorded(name))
    return cli_main(cli_args)


def load_engine(path: Path):
    """The engine module in the shared library at ``path`` (two builds can be loaded at once)."""
    what = f"{path}: not an engine build (`cargo build --release --features python` makes one)"
    spec = importlib.util.spec_from_file_location("spll_hw._engine", path)
    if spec is None or spec.loader is None:
        raise SystemExit(what)
    try:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except ImportError as e:
        raise SystemExit(f"{what}: {e}") from None
    return module


def verdict(a: dict, b: dict) -> str:
    """``same`` if two engine outputs agree bit for bit; ``same counts`` if only times or
    states differ (in their last bits, say); else ``COUNTS DIFFER``."""
    if same(a, b):
        return "same"
    counts = [k for k in a if k.endswith("_counts")]
    return "same counts" if all(same(a[k], b[k]) for k in counts) else "COUNTS DIFFER"


def same(a, b) -> bool:
    """Whether two engine outputs (dicts, lists and arrays of them) are equal bit for bit."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return a.shape == b.shape and a.tobytes() == b.tobytes()
    return a == b


def timed(call, args: list) -> tuple[object, float]:
    """``call(*args)`` and its wall time [s]."""
    start = time.perf_counter()
    out = call(*args)
    return out, time.perf_counter() - start


def compare(folder: Path, engine_a: Path, engine_b: Path, threads: int | None) -> None:
    """Replay every call in ``folder`` on both builds and print a Markdown table per network."""
    files = sorted(folder.glob("*.pkl"))
    if not files:
        raise SystemExit(f"{folder}: no recorded calls (run `record` first)")
    a, b = load_engine(engine_a), load_engine(engine_b)
    empty = {"calls": 0, "samples": 0, "a": 0.0, "b": 0.0, "outputs": set()}
    rows = collections.defaultdict(lambda: {**empty, "outputs": set()})
    for path in files:
        with open(path, "rb") as f:
            name, args = pickle.load(f)
        args = list(args)
        if name == "simulate_batch" and threads is not None:
            args[4] = threads
        (out_a, seconds_a), (out_b, seconds_b) = (timed(getattr(e, name), args) for e in (a, b))
        key = (hashlib.sha1(args[0].tobytes()).hexdigest()[:8], args[0].shape[0], args[2])
        row = rows[key]
        row["calls"] += 1
        row["samples"] += len(args[1]) if name == "simulate_batch" else 1
        row["a"] += seconds_a
        row["b"] += seconds_b
        row["outputs"].add(verdict(out_a, out_b))
    print("| network | sPLLs | duration [s] | calls | samples | A [s] | B [s] | B/A | outputs |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (digest, n, duration), r in sorted(rows.items(), key=lambda kv: -kv[1]["a"]):
        outputs = ", ".join(sorted(r["outputs"]))
        print(f"| {digest} | {n} | {duration:g} | {r['calls']} | {r['samples']} | "
              f"{r['a']:.2f} | {r['b']:.2f} | {r['b'] / r['a']:.3f} | {outputs} |")  # fmt: skip
    total_a = sum(r["a"] for r in rows.values())
    total_b = sum(r["b"] for r in rows.values())
    ratio = total_b / total_a
    print(f"\nall {len(files)} calls: A {total_a:.1f} s, B {total_b:.1f} s, B/A {ratio:.3f}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="run spll-hw ARGS, pickling every engine call into FOLDER")
    rec.add_argument("folder", type=Path)
    rec.add_argument("cli", nargs=argparse.REMAINDER, help="-- then the spll-hw arguments")
    cmp = sub.add_parser("compare", help="replay FOLDER's calls on engine builds A and B")
    cmp.add_argument("folder", type=Path)
    cmp.add_argument("engine_a", type=Path, help="shared library of build A (the baseline)")
    cmp.add_argument("engine_b", type=Path, help="shared library of build B")
    cmp.add_argument("--threads", type=int, default=1,
                     help="threads of batch calls (default 1; 0: each call's own)")  # fmt: skip
    args = parser.parse_args()
    if args.command == "record":
        cli = args.cli[1:] if args.cli[:1] == ["--"] else args.cli
        return record(args.folder, cli)
    compare(args.folder, args.engine_a, args.engine_b, args.threads or None)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
