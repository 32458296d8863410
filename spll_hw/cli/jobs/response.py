"""``spll-hw response``: TDE rate of one sPLL against the frequency of a periodic input."""

from __future__ import annotations

import argparse

import numpy as np

from ...files import atomic_folder, atomic_path, write_results, write_text
from ...report.spll_plots import plot_frequency_response
from ...simulate import frequency_response
from ..inputs import read_network


def run(args: argparse.Namespace) -> int:

    if args.points < 2 or not args.f_max > args.f_min >= 0:
        raise ValueError("need --points >= 2 and 0 <= --f-min < --f-max")
    config = read_network(args).config
    freqs = np.linspace(args.f_min, args.f_max, args.points)
    rates = frequency_response(config.spll, args.free_freq, freqs, args.duration)
    with atomic_folder(args.out) as out:
        write_text(out / "params.toml", config.to_toml())
        with atomic_path(out / "response.csv") as csv:
            np.savetxt(csv, np.column_stack([freqs, rates]), delimiter=",",
                       header="input_hz,tde_rate_hz", comments="")  # fmt: skip
        plot_frequency_response(freqs, rates, args.free_freq, out / "response.png",
                                title=f"{args.network}, g_cco = {config.spll.g_cco:g}")  # fmt: skip
        write_results(out / "results.json", {
            "free_freq_hz": args.free_freq, "input_hz": freqs.tolist(),
            "tde_rate_hz": rates.tolist(),
        })  # fmt: skip
        write_text(
            out / "summary.md",
            f"# Frequency response\n\nBase sPLL of `{args.network}` free-running at "
            f"{args.free_freq:g} Hz, {args.points} periodic inputs from {args.f_min:g} to "
            f"{args.f_max:g} Hz, {args.duration:g} s each. Peak TDE rate {rates.max():.1f} Hz at "
            f"{freqs[np.argmax(rates)]:.1f} Hz.\n\n![response](response.png)\n",
        )
    print(f"peak TDE rate {rates.max():.1f} Hz at {freqs[np.argmax(rates)]:.1f} Hz")
    print(f"report: {args.out / 'summary.md'}")
    return 0
