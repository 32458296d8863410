"""The floor of every clocked construction: exact integration between steps, checked as an
export is.

A clocked target (Loihi's integers, a NIR consumer's steps) puts every spike on a step's end
and holds refractory periods in whole steps. :func:`spll_hw.exporters.dt_ladder.floor_check`
measures what that alone costs: the export check (:func:`spll_hw.exporters.check.check_run`,
its reference inputs and metric) of exact integration between steps of ``dt`` with the golden
product as gate (:func:`spll_hw.construction.reference.simulate_reference`), refractory holds of
rule ``--holds`` (``compensated``: ``round(t_refr/dt - 1/2)`` steps, the exports'; ``dithered``:
that fraction dithered over the spikes, exact on average). No construction on that clock, of
whatever precision, is expected to come closer to golden than this. Beside it, golden's own
variation on the same inputs 0.5 ms later (the check's resolution).

What a construction adds to it, one part at a time: ``--levels K``, the gate's staircase of K
band-quantile levels instead of golden's product; ``--rounded NAMES --bits B``, the named time
constants as a ``B``-bit decay realises them at the step (:func:`rounded`; Loihi's LIF: 12)::

    python benchmarks/bench_clock_floor.py --presets vibtac-time-scaled-peak \\
        --steps 1e-6 --durations 1,10 --holds compensated,dithered
    python benchmarks/bench_clock_floor.py --presets vibtac-time-scaled-peak --steps 1e-6 \\
        --holds dithered --rounded tau_cco_syn,tau_cco --bits 16,20,24
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.bench_golden_sensitivity import (  # noqa: E402
    durations,
    names_of,
    numbers_of,
    preset_names,
    report,
)

#: Refractory holds measured by default (:data:`spll_hw.model.holds.HOLDS`).
DEFAULT_HOLDS = ("compensated",)
#: The time constant [s] of a potential whose decay rounds to 0 (no leak within any run).
NO_LEAK = 1e4


def rounded(network, names: list[str], dt: float, bits: int):
    """``network`` with each time constant of ``names`` [s] replaced by the one its ``bits``-bit
    decay ``round(2^bits (1 - e^(-dt/tau)))`` realises at step ``dt`` [s], as
    :func:`mappings.lava.integers.loihi_decays` rounds at 12 bits: a decay of 0 does not leak
    (:data:`NO_LEAK`), except a kicked synapse's (``tau_tde_trg``, ``tau_cco_syn``), which takes
    a decay of 1 and whose gain then keeps its kicks' charge."""
    from spll_hw.model.discrete import decay_constant, realised_tau
    from spll_hw.model.roles import roles
    from spll_hw.network import Network
    from spll_hw.params import PARAM_NAMES

    r = roles()
    kicked = {r.trg.tau: r.gated.gain, r.cco_syn.tau: r.fed.gain}
    col = {name: j for j, name in enumerate(PARAM_NAMES)}
    m = network.matrix().copy()
    for name in names:
        tau = m[:, col[name]].copy()
        delta = decay_constant(tau, dt, bits)
        if name in kicked:
            m[:, col[kicked[name]]] *= np.where(delta < 1, tau / realised_tau(1, dt, bits), 1.0)
            delta = np.maximum(delta, 1)
        m[:, col[name]] = np.minimum(realised_tau(delta, dt, bits), NO_LEAK)
    return Network.from_matrix(m, layout=network.layout)


