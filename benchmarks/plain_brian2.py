"""A plain Brian2 model of the sPLL network: the yardstick for the golden engine's speed.

This is the network as a Brian2 user would write it from the thesis's equations (1)-(5),
without anything spll-hw's own Brian2 mapping (``mappings/brian2``) adds for checking: one
NeuronGroup per neuron kind (the 50 CCOs, the 50 TDEs), one SpikeGeneratorGroup for the input,
three Synapses (input -> TDE facilitatory, CCO -> TDE trigger, TDE -> CCO), one SpikeMonitor on
the TDEs (counts only), ``method="exact"``, parameters shared by all sPLLs as constants and only
the CCO offset per neuron. It runs one sample per ``cpp_standalone`` build; the time quoted is
Brian2's own run time of the compiled binary (``device._last_run_time``), not compilation.

    python benchmarks/plain_brian2.py          # 3 samples of the reference workload

``benchmarks/bench_engine.py --brian2`` times it beside the golden engine in the same run.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

import numpy as np

from mappings.brian2.model import input_layers
from spll_hw import Network
from spll_hw.params import PARAM_NAMES

#: Thesis eq. 1 and 4: the CCO's synapse current and membrane with its offset current.
CCO = """
dI/dt = -I / tau_cco_syn : amp
dv/dt = (I + I_offset) / c_cco - v / tau_cco : volt (unless refractory)
I_offset : amp (constant)
"""

#: Thesis eq. 2, 3 and 5: the TDE's facilitatory and trigger currents and its membrane.
TDE = """
dI_fac/dt = -I_fac / tau_tde_fac : amp
dI_trg/dt = -I_trg / tau_tde_trg : amp
dv/dt = I_trg / c_tde - v / tau_tde : volt (unless refractory)
"""


def shared_constants(net: Network) -> dict[str, float]:
    """The parameters every sPLL of ``net`` shares (SI), by the thesis's names.

    Raises:
        ValueError: if a parameter other than the CCO offset differs between sPLLs (the plain
            model is for vary-offset networks, the reference workload's layout).
    """
    columns = dict(zip(PARAM_NAMES, np.asarray(net.matrix()).T, strict=True))
    shared = {}
    for name, values in columns.items():
        if name == "i_cco_offset":
            continue
        if np.ptp(values) != 0.0:
            raise ValueError(f"plain Brian2 model: {name} differs between sPLLs (use vary-offset)")
        shared[name] = float(values[0])
    return shared


def run_plain(net: Network, train: np.ndarray, duration: float, dt: float = 10e-6) -> dict:
    """Build, compile and run one sample; return its run time [s] and spike counts.

    Args:
        net: a vary-offset network (only ``i_cco_offset`` may differ between sPLLs).
        train: sorted input spike times [s], shape ``(n_spikes,)``.
        duration: simulated time [s].
        dt: time step [s].

    Returns:
        ``{"run_time": s, "tde_counts": (n_spll,)}``.
    """
    import brian2 as b2
    from brian2.devices.device import reset_device

    c = shared_constants(net)
    units = {
        "tau_cco_syn": b2.second, "tau_cco": b2.second, "c_cco": b2.farad,
        "tau_tde_fac": b2.second, "tau_tde_trg": b2.second, "tau_tde": b2.second,
        "c_tde": b2.farad,
    }  # fmt: skip
    namespace = {name: c[name] * unit for name, unit in units.items()}
    n = net.n_spll
    project = Path(tempfile.mkdtemp(prefix="spll-hw-plain-brian2-"))
    b2.set_device("cpp_standalone", build_on_run=False, directory=str(project))
    try:
        b2.device.reinit()
        b2.device.activate(build_on_run=False, directory=str(project))
        b2.defaultclock.dt = dt * b2.second
        cco = b2.NeuronGroup(
            n, CCO, threshold=f"v >= {c['v_cco_thr']}*volt", reset="v = 0*volt",
            refractory=c["t_cco_refr"] * b2.second, method="exact", namespace=namespace,
        )  # fmt: skip
        cco.I_offset = np.asarray(net.matrix())[:, PARAM_NAMES.index("i_cco_offset")] * b2.amp
        tde = b2.NeuronGroup(
            n, TDE, threshold=f"v >= {c['v_tde_thr']}*volt", reset="v = 0*volt",
            refractory=c["t_tde_refr"] * b2.second, method="exact", namespace=namespace,
        )  # fmt: skip
        # One generator neuron can fire once per step: the k-th spike of a step goes to the
        # k-th neuron, and all of them drive every TDE.
        layers = input_layers(train, dt)
        source = b2.SpikeGeneratorGroup(int(layers.max(initial=0)) + 1, layers, train * b2.second)
        fac = b2.Synapses(source, tde, on_pre=f"I_fac_post += {c['g_tde_fac']}*amp")
        fac.connect()
        trigger = b2.Synapses(cco, tde, on_pre=f"I_trg_post += {c['g_tde_trg']} * I_fac_post")
        trigger.connect(j="i")
        feedback = b2.Synapses(tde, cco, on_pre=f"I_post += {c['g_cco']}*amp")
        feedback.connect(j="i")
        monitor = b2.SpikeMonitor(tde, record=False)
        network = b2.Network(cco, tde, source, fac, trigger, feedback, monitor)
        network.run(duration * b2.second)
        b2.device.build(directory=str(project), compile=True, run=True, with_output=False)
        return {
            "run_time": float(b2.device._last_run_time),
            "tde_counts": np.asarray(monitor.count[:], dtype=np.int64),
        }
    finally:
        b2.device.reinit()
        reset_device()
        shutil.rmtree(project, ignore_errors=True)


def main() -> None:
    from bench_engine import DURATION, workload

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=3, help="samples (one build each)")
    args = parser.parse_args()
    net, trains = workload(args.samples)
    for k, train in enumerate(trains):
        out = run_plain(net, train, DURATION)
        print(f"sample {k}: {out['run_time'] * 1e3:.1f} ms run time, "
              f"TDE spikes {out['tde_counts'].sum()}")  # fmt: skip


if __name__ == "__main__":
    main()
