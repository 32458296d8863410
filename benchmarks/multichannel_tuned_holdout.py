"""A tuned multichannel file against the file it was tuned from, once on the test block
(issue 35): both trained on recordings 1-32, one decision per recording 33-40 from its first T
seconds (as ``spll-hw slide`` decides), on the 20 materials and the thesis's 11, with the
paired change (a bootstrap over test recordings, :func:`spll_hw.stats.bootstrap_ci`).

Run from the repository root after the study (its ``best.toml``)::

    nice -n 15 python benchmarks/multichannel_tuned_holdout.py \\
        ../shared/datasets/biotac_slide_20_50 reports/tune/mc-ele/best.toml \\
        biotac-multichannel-lif 2,4
"""

from __future__ import annotations

import sys
import time

from spll_hw.cli.jobs.slide import class_sets, windows
from spll_hw.datasets.biotac_channels import load_biotac_channels
from spll_hw.datasets.recordings import split_recordings
from spll_hw.multichannel.config import MultichannelConfig
from spll_hw.multichannel.report import change_table, markdown_table
from spll_hw.multichannel.timecourse import accuracy_over_time

TRAIN, TEST = range(1, 33), range(33, 41)


def main(root: str, tuned: str, reference: str, times: str, jobs: int = 2) -> None:
    networks = {"tuned": MultichannelConfig.load(tuned),
                "given": MultichannelConfig.load(reference)}  # fmt: skip
    at = windows(times)
    start = time.perf_counter()
    channels = networks["given"].channels
    loaded = load_biotac_channels(root, channels, "all", [*TRAIN, *TEST], max(at)).openings()
    train, test = split_recordings(loaded, TEST, "recordings 33-40")
    points = accuracy_over_time(train, test, networks, class_sets(), at, jobs=jobs, progress=True)
    print(markdown_table(points))
    print("tuned minus given, accuracy points [95 % CI, paired bootstrap over test recordings]:")
    print(change_table(points, "tuned", "given"))
    print(f"{time.perf_counter() - start:.0f} s wall")


if __name__ == "__main__":
    main(*sys.argv[1:5])
