"""Speed of the multichannel features behind ``spll-hw slide`` (issue 35): every channel of the
opening sample of every recording, encoded and run through its own sPLL network, at every
window, for the multichannel preset and the single-channel pipeline (whose ``pac`` part is the
same simulation, run once).

* ``old``: the path ``spll-hw slide`` took before: window by window, channel by channel,
  :func:`spll_hw.multichannel.features.channel_features` on all samples, each call starting its
  own pool of ``--jobs`` encoder processes, then the engine on ``--jobs`` threads;
* ``new``: :func:`spll_hw.multichannel.windows.features_over_windows`, every channel and window
  in one pool of ``--jobs`` processes, each task encoding and simulating a quarter of the
  samples (``--jobs 2``) of one channel at one window on one engine thread, the longest
  windows first.

``--path both`` runs the two and checks their features are equal, bit for bit. Windows are
not prefixes of one run (the LIF encoder removes each window's own mean; see
``spll_hw/multichannel/windows.py``), so the work itself is the same; what changes is how it
is spread over the cores. The engine releases the GIL while it simulates (``py.detach`` in
``engine/src/python.rs``), so its threads run beside the encoder processes either way.

Run from the repository root; the machine is shared, so the load average is printed beside
each timing::

    nice -n 15 python benchmarks/bench_multichannel.py ../shared/datasets/biotac_slide_20_50 \\
        --path both --jobs 2
    nice -n 15 python benchmarks/bench_multichannel.py ../shared/datasets/biotac_slide_20_50 \\
        --recordings 1-32 --windows 2 --single none      # one tuning trial's features

Results, 2026-11-27, the 2-core development machine shared with other jobs (CPU = user +
system of the process and its workers; load = 1-min load average at start and end, which
slows wall and CPU time alike: compare rows of one run only):

| run | recordings x windows | path | wall | CPU | load |
| --- | --- | --- | ---: | ---: | --- |
| ``spll-hw slide``, whole (``/usr/bin/time``) | 800 x 5 | old | 591 s | 316 s | 0.5 -> 6.0 |
| ``spll-hw slide``, whole (64-sample tasks) | 800 x 5 | new | 1126 s | 421 s | 5.1 -> 9.5 |
| ``--recordings 1-8 --path both`` | 160 x 5 | old | 177 s | 85 s | 4.3 -> 6.2 |
| the same process, right after | 160 x 5 | new | 249 s | 96 s | 6.2 -> 9.3 |
| a trial (T below), all 23 channels | 640 x 1 | new | 181 s | 66 s | 8.3 -> 8.8 |
| T, row channels only (R below) | 640 x 1 | new | 37 s | 14 s | 7.5 -> 7.8 |

T: ``--recordings 1-32 --windows 2 --single none``; R: T plus
``--channels electrodes,pdc,tac,tdc``.

No measurable gain from one pool: the ``pac`` network's simulation is ~85 % of the work and
already ran on both cores. A tuning trial of the row channels (``pac`` fixed and cached)
costs seconds; see docs/multichannel.md ("Speed").
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from spll_hw.cli.inputs import parse_ranges  # noqa: E402
from spll_hw.cli.jobs.slide import channel_list, windows  # noqa: E402
from spll_hw.cli.slide import DEFAULT_NETWORK, DEFAULT_SINGLE  # noqa: E402
from spll_hw.datasets.biotac_channels import load_biotac_channels  # noqa: E402
from spll_hw.multichannel.config import MultichannelConfig  # noqa: E402
from spll_hw.multichannel.features import channel_features, input_levels  # noqa: E402
from spll_hw.multichannel.windows import features_over_windows  # noqa: E402


def cpu_seconds() -> float:
    """User + system CPU time [s] of this process and its finished children."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def old_path(samples, units, times, jobs):
    """Features as ``spll-hw slide`` computed them before (module docstring)."""
    out = {}
    for w in sorted(times):
        part = samples.first(w)
        for channel, group, level in units:
            out[w, channel, group.key, level] = channel_features(
                part, channel, group, level, "golden", jobs
            )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", help="BioTac_slide_20_50 folder")
    parser.add_argument("--recordings", default="1-40", help="recording numbers (default 1-40)")
    parser.add_argument("--windows", default="0.25,0.5,1,2,4", help="decision times [s]")
    parser.add_argument("--network", default=DEFAULT_NETWORK, help="multichannel network")
    parser.add_argument("--channels", help="keep only these channels of --network (comma list)")
    parser.add_argument("--single", default=DEFAULT_SINGLE, help="pac network, or 'none'")
    parser.add_argument("--jobs", type=int, default=2, help="processes / threads (default 2)")
    parser.add_argument("--path", choices=("old", "new", "both"), default="new")
    args = parser.parse_args()

    networks = [MultichannelConfig.load(args.network)]
    if args.channels:
        networks = [networks[0].only(channel_list(args.channels))]
    if args.single != "none":
        networks.append(MultichannelConfig.single("pac", args.single))
    times = windows(args.windows)
    channels = list(dict.fromkeys(c for n in networks for c in n.channels))
    start = time.perf_counter()
    samples = load_biotac_channels(
        args.data, channels, "all", parse_ranges(args.recordings), max(times)
    ).openings()
    units = {}
    for config in networks:
        levels = input_levels(config, samples)
        for group in config.groups:
            for c in group.channels:
                units[c, group.key, levels[c]] = (c, group, levels[c])
    units = list(units.values())
    print(f"loaded {len(samples)} recordings x {len(channels)} channels in "
          f"{time.perf_counter() - start:.0f} s; {len(units)} channel networks, "
          f"{sum(g.network.n for _, g, _ in units)} sPLLs, windows {times}")  # fmt: skip
    results = {}
    for path in ("old", "new") if args.path == "both" else (args.path,):
        load0, cpu0, wall0 = os.getloadavg()[0], cpu_seconds(), time.perf_counter()
        if path == "old":
            results[path] = old_path(samples, units, times, args.jobs)
        else:
            results[path] = features_over_windows(samples, units, times, "golden", args.jobs)
        wall, cpu = time.perf_counter() - wall0, cpu_seconds() - cpu0
        load = f"{load0:.1f} -> {os.getloadavg()[0]:.1f}"
        print(f"| {time.strftime('%Y-%m-%d')} | {len(samples)} x {len(times)} | {path} "
              f"| {wall:.0f} s | {cpu:.0f} s | {load} |")  # fmt: skip
    if len(results) == 2:
        same = all(np.array_equal(results["old"][k], results["new"][k]) for k in results["old"])
        print("old and new features equal bit for bit:", same)
        if not same:
            raise SystemExit(1)


if __name__ == "__main__":
    main()
