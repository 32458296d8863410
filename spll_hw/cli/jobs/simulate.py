"""``spll-hw simulate``: run one input spike train through an sPLL network on one backend (the
golden model by default)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ... import backends
from ...files import atomic_folder, atomic_path, write_npz, write_results, write_text
from ...harness.metrics import rate_error
from ...report.spll_plots import plot_network_rates, plot_spll_activity
from ...simulate import check_probes, periodic_spikes, poisson_spikes
from ..inputs import read_network, read_spike_file

#: The file of every spike time, beside ``results.json`` (:func:`save_spikes`).
SPIKES_FILE = "spikes.npz"
#: Probe times of the activity plot (its first 0.2 s).
N_PROBES = 4001


def run(args: argparse.Namespace) -> int:

    backend = backends.get(args.backend)
    config = read_network(args).config
    window = (0.0, min(0.2, args.duration))
    if backend.capabilities.probes:
        check_probes(
            config.n, N_PROBES, f"the activity plot probes every sPLL {N_PROBES} times: use "
            "fewer sPLLs (n in the [network] table), or a --backend without probes",
        )  # fmt: skip
    probes = np.linspace(*window, N_PROBES) if backend.capabilities.probes else None
    network = config.build()
    if args.input is not None:
        inputs = read_spike_file(args.input)
    elif args.periodic is not None:
        inputs = periodic_spikes(args.periodic, args.duration)
    else:
        inputs = poisson_spikes(args.rate, args.duration, args.seed)  # refuses a train too big
    show = network.n_spll // 2 if args.show is None else args.show
    if not 0 <= show < network.n_spll:
        raise ValueError(f"--show must be an sPLL index in 0..{network.n_spll - 1}, got {show}")
    result = backend.simulate(
        network, inputs, args.duration, noise_sigma=args.phase_noise, seed=args.seed,
        probe_times=probes,
    )  # fmt: skip
    freqs = network.free_frequencies()
    against = _against_golden(backend, network, inputs, args, result)
    with atomic_folder(args.out) as out:
        write_text(out / "params.toml", config.to_toml())
        save_spikes(out / SPIKES_FILE, result)
        plot_network_rates(result, freqs, out / "rates.png")
        if probes is not None:
            plot_spll_activity(result, inputs, show, out / "activity.png", window=window)
            activity = f"![activity of sPLL {show}](activity.png)"
        else:
            activity = f"(no activity plot: backend `{backend.label}` has no probes)"
        late = result.info.get("inputs_after_end", 0)
        write_results(out / "results.json", {
            "backend": result.backend,
            "inputs_after_end": late,
            "duration_s": args.duration,
            "n_input_spikes": result.info["n_input_spikes"],
            "free_frequency_hz": freqs.tolist(),
            "tde_rate_hz": result.tde_rates.tolist(),
            "cco_rate_hz": result.cco_rates.tolist(),
            "spikes_file": SPIKES_FILE,
            "wall_time_s": result.wall_time,
            "against_golden": against,
        })  # fmt: skip
        rows = "\n".join(
            f"| {i} | {f:.1f} | {t:.1f} | {c:.1f} |"
            for i, (f, t, c) in enumerate(
                zip(freqs, result.tde_rates, result.cco_rates, strict=True)
            )
        )
        write_text(
            out / "summary.md",
            f"# sPLL network simulation\n\n"
            f"Layout `{config.layout}`, {network.n_spll} sPLLs, {args.duration} s, "
            f"{result.info['n_input_spikes']} input spikes"
            + (f" ({late} more after the end, not simulated)" if late else "")
            + f", backend `{backend.label}` in "
            f"{result.wall_time * 1e3:.1f} ms.\n\n"
            + ("" if against is None else f"Measured {_golden_line(against)}.\n\n")
            + f"![rates](rates.png)\n\n{activity}\n\n"
            f"| sPLL | free-running [Hz] | TDE rate [Hz] | CCO rate [Hz] |\n|---|---|---|---|\n"
            f"{rows}\n",
        )
    if late:
        print(
            f"note: {late} input spike(s) after --duration {args.duration:g} s were not simulated"
        )
    print(
        f"{network.n_spll} sPLLs on `{backend.label}`, {result.info['n_input_spikes']} input "
        f"spikes in {args.duration:g} s:\n  sPLL  free-running [Hz]  TDE rate [Hz]  CCO rate [Hz]"
    )
    for i, (f, t, c) in enumerate(zip(freqs, result.tde_rates, result.cco_rates, strict=True)):
        print(f"  {i:4d}  {f:17.1f}  {t:13.1f}  {c:13.1f}")
    if against is not None:
        print(_golden_line(against))
    print(f"report: {args.out / 'summary.md'}")
    return 0


def _against_golden(backend, network, inputs, args, result) -> dict | None:
    """On a backend other than golden: golden's run of the same network and input (the network
    as given, not as a chip realises it) and the relative L1 errors of the TDE and CCO rates
    against it (:func:`spll_hw.harness.metrics.rate_error`); ``None`` on golden itself."""
    if backend.spec == "golden":
        return None
    golden = backends.get("golden").simulate(
        network, inputs, args.duration, noise_sigma=args.phase_noise, seed=args.seed
    )
    errors = {part: rate_error(result, golden, part) for part in ("tde", "cco")}
    return {"backend": "golden", "tde_rate_error": errors["tde"],
            "cco_rate_error": errors["cco"]}  # fmt: skip


def _golden_line(against: dict) -> str:
    def pct(x: float) -> str:
        return "-" if x != x else f"{100 * x:.1f} %"  # NaN: golden has no such spike

    return (
        f"against golden on the same input (the network as given): TDE-rate error "
        f"{pct(against['tde_rate_error'])}, CCO {pct(against['cco_rate_error'])} "
        "(sum |rate - golden's| / sum golden's)"
    )


def save_spikes(path: Path, result) -> None:
    """Every TDE and CCO spike time of ``result`` [s] as one ``.npz`` (atomically): for each
    ``kind`` in ``tde``, ``cco``, ``{kind}_times`` holds the spike times of all sPLLs one after
    the other (float64) and ``{kind}_offsets`` (int64, shape ``(n_spll + 1,)``) where each
    sPLL's begin, so sPLL ``i``'s times are ``times[offsets[i]:offsets[i + 1]]``. Binary, so a
    long run's spikes take 8 bytes each, not a JSON list."""
    arrays = {}
    for kind in ("tde", "cco"):
        trains = getattr(result, f"{kind}_spikes")
        if trains is None:  # a backend that records no spikes of this kind
            continue
        lengths = [len(t) for t in trains]
        arrays[f"{kind}_offsets"] = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        arrays[f"{kind}_times"] = np.concatenate([[], *trains]).astype(np.float64)
    with atomic_path(path) as temporary:
        write_npz(temporary, arrays)
