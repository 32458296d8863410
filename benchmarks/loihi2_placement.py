"""Every preset on Loihi 2 with its placement figures as ranges (issue 58): the cores at the
values and over the ranges of configurations, thresholds and neurons per core, and the dynamic
energy of a 1-s Poisson train (300 Hz) as ``[low, high]``, each end the extreme over the three
placements (docs/profiles.md, "Placement figures as ranges").

Run from the repository root::

    python benchmarks/loihi2_placement.py [PROFILE]
"""

from __future__ import annotations

import argparse

import numpy as np

from spll_hw import chips, presets, simulate
from spll_hw.config import NetworkConfig


def row(name: str, profile: str, train: np.ndarray) -> str:
    """One preset's Markdown row: cores [fewest, most], fits at the values, dynamic energy."""
    network = NetworkConfig.preset(name).build()
    fit = chips.resources(chips.OnChip(network, profile))
    result = simulate(network, train, 1.0)
    result.info["n_input_spikes"] = len(train)
    cost = chips.cost(chips.OnChip(network, profile), result)
    return (
        f"| {name} | {fit.cores_words()} | {'yes' if fit.fits else 'no'} | "
        f"{chips.format_joules(cost.dynamic_energy)} {cost.dynamic_range} |"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("profile", nargs="?", default="loihi2")
    args = p.parse_args()
    train = np.sort(np.random.default_rng(0).uniform(0.0, 1.0, 300))
    print("| preset | cores [fewest, most] | fits | dynamic energy, 1 s at 300 Hz [low, high] |")
    print("|---|---:|---|---:|")
    for name in presets.names():
        print(row(name, args.profile, train))


if __name__ == "__main__":
    main()
