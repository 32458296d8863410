"""Speed of the USB board emulator against the fixed-point reference it runs, on long trains.

Workload: the reference network of ``bench_engine.py`` (50-sPLL vary-offset, Table 6 "VibTac
vary offset LIF"), quantized to a fixed-point profile (default ``loihi2``, dt = 10 µs), driven
by a Poisson train of ``--events`` input spikes (default 10^6) spread over ``--duration``
seconds. ``usb-emulator`` streams the train through pyusb to the emulated board in packets of
at most 1024 events (8 KiB; about 980 input and 6 800 output packets for 10^6 events) and
collects its output; ``golden-fixed-point`` runs the same integer model over the whole train in
one call, on every core and on one (the emulator makes one short call per batch of buffered
input packets). The two must give the same spikes bit for bit (checked); the table gives wall
and CPU times and the wall-time ratio to the one-call reference on every core.

    python benchmarks/bench_usb_emulator.py                  # 10^6 events
    python benchmarks/bench_usb_emulator.py --events 50000   # a quick check

Measured 2026-11-27 on the shared 2-core development machine (``nice``, other engineers' jobs
running, load average 8.2 - 8.6), this script on the code before and after the last change run
alternately, three runs each (ranges):

==========================================  ===========  ===========  ============  ===========
code                                        golden wall  golden CPU   usb wall      × golden
==========================================  ===========  ===========  ============  ===========
256-event packets, per-packet copies        2.5 - 2.9 s  1.2 - 1.4 s  9.7 - 11.4 s  3.6 - 4.6
1024-event packets, fewer copies            2.5 - 2.7 s  1.2 - 1.3 s  6.3 - 7.0 s   2.5 - 2.7
==========================================  ===========  ===========  ============  ===========

In CPU time the emulator now costs 3.3 - 3.5 s against the reference's 1.2 - 1.3 s (before:
6.7 - 7.3 s). On the idle machine (load 0.2 - 0.5, three runs, the same day, after the change)
the reference runs on both cores, **0.68 - 0.74 s**, and the emulator, one Python thread whose
engine calls use both cores, **2.7 - 3.3 s: 3.6 - 4.5×** (CPU 3.2 - 3.7 s against 1.2 - 1.3 s);
before the change it took 8.9 s against 0.75 s, 11.8×. Within the USB issue's 5×, with little
room. What is left is the engine's ~250 short calls (one per batch of four
buffered input packets) and the per-packet protocol work (pyusb's transfer path, framing and
CRC on the board, decoding and checking on the host). A board declaring 4096-event packets
(32 KiB) measured 0.4 - 0.7 s CPU less again; 1024 is kept as the emulator's default, a
transfer size every USB 2.0 high-speed board handles.
"""

from __future__ import annotations

import argparse
import os
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
    """``(fn(), (wall seconds, CPU seconds of this process, every thread))``."""
    start, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return out, (time.perf_counter() - start, time.process_time() - cpu)


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
    print("| backend | wall time [s] | × golden-fixed-point | CPU time [s] | spikes equal |")
    print("|---|---|---|---|---|")
    rows = [
        ("golden-fixed-point", t_ref, ""),
        ("golden-fixed-point, 1 thread", t_one, ""),
        ("usb-emulator", t_usb, "yes" if equal else "NO"),
    ]
    for name, (wall, cpu), same in rows:
        print(f"| {name} | {wall:.2f} | {wall / t_ref[0]:.2f} | {cpu:.2f} | {same} |")
    print(f"\nload average (1 min): {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if not equal:
        sys.exit("usb-emulator's spikes differ from golden-fixed-point's")


if __name__ == "__main__":
    main()