def measure(preset: str, dt: float, duration: float, hold: str, levels: int = 0,
            names: tuple[str, ...] = (), bits: int = 12) -> dict:  # fmt: skip
    """One row: exact integration between steps of ``dt`` [s] (refractory hold ``hold``) of
    ``preset`` on its reference inputs of ``duration`` [s], against golden; with a gate of
    ``levels`` band-quantile levels (0: golden's product) and the time constants ``names``
    as ``bits``-bit decays realise them (:func:`rounded`)."""
    from spll_hw.config import NetworkConfig
    from spll_hw.construction.gate import gate_levels
    from spll_hw.exporters.check import golden_resolution
    from spll_hw.exporters.dt_ladder import floor_check

    start = time.perf_counter()
    net = NetworkConfig.preset(preset).build()
    gate = gate_levels(net, levels, "band-quantile") if levels else None
    integrated = rounded(net, list(names), dt, bits) if names else None
    floor = floor_check(net, dt, hold=hold, duration=duration, gate=gate, integrated=integrated)
    row = {"preset": preset, "dt": dt, "duration": duration, "hold": hold, "levels": levels,
           "rounded": list(names), "bits": bits if names else None,
           "tde_error": floor.error, "worst_spll": int(floor.spll_error.argmax()),
           "worst_spll_error": float(floor.spll_error.max()),
           "golden_shifted": golden_resolution(net, duration)}  # fmt: skip
    row["seconds"] = time.perf_counter() - start
    print(f"{preset} at {dt * 1e6:g} µs ({variant(row)}) on {duration:g} s: "
          f"{100 * floor.error:.2f} % (golden 0.5 ms later {100 * row['golden_shifted']:.2f} %), "
          f"{row['seconds']:.0f} s", file=sys.stderr, flush=True)  # fmt: skip
    return row


def variant(row: dict) -> str:
    """What was integrated besides the step: the hold, the gate, the rounded decays."""
    gate = f"{row['levels']} levels" if row.get("levels") else "golden's product"
    decays = f", {', '.join(row['rounded'])} at {row['bits']} bits" if row.get("rounded") else ""
    return f"{row['hold']} hold, {gate}{decays}"


def markdown(rows: list[dict]) -> str:
    """The rows as a table: one row per preset, step and variant; one column per duration."""
    spans = sorted({r["duration"] for r in rows})
    head = [f"{d:g} s (golden 0.5 ms later)" for d in spans]
    lines = ["| preset | step | integrated | " + " | ".join(head) + " |",
             "|---" * (len(head) + 3) + "|"]  # fmt: skip
    for key in dict.fromkeys((r["preset"], r["dt"], variant(r)) for r in rows):
        cells = []
        for d in spans:
            row = next((r for r in rows if (r["preset"], r["dt"], variant(r)) == key
                        and r["duration"] == d), None)  # fmt: skip
            cells.append("" if row is None else f"{100 * row['tde_error']:.2f} % "
                         f"({100 * row['golden_shifted']:.2f} %)")  # fmt: skip
        lines.append(f"| `{key[0]}` | {key[1] * 1e6:g} µs | {key[2]} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _holds() -> list[str]:
    from spll_hw.model.holds import HOLDS

    return list(HOLDS)


def _time_constants() -> list[str]:
    from spll_hw.model.roles import roles

    return list(roles().time_constants)


#: ``--holds``, ``--rounded``: comma-separated refractory holds of the reference, time
#: constants of the sPLL.
holds = names_of("hold", _holds)
time_constants = names_of("time constant", _time_constants)

#: ``--levels``, ``--bits``: comma-separated whole numbers >= 0.
counts = numbers_of(int, lambda x: x >= 0, "integers >= 0")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], epilog="Every list is comma-separated."
    )
    options = (  # (flag, type, default, help); every list comma-separated
        ("--presets", preset_names, None, "presets (required)"),
        ("--steps", durations, None, "steps [s] (required)"),
        ("--durations", durations, [1.0], "input lengths [s] (default 1, the check's)"),
        ("--holds", holds, list(DEFAULT_HOLDS), "refractory holds (default compensated)"),
        ("--levels", counts, [0], "band-quantile gate levels (default 0: golden's product)"),
        ("--rounded", time_constants, [], "time constants to round (default none)"),
        ("--bits", counts, [12], "bits of the rounded decays (default 12)"),
        ("--json", Path, None, "write the rows here"),
        ("--markdown", Path, None, "write the table here"),
    )
    for flag, kind, default, words in options:
        parser.add_argument(flag, type=kind, default=default, help=words,
                            required=flag in ("--presets", "--steps"))  # fmt: skip
    args = parser.parse_args(argv)
    bits = args.bits if args.rounded else [12]
    rows = [measure(p, dt, d, h, k, tuple(args.rounded), b) for p in args.presets
            for dt in args.steps for h in args.holds for k in args.levels for b in bits
            for d in args.durations]  # fmt: skip
    report(rows, markdown(rows), args.json, args.markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
