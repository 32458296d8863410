"""The standard sPLL as a NIR graph of standard nodes only, written the way clocked consumers
(snnTorch, Norse, nirtorch) read them.

Graph of an N-sPLL network with K gate levels (``M = N K``; level k of sPLL i is row
``i K + k``), node names prefixed so that their alphabetical order is the execution order
(:data:`NODE_NAMES`; nirtorch runs the nodes of a file in that order)::

    a_input (Input 1) ─> b_level_input (Linear (M+2N)×1) ─> c_level (CubaLIF M+2N)
    c_level ─> d_gate (LIF M+2N)
    d_gate ─> e_synapses (Affine 2N×(M+2N), bias) ─> f_spll (CubaLIF 2N) ─> h_output (Output 2N)
    f_spll ─> g_fanout (Linear (M+2N)×2N) ─> d_gate                        (closes the loop)

``f_spll`` holds the N TDEs (rows ``0..N-1``) and the N CCOs (rows ``N..2N-1``), so the
graph's one output is the TDE and CCO spikes of every step. ``d_gate`` holds the M AND neurons
(rows ``0..M-1``: level neuron and CCO spike in the same step) and 2N *relays* (rows
``M..M+2N-1``), memoryless neurons that repeat each TDE's and CCO's spike: through
``e_synapses`` a TDE relay adds ``g_cco`` to its CCO's current, and each relay inhibits its own
source (the refractory stand-in below). So the graph is one feed-forward chain closed by one
edge, ``g_fanout -> d_gate``, and every consumer runs it alike: the previous step's TDE and CCO
spikes reach the gate node through that edge, so every spike between neurons arrives one step
after it was emitted (as on Loihi and in the fixed-point reference), the input in its own step.
No node carries meaning in metadata: every consumer that runs CubaLIF, LIF, Linear and Affine
runs the sPLL.

**Time step and spike size.** NIR states neurons in continuous time; clocked consumers step
them by Euler with a time step ``dt`` and count a spike as 1 in the step it happens (a pulse of
height 1 lasting ``dt``). This graph is written for one ``dt`` (``metadata["dt"]``, default
100 µs, snnTorch's fixed step; pass the same ``dt`` to Norse's ``from_nir``) so that every
consumer reads it the same way:

* CubaLIF: ``w_in = tau_syn / dt`` and ``r = tau_mem / dt``, so a step is
  ``I <- (1 - dt/tau_syn) I + x`` and ``v <- (1 - dt/tau_mem) v + I`` (snnTorch's ``Synaptic``
  and Norse's ``CubaLIF`` alike); thresholds are 1, resets to 0, ``v_leak = 0``.
* LIF: ``tau = dt``, ``r = 1``: ``v <- x`` (memoryless), threshold 1.5: the AND neuron.
* The currents are potentials gained per step: the TDE's synaptic current is
  ``I_trg dt / (c_tde v_tde_thr)``, the CCO's ``(I + I_offset) dt / (c_cco v_cco_thr)``; the
  offset enters as the bias ``b`` of ``e_synapses`` with ``b / (1 - (1 - dt/tau_cco_syn)) =
  I_offset dt / (c_cco v_cco_thr)``.
* Level neuron k of sPLL i holds ``I_fac / thresholds[i, k]`` (input weight
  ``g_tde_fac / thresholds[i, k]``, ``tau_syn = tau_tde_fac``) and, with ``tau_mem = dt``,
  fires on every step it exceeds 1.

**Refractory periods** do not exist in NIR. With ``refractory="self-inhibition"`` each TDE and
CCO inhibits its own synaptic current after each spike by the charge it loses while held at 0
in the golden model, averaged over its spikes in a golden run under Poisson input
(:func:`inhibition_weights`); with ``"none"`` they are dropped. Either way this approximates the
hold at 0; the error is measured in ``tests/test_standard_nir.py`` and the README.

The offset enters through the bias of ``e_synapses``, filtered by the CCO's synapse: it reaches
its value within a few ``tau_cco_syn`` of the start. :func:`~mappings.standard.nir_run.run_nir`
executes such a graph by the consumers' rules with numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

from .construction import DEFAULT_LEVELS, DEFAULT_PLACEMENT, Gate, gate_levels

#: ``metadata["format"]`` of the graph.
FORMAT = "spll-hw standard sPLL, NIR standard nodes v1"
#: Default time step [s]: snnTorch's import assumes 100 µs.
DEFAULT_DT = 1e-4
#: Refractory realisations.
REFRACTORY = ("self-inhibition", "none")
#: A time constant shorter than this many steps cannot be stepped by Euler (the decay factor
#: ``1 - dt/tau`` would be <= 0).
MIN_TAU_STEPS = 1.0
INSTALL_HINT = "pip install -e '.[nir]'"


@dataclass(frozen=True)
class StandardNir:
    """The graph and what it was built from."""

    graph: object
    network: Network
    gate: Gate
    dt: float
    refractory: str


#: Node names in execution order: consumers that read a NIR file (nirtorch) run the nodes in
#: the file's order, which is alphabetical, so the letter prefix sets it.
NODE_NAMES = {
    "input": "a_input",
    "level_input": "b_level_input",
    "level": "c_level",
    "gate": "d_gate",
    "synapses": "e_synapses",
    "spll": "f_spll",
    "fanout": "g_fanout",
    "output": "h_output",
}


def to_standard_nir(
    network: Network,
    *,
    dt: float = DEFAULT_DT,
    levels: int = DEFAULT_LEVELS,
    placement: str = DEFAULT_PLACEMENT,
    input_rate: float = 300.0,
    refractory: str = "self-inhibition",
    gate: Gate | None = None,
) -> StandardNir:
    """The NIR graph of ``network`` from standard nodes (layout in the module docstring).

    Raises:
        ValueError: naming the parameter and the target when the network cannot be
            represented: a time constant shorter than ``dt`` (Euler's decay factor would be
            negative), a refractory realisation not in :data:`REFRACTORY`, or a gate that does
            not fit the network.
    """
    nir = _nir()
    if not isinstance(network, Network):
        raise ValueError(f"nir-standard needs a spll_hw Network, got {type(network).__name__}")
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"nir-standard: dt must be a finite time > 0 s, got {dt!r}")
    if refractory not in REFRACTORY:
        raise ValueError(
            f"nir-standard: refractory must be one of {REFRACTORY}, got {refractory!r}"
        )
    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    for name in ("tau_cco_syn", "tau_cco", "tau_tde_fac", "tau_tde_trg", "tau_tde"):
        short = np.flatnonzero(p[name] < MIN_TAU_STEPS * dt)
        if short.size:
            i = int(short[0])
            raise ValueError(
                f"sPLL {i}: {name} = {p[name][i]:g} s is shorter than the time step {dt:g} s; "
                "target nir-standard steps it by Euler and cannot represent it (use a smaller dt)"
            )
    if gate is None:
        gate = gate_levels(network, levels, placement, input_rate)
    n, k = network.n_spll, gate.n_levels
    if gate.thresholds.shape[0] != n:
        raise ValueError(f"nir-standard: gate has {gate.thresholds.shape[0]} sPLLs, network {n}")
    m = n * k
    tde_scale = dt / (p["c_tde"] * p["v_tde_thr"])  # current [A] -> potential per step / thr
    cco_scale = dt / (p["c_cco"] * p["v_cco_thr"])
    spll_of_row = np.repeat(np.arange(n), k)
    tde_rows, cco_rows = np.arange(n), n + np.arange(n)  # rows of the spll node
    relay_tde, relay_cco = m + np.arange(n), m + n + np.arange(n)  # rows of the gate node

    # fanout: the spll node's spikes to the gate node: each CCO to its K AND neurons (weight
    # 1, with the level neuron's 1 above the threshold 1.5) and every TDE and CCO to its relay
    # (weight 2: the relay fires whenever its source did).
    fanout = np.zeros((m + 2 * n, 2 * n))
    fanout[np.arange(m), cco_rows[spll_of_row]] = 1.0
    fanout[relay_tde, tde_rows] = 2.0
    fanout[relay_cco, cco_rows] = 2.0
    # synapses: gate node -> spll node. AND neurons add g_trg * increment to the trigger
    # current; TDE relays add g_cco to the CCO's current; relays inhibit their own source
    # (refractory stand-in); the bias is the CCO's offset.
    synapses = np.zeros((2 * n, m + 2 * n))
    synapses[tde_rows[spll_of_row], np.arange(m)] = (
        (p["g_tde_trg"] * tde_scale)[:, None] * gate.increments
    ).reshape(m)
    synapses[cco_rows, relay_tde] = p["g_cco"] * cco_scale
    if refractory == "self-inhibition":
        w = inhibition_weights(network, dt, input_rate)
        synapses[tde_rows, relay_tde] = -w["tde"] * dt
        synapses[cco_rows, relay_cco] = -w["cco"] * dt
    bias = np.r_[np.zeros(n), p["i_cco_offset"] * cco_scale * dt / p["tau_cco_syn"]]

    def cuba(tau_syn, tau_mem, threshold=1.0):
        size = len(tau_syn)
        return nir.CubaLIF(
            tau_syn=np.asarray(tau_syn, dtype=float),
            tau_mem=np.asarray(tau_mem, dtype=float),
            r=np.asarray(tau_mem, dtype=float) / dt,
            v_leak=np.zeros(size),
            v_threshold=np.full(size, threshold),
            v_reset=np.zeros(size),
            w_in=np.asarray(tau_syn, dtype=float) / dt,
        )

    size_gate = m + 2 * n
    # Level neurons sit in the rows of their AND neurons; the relays' rows get no input.
    level_weight = np.zeros((size_gate, 1))
    level_weight[:m, 0] = (p["g_tde_fac"][:, None] / gate.thresholds).reshape(m)
    nodes = {
        NODE_NAMES["input"]: nir.Input(input_type={"input": np.array([1])}),
        NODE_NAMES["level_input"]: nir.Linear(weight=level_weight),
        NODE_NAMES["level"]: cuba(
            np.r_[np.repeat(p["tau_tde_fac"], k), np.full(2 * n, dt)], np.full(size_gate, dt)
        ),
        NODE_NAMES["gate"]: nir.LIF(
            tau=np.full(size_gate, dt),
            r=np.ones(size_gate),
            v_leak=np.zeros(size_gate),
            v_threshold=np.full(size_gate, 1.5),
            v_reset=np.zeros(size_gate),
        ),  # fmt: skip
        NODE_NAMES["synapses"]: nir.Affine(weight=synapses, bias=bias),
        NODE_NAMES["spll"]: cuba(
            np.r_[p["tau_tde_trg"], p["tau_cco_syn"]], np.r_[p["tau_tde"], p["tau_cco"]]
        ),
        NODE_NAMES["fanout"]: nir.Linear(weight=fanout),
        NODE_NAMES["output"]: nir.Output(output_type={"output": np.array([2 * n])}),
    }
    edges = [
        (NODE_NAMES[a], NODE_NAMES[b])
        for a, b in (
            ("input", "level_input"),
            ("level_input", "level"),
            ("level", "gate"),
            ("gate", "synapses"),
            ("synapses", "spll"),
            ("spll", "fanout"),
            ("fanout", "gate"),
            ("spll", "output"),
        )
    ]
    metadata = {
        "format": FORMAT,
        "dt": float(dt),
        "spike_size": "a spike is 1 in the time step it happens (a pulse of height 1 for dt)",
        "outputs": "output[:N] = TDE spikes, output[N:] = CCO spikes, per time step",
        "n_spll": int(n),
        "gate_levels": int(k),
        "gate_placement": gate.placement,
        "refractory": refractory,
    }
    graph = nir.NIRGraph(nodes=nodes, edges=edges, metadata=metadata)
    return StandardNir(graph, network, gate, float(dt), refractory)


def inhibition_weights(network: Network, dt: float, input_rate: float) -> dict[str, np.ndarray]:
    """Self-inhibition weights (potential per step, threshold 1) standing in for the TDE's and
    the CCO's refractory periods, per sPLL, shape ``(N,)`` each.

    A refractory neuron loses the charge its current would have delivered while it is held at
    0. The weight removes that charge on average: from a golden run on a Poisson train at
    ``input_rate`` (1 s, fixed seed), the mean over a neuron's spikes of
    ``∫_0^t_refr I(t_s + s) ds / (c v_thr)`` with the current decaying from its value just
    after the spike (the CCO's includes the offset), spread over the synapse it enters
    (``w tau_syn / dt`` steps of potential in total).
    """
    from spll_hw import simulate

    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    rng = np.random.default_rng(2024)
    train = np.sort(rng.uniform(0.0, 1.0, rng.poisson(input_rate)))
    res = simulate(network, train, 1.0)
    lost = {}
    for part, spikes, var, tau_s, refr, c, thr in (
        ("tde", res.tde_spikes, "i_trg", p["tau_tde_trg"], p["t_tde_refr"], p["c_tde"],
         p["v_tde_thr"]),
        ("cco", res.cco_spikes, "i_cco", p["tau_cco_syn"], p["t_cco_refr"], p["c_cco"],
         p["v_cco_thr"]),
    ):  # fmt: skip
        times = np.unique(np.concatenate([s for s in spikes if len(s)] or [np.zeros(0)]))
        mean_current = np.zeros(network.n_spll)
        if times.size:
            trace = simulate(network, train, 1.0, record_spikes=False, probe_times=times)
            values = trace.info["trace"][var]
            for i, s in enumerate(spikes):
                if len(s):
                    mean_current[i] = values[i, np.searchsorted(times, s)].mean()
        charge = mean_current * tau_s * -np.expm1(-refr / tau_s)
        if part == "cco":
            charge = charge + p["i_cco_offset"] * refr
        lost[part] = charge / (c * thr) / tau_s  # total potential w tau_s/dt = charge/(c thr)
    return lost


def write_standard_nir(network: Network, path: str | Path, **options) -> Path:
    """Write :func:`to_standard_nir` of ``network`` as a NIR HDF5 file; returns the path."""
    path = Path(path)
    _nir().write(path, to_standard_nir(network, **options).graph)
    return path


def _nir():
    try:
        import nir
    except ImportError as exc:
        raise ImportError(f"nir-standard export needs the nir package: {INSTALL_HINT}") from exc
    return nir
