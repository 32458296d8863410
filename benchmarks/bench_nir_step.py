"""nir-standard's time step per consumer: the error against golden at the file's own step, and
what each consumer does when given another.

For each network (the default one and a tuned preset) and step, the network is built as
``spll-hw export --to nir-standard --dt STEP`` builds it (16 gate levels), run on Poisson trains
by the numpy executor, Norse and snnTorch (each at the file's step, loaded as the folder's
``load_consumer.py`` loads it) and compared with golden (TDE-rate error,
:func:`spll_hw.harness.metrics.rate_error`). Then Norse is given other steps (half, twice, its
own default of 1 ms) as a user who ignores the file's would: the graph's step guard
(:mod:`mappings.nir.step_guard`) makes every output spike in every step and
``load_consumer.run`` raises; ``load_consumer.load`` refuses the wrong step before that; and
snnTorch, which steps by 100 µs only, is refused by the folder's table for another step.

    PYTHONPATH=. python benchmarks/bench_nir_step.py --json benchmarks/results/nir_step.json

Needs ``nir``; Norse and snnTorch need torch (a consumer that is not installed is reported as
such). Docs: docs/notes/2026-12-06-nir-step.md.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mappings.nir.consumers import run_consumer, support  # noqa: E402
from mappings.nir.executor import input_steps  # noqa: E402
from mappings.nir.loader import StepGuardTripped, guard_check, load_module, step_module  # noqa: E402,E501
from mappings.nir.standard import EXPORT_LEVELS, to_standard_nir  # noqa: E402
from spll_hw import simulate_batch  # noqa: E402
from spll_hw.config import NetworkConfig  # noqa: E402
from spll_hw.construction.gate import GateOptions  # noqa: E402
from spll_hw.harness.metrics import rate_error  # noqa: E402

#: Networks: the export's default network (spll-hw's --network default) and a tuned preset
#: (issue 59's 50-µs one).
NETWORKS = ("vibtac-vary-offset-lif", "biotac-tuned-time-scaled-lif")
#: Steps [s] each network is written for.
STEPS = (1e-4, 5e-5)


def _trains(samples: int, duration: float, rate: float, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [np.sort(rng.uniform(0, duration, rng.poisson(rate * duration))) for _ in range(samples)]


def _installed(consumer: str) -> bool:
    return consumer == "numpy" or importlib.util.find_spec(consumer) is not None


def _wrong_step(graph, dt_wrong: float, train: np.ndarray, duration: float):
    """Norse given ``dt_wrong`` [s] (the input binned by it): what ``load_consumer.run`` says
    of the run, and the share of steps in which every output spiked."""
    out = step_module(
        load_module("norse", graph, dt_wrong), input_steps(train, duration, dt_wrong)[:, None]
    )
    try:
        guard_check(out, dt_wrong)
        outcome = "ran without error"
    except StepGuardTripped as exc:
        outcome = f"StepGuardTripped: {exc}"
    return outcome, float(np.all(out > 0, axis=2).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2, help="Poisson samples (default 2)")
    parser.add_argument("--duration", type=float, default=1.0, help="run length [s] (default 1)")
    parser.add_argument("--rate", type=float, default=300.0, help="input rate [Hz] (default 300)")
    parser.add_argument("--networks", default=",".join(NETWORKS), help="comma-separated")
    parser.add_argument("--json", type=Path, help="write the numbers here")
    args = parser.parse_args()
    trains = _trains(args.samples, args.duration, args.rate)
    rows, wrong = [], []
    for name in args.networks.split(","):
        network = NetworkConfig.preset(name).build()
        golden = simulate_batch(network, trains, args.duration)
        for dt in STEPS:
            graph = to_standard_nir(network, GateOptions(EXPORT_LEVELS), dt=dt).graph
            table = support(dt)
            for consumer in ("numpy", "norse", "snntorch"):
                row = {"network": name, "dt": dt, "consumer": consumer}
                if not _installed(consumer):
                    row["outcome"] = "not installed"
                elif not table.get(consumer, "runs it").startswith("runs it"):
                    row["outcome"] = f"refused by standard.json: {consumer} {table[consumer]}"
                else:
                    start = time.perf_counter()
                    res = run_consumer(consumer, graph, trains, args.duration)
                    errors = [rate_error(r, g) for r, g in zip(res, golden, strict=True)]
                    row |= {"tde_rate_error": float(np.mean(errors)),
                            "wall_s": time.perf_counter() - start}  # fmt: skip
                rows.append(row)
                print(json.dumps(row), flush=True)
            if _installed("norse"):
                for dt_wrong in (dt / 2, 2 * dt, 1e-3):
                    outcome, every = _wrong_step(graph, dt_wrong, trains[0], 0.2)
                    entry = {"network": name, "dt": dt, "norse_dt": dt_wrong,
                             "outcome": outcome, "steps_with_every_output": every}  # fmt: skip
                    wrong.append(entry)
                    print(json.dumps(entry), flush=True)
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"runs": rows, "wrong_step": wrong}, indent=1) + "\n")


if __name__ == "__main__":
    main()
