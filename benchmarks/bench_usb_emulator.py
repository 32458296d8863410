"""Speed of the USB board emulator against the fixed-point reference it runs, on long trains.

Workload: the reference network of ``bench_engine.py`` (50-sPLL vary-offset, Table 6 "VibTac
vary offset LIF"), quantized to a fixed-point profile (default ``loihi2``, dt = 10 µs), driven
by a Poisson train of ``--events`` input spikes (default 10^6) spread over ``--duration``
seconds. ``usb-emulator`` streams the train through pyusb to the emulated board in packets of
256 events (about 4 000 packets for 10^6 events) and collects its output;
``golden-fixed-point`` runs the same integer model over the whole train in one call, on every
core and on one (the emulator makes one short call per batch of buffered input packets).
The two must give the same spikes bit for bit (checked); the table gives the wall times and
their ratio to the one-call reference on every core.

    python benchmarks/bench_usb_emulator.py                  # 10^6 events
    python benchmarks/bench_usb_emulator.py --events 50000   # a quick check

The board answers the input packets it has buffered (up to its 4 input credits) with one call
of the fixed-point core when the host reads output, so a 10^6-event run makes about 980 engine
calls for its ~3 900 input and ~23 000 output packets. Measured 2026-11-27 on the shared 2-core
development machine (``nice``, other engineers' jobs running; wall times: medians of 3 runs
after the change, 2 before; × golden: the range over those runs):

=====================================  ============  ===========  ==============  ============
code                                   load average  golden [s]   usb-emulator    × golden
=====================================  ============  ===========  ==============  ============
before (per-packet engine calls)       8.2 - 8.5     2.9          24.9 s          8.5 - 8.7
after                                  8.1 - 8.4     3.2          15.1 s          4.2 - 5.0
after                                  4.2 - 4.7     1.2          7.6 s           5.9 - 6.8
=====================================  ============  ===========  ==============  ============

The ratio depends on the load: ``golden-fixed-point`` is one long call whose two threads share
the cores, the emulator is ~27 000 short pyusb transfers in one Python thread. In CPU time the
emulator costs 6.8 s against the reference's 1.1 - 1.3 s (before: 8.3 s); most of it is the
per-packet work of the protocol (pyusb's transfer path, framing and CRC on the board, decoding
and checking every packet on the host), about 0.2 ms per packet, which only larger packets
(a board declaring more than 256 events per packet) would cut further.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from bench_engine import PARAMS  # noqa: E402

from mappings.fixed_point.backend import FixedPointBackend  # noqa: E402
from mappings.usb.backend import simulate_usb  # noqa: E402
from spll_hw import Network, network_frequencies  # noqa: E402


def poisson_events(n_events: int, duration: float, seed: int) -> np.ndarray:
    """``n_events`` sorted uniform spike times [s] in ``(0, duration)``, shape ``(n_events,)``."""
    return np.sort(np.random.default_rng(seed).uniform(0.0, duration, n_events))


def timed(fn):
    """``(fn(), wall seconds)``."""
    start = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - start


def same_spikes(a, b) -> bool:
    """Whether two results have the same TDE and CCO spike times, sPLL by sPLL."""
    trains = zip(a.tde_spikes + a.cco_spikes, b.tde_spikes + b.cco_spikes, strict=True)
    return all(np.array_equal(x, y) for x, y in trains)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=1_000_000, help="input spikes (10^6)")
    parser.add_argument("--duration", type=float, default=100.0, help="run length [s] (100)")
    parser.add_argument("--profile", default="loihi2", help="fixed-point profile (loihi2)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the input train (0)")
    parser.add_argument("--timeout", type=float, default=10.0, help="USB transfer bound [s]")
    args = parser.parse_args()

    net = Network.vary_offset(PARAMS, network_frequencies(56.2, 668.0, 50))
    x = poisson_events(args.events, args.duration, args.seed)
    reference_backend = FixedPointBackend(profile=args.profile)
    reference, t_ref = timed(lambda: reference_backend.simulate(net, x, args.duration))
    _, t_one = timed(lambda: reference_backend.simulate(net, x, args.duration, threads=1))
    board, t_usb = timed(
        lambda: simulate_usb(
            net, x, args.duration, profile=args.profile, device="emulator", timeout=args.timeout
        )
    )
    equal = same_spikes(board, reference) and board.info["complete"]
    steps = board.info["n_steps"]
    print(
        f"workload: {net.n_spll} sPLLs, {args.events} input spikes over {args.duration:g} s, "
        f"profile {args.profile} ({steps} steps); spikes: TDE {int(reference.tde_counts.sum())}, "
        f"CCO {int(reference.cco_counts.sum())}\n"
    )
    print("| backend | wall time [s] | × golden-fixed-point | spikes equal |")
    print("|---|---|---|---|")
    print(f"| golden-fixed-point | {t_ref:.2f} | 1 | |")
    print(f"| golden-fixed-point, 1 thread | {t_one:.2f} | {t_one / t_ref:.2f} | |")
    print(f"| usb-emulator | {t_usb:.2f} | {t_usb / t_ref:.2f} | {'yes' if equal else 'NO'} |")
    if not equal:
        sys.exit("usb-emulator's spikes differ from golden-fixed-point's")


if __name__ == "__main__":
    main()
