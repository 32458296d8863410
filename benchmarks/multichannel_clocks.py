"""The BioTac multichannel network on Loihi 2 with a clock per channel group: the step each group
tolerates, and the energy per classification it saves (issue 58; docs/multichannel.md, "Separate
clocks").

No single step writes the whole preset in Loihi 2's integers (:mod:`spll_hw.multichannel.clocks`):
``pac``'s network only at 40–80 µs, the row channels' only at 320 µs–1.28 ms; at the profile's own
10 µs both are clamped. Each candidate runs ``pac`` and the 22 row channels on chips of their own,
each at its own step, in the chip's integer arithmetic (``golden-fixed-point:profile=loihi2@STEP``),
beside the exact network (``golden``) and today's single 10-µs clock. Stages:

- ``steps``: the steps of the doubling ladder 10 µs-2.56 ms at which each group can be written.
- ``choose``: every candidate trained on recordings 1-24, scored on 25-32 (20 materials and the
  thesis's 11, at 0.5, 1, 2 and 4 s), with its paired change against golden and its dynamic energy
  per 4-s classification ([low, high] over the figures' ranges; recording 1 of every material,
  as ``spll-hw chips --multichannel``). The rule: the least energy among the candidates whose
  paired change at 4 s on the 20 materials has a 95 % interval that holds 0.
- ``test PAC ROWS``: the chosen steps, trained on 1-32 and scored once on 33-40, against golden
  and against today's 10-µs clock (paired), with its energy.

Run from the repository root::

    nice -n 15 python benchmarks/multichannel_clocks.py ../shared/datasets/biotac_slide_20_50 steps
    nice -n 15 python benchmarks/multichannel_clocks.py ../shared/datasets/biotac_slide_20_50 \\
        choose --jobs 2
    nice -n 15 python benchmarks/multichannel_clocks.py ../shared/datasets/biotac_slide_20_50 \\
        test 80us 640us --jobs 2
"""

from __future__ import annotations

import argparse
import time

from quantize import load_profile
from quantize.steps import ladder
from spll_hw.cli.jobs.slide import class_sets
from spll_hw.cli.slide import DEFAULT_NETWORK
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.datasets.recordings import split_recordings
from spll_hw.multichannel.chips import ClockedCost, classification_cost, clocks
from spll_hw.multichannel.clocks import GROUP_LADDER, group_label, with_group_backends
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.features import input_levels
from spll_hw.multichannel.report import change_table, markdown_table
from spll_hw.multichannel.timecourse import accuracy_over_time
from spll_hw.timestep import parse_step, step_label

PROFILE = "loihi2"
CHIP = f"golden-fixed-point:profile={PROFILE}"
WINDOWS = (0.5, 1.0, 2.0, 4.0)
#: Candidate steps [s] of each group (those of :data:`GROUP_LADDER` that write it).
PAC_STEPS = (40e-6, 80e-6)
ROW_STEPS = (320e-6, 640e-6, 1.28e-3)
GOLDEN = "golden"
TODAY = "one 10us clock"


def label(pac: float, rows: float) -> str:
    return f"pac@{step_label(pac)} + rows@{step_label(rows)}"


def candidates(preset: MultichannelConfig, pairs) -> dict[str, MultichannelConfig]:
    """Label -> the preset with ``pac`` (group 0) and the rows (group 1) on their own clocks,
    plus golden and today's single 10-µs clock."""
    out = {GOLDEN: with_group_backends(preset, "golden", {}),
           TODAY: with_group_backends(preset, CHIP, {})}  # fmt: skip
    for pac, rows in pairs:
        out[label(pac, rows)] = with_group_backends(preset, CHIP, {0: pac, 1: rows})
    return out


def steps_table(preset: MultichannelConfig) -> str:
    profile = load_profile(PROFILE)
    rows = ["| group | " + " | ".join(step_label(s) for s in GROUP_LADDER) + " |",
            "|---|" + "---|" * len(GROUP_LADDER)]  # fmt: skip
    for group in preset.groups:
        checks = ladder(group.network.build(), profile, GROUP_LADDER)
        rows.append(f"| {group_label(group)} | "
                    + " | ".join("yes" if c.works else "no" for c in checks) + " |")  # fmt: skip
    return "\n".join(rows)


