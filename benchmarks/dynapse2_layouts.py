"""Layouts of the BioTac multichannel network that fit one DYNAP-SE2, and what they cost in
accuracy (issue 35; docs/multichannel.md, "The whole network on the chips").

DYNAP-SE2 (``quantize/profiles/dynapse2.toml``) has 4 cores of 256 neurons and one bias set
per core: the TDEs share one core's set, every CCO offset needs a core of its own, so one chip
holds one sPLL circuit at 3 offsets. Each candidate is the preset's channels (or some of them),
every channel through copies of **one shared vary-offset network** (``grouped:1``: a base sPLL
scaled once, 3 offsets), each channel keeping its own encoder (on the host). Stages:

- ``fit``: every candidate (and two that must not fit) placed on ``dynapse2``
  (:func:`spll_hw.multichannel.chips.placement`): fits or why not.
- ``choose``: every fitting candidate trained on recordings 1-24 and scored on 25-32 as
  ``spll-hw slide`` decides (:func:`spll_hw.multichannel.timecourse.accuracy_over_time`), 20
  materials and the thesis's 11, at 2 s and 4 s, ideal and **as the chip realises it**
  (``golden:profile=dynapse2:chip_seed=0``: the 3 offset levels and the 10 % mismatch of time
  constants and gains; each channel's network is realised on its own, so every channel's copy
  has the same mismatch draw), and its dynamic energy and latency per classification
  (:func:`spll_hw.multichannel.chips.classification_cost`, recording 1 of every material).
- ``test NAME``: the chosen candidate, trained on 1-32 and scored once on 33-40, on the chip
  (mismatch draws 0, 1, 2) and ideal, beside the full preset (ideal), with the paired change.

Run from the repository root (``--jobs`` processes)::

    nice -n 15 python benchmarks/dynapse2_layouts.py ../shared/datasets/biotac_slide_20_50 fit
    nice -n 15 python benchmarks/dynapse2_layouts.py ../shared/datasets/biotac_slide_20_50 \\
        choose --jobs 2
    nice -n 15 python benchmarks/dynapse2_layouts.py ../shared/datasets/biotac_slide_20_50 \\
        test rows-circuit-2-45 --jobs 2 --write chosen.toml
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from spll_hw.cli.jobs.slide import class_sets
from spll_hw.cli.slide import DEFAULT_NETWORK, DEFAULT_SINGLE
from spll_hw.config import NetworkConfig
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.datasets.recordings import split_recordings
from spll_hw.multichannel.chips import classification_cost, placement
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels
from spll_hw.multichannel.report import change_table, markdown_table
from spll_hw.multichannel.timecourse import accuracy_over_time

PROFILE = "dynapse2"
WINDOWS = (2.0, 4.0)
IDEAL = "golden"
ROWS = [f"ele{i}" for i in range(1, 20)] + ["pdc", "tac", "tdc"]


def chip(seed: int) -> str:
    """The backend that simulates a network as DYNAP-SE2 realises it (mismatch draw ``seed``)."""
    return f"golden:profile={PROFILE}:chip_seed={seed}"


def shared(base: NetworkConfig, f_start: float, f_end: float, n: int = 3) -> NetworkConfig:
    """``base``'s sPLL (spread off) as one circuit at ``n`` offsets over ``f_start``-``f_end``
    [Hz], scaled once around its reference frequency."""
    return replace(base, layout="grouped:1", f_start=f_start, f_end=f_end, n=n, beta=1.0,
                   spread=0.0)  # fmt: skip


def candidates() -> dict[str, MultichannelConfig]:
    """Name -> candidate; the last one, ``pac`` on a circuit of its own, must not fit."""
    preset = MultichannelConfig.load(DEFAULT_NETWORK)
    rows_base = preset.groups[1].network
    pac_base = NetworkConfig.preset(DEFAULT_SINGLE)
    out = {
        "rows-circuit-2-45": preset.with_network(shared(rows_base, 2.0, 45.0)),
        "pac-circuit-2-45": preset.with_network(shared(pac_base, 2.0, 45.0)),
        "rows-circuit-0.5-20": preset.with_network(shared(rows_base, 0.5, 20.0)),
        "rows-only-2-45": preset.only(ROWS).with_network(shared(rows_base, 2.0, 45.0)),
        "pac-only-42-671": preset.only(["pac"]).with_network(shared(pac_base, 41.6, 671.0)),
    }
    two = preset.with_network(shared(rows_base, 2.0, 45.0))
    pac_own = replace(two.groups[0], network=shared(pac_base, 41.6, 671.0))
    out["two-circuits"] = replace(two, groups=(pac_own, *two.groups[1:]))
    return {k: replace(v, source=k) for k, v in out.items()}


def fit_table(configs: dict[str, MultichannelConfig]) -> tuple[str, list[str]]:
    """A Markdown row per candidate (channels, sPLLs, fits, cores, why not) and the names of
    those that fit."""
    rows = [
        "| candidate | channels | sPLLs | fits | cores | why not |",
        "|---|---:|---:|---|---:|---|",
    ]
    fitting = []
    for name, config in configs.items():
        fit = placement(config, PROFILE).fit
        fitting += [name] if fit.fits else []
        why = "; ".join(fit.problems) or "-"
        rows.append(f"| {name} | {len(config.channels)} | {config.n_spll} | "
                    f"{'yes' if fit.fits else 'no'} | {fit.cores} | {why} |")  # fmt: skip
    return "\n".join(rows), fitting


def accuracy(root, runs, train_numbers, test_numbers, jobs):
    """Points of every run ``(configs, backends)``: each config (label ``NAME (BACKEND)``) on
    each backend label -> spec, trained on ``train_numbers`` and scored on ``test_numbers``
    (the recordings read once)."""
    channels = list(dict.fromkeys(c for configs, _ in runs for v in configs.values()
                                  for c in v.channels))  # fmt: skip
    loaded = load_biotac_channels(
        root, channels, "all", [*train_numbers, *test_numbers], max(WINDOWS)
    ).openings()
    train, test = split_recordings(loaded, list(test_numbers), "held-out recordings")
    points = []
    for configs, backends in runs:
        for label, spec in backends.items():
            networks = {f"{name} ({label})": config for name, config in configs.items()}
            points += accuracy_over_time(train, test, networks, class_sets(), WINDOWS,
                                         backend=spec, jobs=jobs)  # fmt: skip
    return points


def energy_table(root, configs) -> str:
    """Dynamic energy and latency per classification on DYNAP-SE2, recording 1 of every
    material (as ``spll-hw chips --multichannel``)."""
    rows = ["| candidate | window | dynamic energy / classification | input spikes | "
            "static energy | latency |", "|---|---:|---:|---:|---:|---:|"]  # fmt: skip
    for name, config in configs.items():
        samples = load_biotac_channels(root, config.channels, "all", [1], max(WINDOWS)).openings()
        levels = input_levels(config, samples)
        for window in WINDOWS:
            cost = classification_cost(config, PROFILE, samples, levels, window, seed=0)
            rows.append(f"| {name} | {window:g} s | {cost.dynamic_energy * 1e6:.1f} uJ * | "
                        f"{cost.input_spikes:.0f} | {cost.static_energy * 1e3:.2f} mJ * | "
                        f"{cost.latency:g} s |")  # fmt: skip
    return "\n".join(rows)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("data")
    p.add_argument("stage", choices=("fit", "choose", "test"))
    p.add_argument("candidate", nargs="?", help="the chosen candidate (stage test)")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--write", help="stage test: write the chosen candidate's file here")
    args = p.parse_args()
    start = time.perf_counter()
    configs = candidates()
    table, fitting = fit_table(configs)
    print(table + "\n")
    if args.stage == "choose":
        chosen = {k: configs[k] for k in fitting}
        runs = [(chosen, {"chip": chip(0), "ideal": IDEAL})]
        points = accuracy(args.data, runs, range(1, 25), range(25, 33), args.jobs)
        print("Trained on 1-24, scored on 25-32:\n\n" + markdown_table(points))
        print(energy_table(args.data, chosen) + "\n")
    elif args.stage == "test":
        if args.candidate not in fitting:
            raise SystemExit(f"test: give a fitting candidate: {', '.join(fitting)}")
        config = configs[args.candidate]
        runs = [
            ({args.candidate: config}, {f"chip {k}": chip(k) for k in range(3)} | {"ideal": IDEAL}),
            ({"preset": MultichannelConfig.load(DEFAULT_NETWORK)}, {"ideal": IDEAL}),
        ]
        points = accuracy(args.data, runs, range(1, 33), range(33, 41), args.jobs)
        print("Trained on 1-32, scored once on 33-40:\n\n" + markdown_table(points))
        for label in ("chip 0", "ideal"):
            print(
                f"{args.candidate} ({label}) minus the preset, accuracy points [95 % CI, "
                "paired bootstrap over test recordings]:\n"
            )
            print(change_table(points, f"{args.candidate} ({label})", "preset (ideal)"))
        if args.write:
            with open(args.write, "w") as f:
                f.write(config.to_toml())
    print(f"{time.perf_counter() - start:.0f} s wall")


if __name__ == "__main__":
    main()
