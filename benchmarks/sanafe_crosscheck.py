"""Cross-check of the loihi1 chip estimate against SANA-FE's Loihi model (``pip install sanafe``).

Workload: the reference of issue 2 (50-sPLL vary-offset network, VibTac vary-offset LIF
parameters, 56.2-668 Hz, 2 s of 300 Hz Poisson input, seed 0; benchmarks/bench_engine.py), run
through the golden model of the network as the loihi1 profile realises it (dt = 10 us).

SANA-FE has no TDE (its somas cannot gate a synapse by a product), so it cannot simulate the
sPLL itself. It replays the sPLL's traffic instead: the input and every TDE and CCO spike of
the golden run (binned to 10 us steps) come from SANA-FE "input" neurons, which send them over
the sPLL's own synapses (input -> every TDE, CCO_i -> TDE_i, TDE_i -> CCO_i) to 100 LIF neurons
that stand for the TDEs and CCOs, never fire, and update every step (``force_update``), all on
core 0 as the toolkit's placement puts them. So SANA-FE charges the same synaptic events,
messages and neuron updates with its own figures (arch/loihi.yaml), and the differences are:

* neuron updates: SANA-FE 51.2 + 21.6 pJ per update, the toolkit 81 pJ (Davies et al. 2018,
  Table 2, active) for 150 compartments (a Loihi-1 TDE takes two) against SANA-FE's 100;
* synaptic events: SANA-FE 33.6 pJ (sparse synapse), the toolkit 23.6 pJ (Table 2 minimum);
* spikes: replayed spikes cost SANA-FE nothing at the soma, the toolkit 69.3 pJ each;
* static power: SANA-FE has none; the ratio below compares dynamic energy.

    python -m benchmarks.sanafe_crosscheck                 # 2 s, 50 sPLLs
    python -m benchmarks.sanafe_crosscheck --duration 0.1  # quick
    python -m benchmarks.sanafe_crosscheck --biotac ../shared/datasets/biotac_slide_20_50

``--biotac DIR`` costs one BioTac sample instead (the first 2-s sample of recording 33 of the
first thesis material, LIF-encoded as the ``biotac-vary-offset-lif`` preset's thesis network
was tuned) through that network: real tactile input, a different spike rate, the same replay.

Recorded result: benchmarks/results/sanafe_crosscheck.md.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from quantize import load_profile
from quantize.resources import resource_report, sample_cost
from spll_hw import Network, backends, network_frequencies
from spll_hw.config import NetworkConfig
from spll_hw.datasets.biotac import load_biotac
from spll_hw.encoders import make_encoder
from spll_hw.model.grid import spike_steps

from .bench_engine import PARAMS, RATE

#: SANA-FE's synapse unit for every connection (all are one-to-one or one-to-many sparse).
SYNAPSE = "loihi_sparse_synapse"


def workload(duration: float, n_spll: int, seed: int = 0):
    """The reference network (``n_spll`` sPLLs) and one Poisson train of ``duration`` s."""
    net = Network.vary_offset(PARAMS, network_frequencies(56.2, 668.0, n_spll))
    rng = np.random.default_rng(seed)
    return net, np.sort(rng.uniform(0.0, duration, rng.poisson(RATE * duration)))


def biotac_workload(root: str, recording: int = 33) -> tuple[Network, np.ndarray, float, str]:
    """The ``biotac-vary-offset-lif`` thesis network, the LIF spike train of the first 2-s
    sample of ``recording`` of the first thesis material, its duration [s] and a description."""
    samples = load_biotac(root, recordings=[recording])
    train = make_encoder("lif").encode(samples.signals[:1], samples.fs)[0]
    duration = samples.signals.shape[1] / samples.fs
    net = NetworkConfig.preset("biotac-vary-offset-lif").build()
    return net, np.asarray(train, dtype=float), duration, f"BioTac {samples.sources[0]}"


def replay_on_sanafe(result, input_steps: np.ndarray, n_steps: int) -> tuple[dict, float]:
    """SANA-FE's Loihi run of the recorded traffic (module docstring): its result dict and
    wall time [s]. ``input_steps``: distinct steps with an input spike (1-based)."""
    import sanafe

    dt = 1e-5
    arch = sanafe.load_loihi()
    net = sanafe.Network()
    n = result.n_spll

    def train(steps: np.ndarray) -> list[bool]:
        spikes = np.zeros(n_steps, dtype=bool)
        spikes[np.asarray(steps, dtype=np.int64) - 1] = True
        return spikes.tolist()

    sources = [("in", [input_steps])]
    sources.append(("tde_out", [spike_steps(s, dt) for s in result.tde_spikes]))
    sources.append(("cco_out", [spike_steps(s, dt) for s in result.cco_spikes]))
    core = arch.tiles[0].cores[0]
    replay, slot = {}, 0
    for name, trains in sources:
        group = net.create_neuron_group(name, len(trains), {})
        for k, steps in enumerate(trains):
            group[k].set_attributes(
                soma_hw_name=f"loihi_inputs[{slot}]", model_attributes={"spikes": train(steps)}
            )
            group[k].map_to_core(core)
            slot += 1
        replay[name] = group
    sinks = {}
    for name in ("tde", "cco"):
        group = net.create_neuron_group(
            name, n, {"threshold": 1e30, "force_update": True}, soma_hw_name="loihi_lif"
        )
        for k in range(n):
            group[k].map_to_core(core)
        sinks[name] = group
    weight = {"weight": 1.0, "synapse_hw_name": SYNAPSE}
    for i in range(n):
        replay["in"][0].connect_to_neuron(sinks["tde"][i], weight)
        replay["cco_out"][i].connect_to_neuron(sinks["tde"][i], weight)  # trigger
        replay["tde_out"][i].connect_to_neuron(sinks["cco"][i], weight)  # feedback
    chip = sanafe.SpikingChip(arch)
    chip.load(net)
    start = time.perf_counter()
    out = chip.sim(n_steps)
    return out, time.perf_counter() - start


def crosscheck(
    duration: float = 2.0, n_spll: int = 50, seed: int = 0, biotac: str | None = None
) -> dict:
    """Both estimates of one sample and their ratios (module docstring)."""
    profile = load_profile("loihi1")
    if biotac is None:
        net, inputs = workload(duration, n_spll, seed)
        what = f"{duration:g} s of {RATE:g} Hz Poisson input"
    else:
        net, inputs, duration, what = biotac_workload(biotac)
    result = backends.get("golden:profile=loihi1").simulate(
        net, inputs, duration, record_spikes=True
    )
    # Two input spikes in one 10 us step are one spike on the chip (and in the replay).
    input_steps = np.unique(spike_steps(inputs, profile.dt))
    n_steps = round(duration / profile.dt)
    report = resource_report(net, profile)
    ours = sample_cost(
        report, profile, result.tde_counts, result.cco_counts, input_steps.size, duration
    )
    sf, wall = replay_on_sanafe(result, input_steps, n_steps)
    c = ours.counts
    dynamic = ours.total_energy - (ours.energy["static"] or 0.0)
    rows = {
        "synaptic events": (c.synaptic_events, sf["spikes"]),
        "messages": (c.total("messages"), sf["packets_sent"]),
        "sink neuron updates (SANA-FE) / compartment updates (toolkit)": (
            c.neuron_updates, sf["neurons_updated"] - int(sf["neurons_fired"])
        ),
        "synapse energy [J]": (
            sum(ours.energy[k] for k in ("input deliveries", "trigger deliveries",
                                        "feedback deliveries")),
            sf["energy"]["synapse"],
        ),
        "neuron energy [J]": (ours.energy["neuron updates"] + ours.energy["spikes"],
                              sf["energy"]["soma"]),
        "network energy [J]": (ours.energy["messages"] + ours.energy["hops"],
                               sf["energy"]["network"]),
        "dynamic energy [J]": (dynamic, sf["energy"]["total"]),
        "time on chip [s]": (ours.time_on_chip, sf["sim_time"]),
    }  # fmt: skip
    return {
        "duration": duration,
        "input": what,
        "n_spll": net.n_spll,
        "input_spikes": int(inputs.size),
        "input_steps": int(input_steps.size),
        "rows": {
            k: (float(a), float(b), float(a) / float(b) if b else float("nan"))
            for k, (a, b) in rows.items()
        },  # fmt: skip
        "sanafe_wall_s": wall,
    }


def markdown(check: dict) -> str:
    lines = [
        f"{check['n_spll']} sPLLs, {check['input']} "
        f"({check['input_spikes']} spikes, {check['input_steps']} distinct 10 us steps), "
        "loihi1 profile against SANA-FE arch/loihi.yaml (replayed traffic).",
        "",
        "| quantity | toolkit (loihi1) | SANA-FE | toolkit / SANA-FE |",
        "|---|---:|---:|---:|",
    ]
    for name, (ours, theirs, ratio) in check["rows"].items():
        lines.append(f"| {name} | {ours:.6g} | {theirs:.6g} | {ratio:.3f} |")
    lines.append(f"\nSANA-FE wall time: {check['sanafe_wall_s']:.1f} s")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=2.0, help="seconds (default 2)")
    parser.add_argument("--n", type=int, default=50, help="sPLLs (default 50)")
    parser.add_argument("--seed", type=int, default=0, help="input seed (default 0)")
    parser.add_argument("--biotac", metavar="DIR", help="cost one BioTac sample (docstring)")
    args = parser.parse_args()
    print(markdown(crosscheck(args.duration, args.n, args.seed, args.biotac)))


if __name__ == "__main__":
    main()