def energy(root, preset: MultichannelConfig, pairs, window: float = 4.0) -> dict:
    """Label -> the cost of one classification (recording 1 of every material) of today's
    single clock and of each pair's two clocks."""
    samples = load_biotac_channels(root, preset.channels, "all", [1], window).openings()
    levels = input_levels(preset, samples)
    out = {TODAY: classification_cost(preset, PROFILE, samples, levels, window)}
    for pac, rows in pairs:
        parts = clocks(preset, PROFILE, {0: pac, 1: rows})
        out[label(pac, rows)] = ClockedCost(tuple(
            classification_cost(c.config, c.profile, samples, levels, window) for c in parts
        ))  # fmt: skip
    return out


def energy_table(costs: dict) -> str:
    """Dynamic energy per classification [low, high] of each, and how much less than today."""
    lines = ["| candidate | dynamic energy / classification | [low, high] | vs today |",
             "|---|---:|---:|---:|"]  # fmt: skip
    return "\n".join(lines + [_energy_row(k, c, costs[TODAY]) for k, c in costs.items()])


def chosen(points, costs: dict) -> str:
    """The rule of the module docstring: the least energy among the candidates whose paired
    change against golden at 4 s on the 20 materials has a 95 % interval that holds 0."""
    at = {(p.network, p.classes, p.window): p.result for p in points}
    ties = []
    for name in costs:
        if name == TODAY:
            continue
        change = at[name, "all 20", 4.0].change_against(at[GOLDEN, "all 20", 4.0])
        if change.low <= 0 <= change.high:
            ties.append(name)
    if not ties:
        return "none ties golden at 4 s"
    return min(ties, key=lambda k: costs[k].dynamic_energy)


def _energy_row(name, cost, today) -> str:
    span, base = cost.dynamic_range, today.dynamic_range
    return (
        f"| {name} | {cost.dynamic_energy * 1e3:.3g} mJ | [{span.low * 1e3:.3g}, "
        f"{span.high * 1e3:.3g}] mJ | {today.dynamic_energy / cost.dynamic_energy:.3g}x "
        f"[{base.low / span.low:.3g}x at low, {base.high / span.high:.3g}x at high] |"
    )


def accuracy(root, configs, train_numbers, test_numbers, jobs):
    preset = next(iter(configs.values()))
    loaded = load_biotac_channels(
        root, preset.channels, "all", [*train_numbers, *test_numbers], max(WINDOWS)
    ).openings()
    train, test = split_recordings(loaded, list(test_numbers), "held-out recordings")
    return accuracy_over_time(train, test, configs, class_sets(), WINDOWS, jobs=jobs, progress=True)


def report(points, names, against) -> None:
    print(markdown_table(points))
    for name in names:
        if name != against:
            print(f"{name} minus {against}, accuracy points [95 % CI, paired bootstrap over "
                  "test recordings]:\n")  # fmt: skip
            print(change_table(points, name, against))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("data")
    p.add_argument("stage", choices=("steps", "choose", "test"))
    p.add_argument("steps", nargs="*", help="stage test: the pac step and the rows' step")
    p.add_argument("--jobs", type=int, default=2)
    args = p.parse_args()
    start = time.perf_counter()
    preset = MultichannelConfig.load(DEFAULT_NETWORK)
    print(steps_table(preset) + "\n")
    if args.stage == "choose":
        pairs = [(a, b) for a in PAC_STEPS for b in ROW_STEPS]
        configs = candidates(preset, pairs)
        points = accuracy(args.data, configs, range(1, 25), range(25, 33), args.jobs)
        print("Trained on 1-24, scored on 25-32:\n")
        report(points, configs, GOLDEN)
        costs = energy(args.data, preset, pairs)
        print(energy_table(costs) + "\n")
        print(f"Chosen (least energy of those that tie golden at 4 s): {chosen(points, costs)}")
    elif args.stage == "test":
        if len(args.steps) != 2:
            raise SystemExit("test: give the pac step and the rows' step, e.g. 80us 640us")
        pair = (parse_step(args.steps[0]), parse_step(args.steps[1]))
        configs = candidates(preset, [pair])
        points = accuracy(args.data, configs, range(1, 33), range(33, 41), args.jobs)
        print("Trained on 1-32, scored once on 33-40:\n")
        report(points, configs, GOLDEN)
        print(f"{label(*pair)} minus {TODAY}:\n")
        print(change_table(points, label(*pair), TODAY))
        print(energy_table(energy(args.data, preset, [pair])) + "\n")
    print(f"{time.perf_counter() - start:.0f} s wall")


if __name__ == "__main__":
    main()
