"""NeuroBench's metrics of an sPLL network, counted natively from its spike counts.

NeuroBench (Yik et al., Nat. Commun. 2025; the ``neurobench`` 2.3 harness) counts through
PyTorch hooks on a time-stepped model, so it cannot see the event-driven golden model. The same
quantities follow exactly from the network's shape and a run's spike counts. The network as
NeuroBench would see it, a layered model of ``n`` sPLLs at a time step ``dt``:

* two neuron layers, the ``n`` TDEs and the ``n`` CCOs (``2n`` neurons), and the input (one
  spike train, not a neuron layer);
* three connection layers as dense weight matrices: input → TDE (``n × 1``, the facilitatory
  synapses), CCO → TDE (``n × n``, the trigger synapses on its diagonal) and TDE → CCO
  (``n × n``, the feedback synapses on its diagonal): ``n + 2n²`` weights, ``3n`` of them
  non-zero.

Each metric, with the NeuroBench 2.3 definition it follows (``neurobench/metrics/...`` and the
metric pages of its documentation):

* **footprint** [bytes] (``static/footprint.py``: bytes of every parameter and buffer): the
  15 parameters and the 7 state values of each sPLL (:data:`PARAMETERS`, :data:`STATE`), at
  float32 as NeuroBench counts a torch model, or at a chip profile's word widths
  (:attr:`spll_hw.chips.ProfileInfo.storage_bits`). What the network stores: the zeros of the
  dense matrices above are not stored anywhere (a torch model with dense ``Linear`` layers
  would add ``4 (2n² - 2n)`` bytes of them).
* **connection sparsity** (``static/connection_sparsity.py``: zero weights over all weights of
  the connection layers): ``1 - 3n / (n + 2n²)``.
* **activation sparsity** (``workload/activation_sparsity.py``: zero activations over all
  activations of the neuron layers, every time step and sample): ``1 - spikes / (2n K)`` with
  ``K = round(duration / dt)`` steps. A spike count equals the non-zero activations when no
  neuron spikes twice in one step, i.e. when every refractory period is at least ``dt``
  (:attr:`NeuroBenchMetrics.activation_exact`; otherwise the sparsity is a lower bound).
* **synaptic operations** per sample (``workload/synaptic_operations.py``): *dense*, every
  weight of every connection layer at every step, ``K (n + 2n²)``; *effective ACs*, one per
  non-zero weight a spike reaches: ``n`` per input spike (facilitatory) and one per TDE spike
  (feedback); the **TDE gate**, one *MAC* per CCO spike: the trigger synapse adds
  ``g_tde_trg · I_fac``, the facilitatory current times the spike, a multiplication by a state
  where an AC adds a constant weight. NeuroBench's hooks, which see a binary CCO spike, would
  count it among the ACs: ACs + gate MACs is their ``Effective_ACs``.
* **neuron updates** per sample (``workload/membrane_updates.py``: updates of each neuron's
  membrane over the steps): ``2n K``, every neuron once a step, as a clocked chip does (a
  chip with two-compartment TDEs updates more: its energy model counts compartments).
* **time to decision** [s], in place of NeuroBench's model execution rate (forward passes per
  second of a time-stepped model), which its paper advises replacing for event-driven models:
  the classifier reads the TDE rates over the whole window, so the decision comes when the
  window is over and the chip has worked through it: ``max(window, time on chip)``.

Every count is a mean per sample, as NeuroBench reports them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from ..model.equations import NEURONS
from ..model.grid import n_steps
from ..network import Network
from ..params import PARAM_NAMES

#: Parameters of one sPLL (every parameter of its two neurons, eqs. 1-6).
PARAMETERS: tuple[str, ...] = tuple(dict.fromkeys(p for n in NEURONS for p in n.parameters))
#: State values of one sPLL: each neuron's synapse currents, potential and refractory counter.
STATE: tuple[str, ...] = tuple(
    f"{n.name}.{s}"
    for n in NEURONS
    for s in (*(syn.current for syn in n.synapses), "v", "refractory")
)
#: The refractory periods of each sPLL's two neurons.
REFRACTORY = tuple(n.membrane.t_refr for n in NEURONS)
#: Bits of a float32, NeuroBench's count of a torch parameter without a chip profile.
FLOAT32_BITS = 32
#: Time step [s] of a cell without a clocked profile (the exact model has none): Loihi 2's.
REFERENCE_DT = 1e-5


@dataclass(frozen=True)
class NeuroBenchMetrics:
    """NeuroBench's metrics of one network on one cell (module docstring for each).

    Attributes:
        n_spll: sPLLs.
        dt: time step [s] of the activation sparsity and the dense counts.
        dt_source: ``"profile"`` (the chip's step) or ``"reference"`` (:data:`REFERENCE_DT`).
        widths: ``"float32"`` or the profile whose word widths the footprint uses.
        footprint: bytes of parameters and state.
        connection_sparsity: zero weights over all weights (fraction).
        activation_sparsity: zero activations over all activations (fraction).
        activation_exact: no neuron can spike twice in one step (every refractory ≥ ``dt``).
        dense_synops: synaptic operations per sample, zeros included.
        effective_acs: accumulates per sample (input and feedback deliveries).
        gate_macs: multiply-accumulates per sample (the TDE gate: one per CCO spike).
        neuron_updates: neuron updates per sample.
        time_to_decision: [s] from the start of a sample to its decision.
        samples: samples averaged.
    """

    n_spll: int
    dt: float
    dt_source: str
    widths: str
    footprint: float
    connection_sparsity: float
    activation_sparsity: float
    activation_exact: bool
    dense_synops: float
    effective_acs: float
    gate_macs: float
    neuron_updates: float
    time_to_decision: float
    samples: int

    def to_dict(self) -> dict:
        return asdict(self)


def footprint(n_spll: int, storage_bits: tuple[int, int] | None = None) -> float:
    """Bytes of ``n_spll`` sPLLs: ``(parameter bits, state bits)`` per sPLL at a chip's widths,
    or float32 for each of :data:`PARAMETERS` and :data:`STATE` (``None``)."""
    if storage_bits is None:
        storage_bits = (FLOAT32_BITS * len(PARAMETERS), FLOAT32_BITS * len(STATE))
    return n_spll * sum(storage_bits) / 8


def connection_sparsity(n_spll: int) -> float:
    """Zero weights over all weights of the three dense connection layers (module
    docstring): ``1 - 3n / (n + 2n²)``."""
    n = n_spll
    return 1.0 - 3 * n / (n + 2 * n * n)


def metrics(
    network: Network,
    n_input: Sequence[int],
    tde_spikes: Sequence[int],
    cco_spikes: Sequence[int],
    window: float,
    dt: float | None = None,
    storage_bits: tuple[int, int] | None = None,
    widths: str = "float32",
    time_on_chip: float | None = None,
) -> NeuroBenchMetrics:
    """The metrics of ``network`` over samples of ``window`` [s] each.

    Args:
        network: the simulated network (its size and refractory periods).
        n_input, tde_spikes, cco_spikes: per sample, its input spikes and the spikes of all
            TDEs and of all CCOs, each shape ``(S,)``.
        window: length of each sample [s].
        dt: the profile's time step [s]; ``None``: :data:`REFERENCE_DT`.
        storage_bits: ``(parameter bits, state bits)`` per sPLL; ``None``: float32.
        widths: what ``storage_bits`` are (``"float32"`` or the profile's name).
        time_on_chip: mean time the chip works on a sample [s] (``None``: unknown, the window).
    """
    n = network.n_spll
    inputs = np.asarray(n_input, dtype=np.float64)
    tde = np.asarray(tde_spikes, dtype=np.float64)
    cco = np.asarray(cco_spikes, dtype=np.float64)
    if not (inputs.shape == tde.shape == cco.shape) or inputs.ndim != 1 or inputs.size == 0:
        raise ValueError(
            f"n_input, tde_spikes and cco_spikes need one value per sample, got shapes "
            f"{inputs.shape}, {tde.shape}, {cco.shape}"
        )
    size, sparsity = footprint(n, storage_bits), connection_sparsity(n)
    step = REFERENCE_DT if dt is None else dt
    steps = n_steps(window, step)
    refractory = network.matrix()[:, [PARAM_NAMES.index(k) for k in REFRACTORY]].min()
    return NeuroBenchMetrics(
        n_spll=n,
        dt=step,
        dt_source="reference" if dt is None else "profile",
        widths=widths if storage_bits is not None else "float32",
        footprint=size,
        connection_sparsity=sparsity,
        activation_sparsity=float(1.0 - np.mean(tde + cco) / (2 * n * steps)),
        activation_exact=bool(refractory >= step),
        dense_synops=float(steps * (n + 2 * n * n)),
        effective_acs=float(np.mean(n * inputs + tde)),
        gate_macs=float(np.mean(cco)),
        neuron_updates=float(2 * n * steps),
        time_to_decision=float(max(window, time_on_chip or 0.0)),
        samples=int(inputs.size),
    )


def from_results(
    network: Network,
    results: Sequence,
    window: float,
    profile=None,
    time_on_chip: float | None = None,
) -> NeuroBenchMetrics:
    """:func:`metrics` of simulated samples (:class:`~spll_hw.result.SimulationResult` of
    ``network``, each with ``info["n_input_spikes"]``) on chip ``profile``
    (:class:`spll_hw.chips.ProfileInfo`; ``None``: no profile, float32 and
    :data:`REFERENCE_DT`)."""
    bits = None if profile is None else profile.storage_bits
    return metrics(
        network,
        [r.info["n_input_spikes"] for r in results],
        [int(np.sum(r.tde_counts)) for r in results],
        [int(np.sum(r.cco_counts)) for r in results],
        window,
        dt=None if profile is None else profile.dt,
        storage_bits=bits,
        widths="float32" if bits is None else profile.name,
        time_on_chip=time_on_chip,
    )


def markdown(
    rows: Sequence[tuple[str, str, NeuroBenchMetrics | None]],
    keys: tuple[str, str] = ("layout", "column"),
) -> str:
    """One row per ``(layout, column, metrics)`` (``None``: the cell cannot be realised);
    ``keys`` are the titles of the first two columns."""
    lines = [
        f"| {keys[0]} | {keys[1]} | footprint [B] (widths) | connection sparsity | activation "
        "sparsity (dt) | dense SynOps | effective ACs | TDE gate MACs | neuron updates | time "
        "to decision [s] |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for layout, column, m in rows:
        if m is None:
            lines.append(f"| {layout} | {column} | does not fit |" + " - |" * 7)
            continue
        bound = "" if m.activation_exact else " ≥"
        ref = "" if m.dt_source == "profile" else ", reference"
        lines.append(
            f"| {layout} | {column} | {m.footprint:.0f} ({m.widths}) | "
            f"{m.connection_sparsity:.4f} | {bound}{m.activation_sparsity:.4f} "
            f"({m.dt * 1e6:g} µs{ref}) | {m.dense_synops:.4g} | {m.effective_acs:.4g} | "
            f"{m.gate_macs:.4g} | {m.neuron_updates:.4g} | {m.time_to_decision:.4g} |"
        )
    return "\n".join(lines)
