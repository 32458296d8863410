"""The sPLL network as Brian2 objects (thesis section 2.4.1, eqs. 1-5).

All N sPLLs live in two NeuronGroups of size N, one neuron per sPLL in each:

* ``cco``: synapse current ``I`` (eq. 1) and membrane ``v`` with the offset current (eq. 4);
* ``tde``: facilitatory and trigger currents ``I_fac``, ``I_trg`` (eqs. 2-3) and membrane ``v``
  (eq. 5).

Every parameter is a per-neuron constant in SI units, so one network holds any layout
(vary-offset, time-scaled, grouped, quantized). Spikes follow the golden model: an input spike
adds ``g_tde_fac`` to ``I_fac`` (input -> TDE, all to all), a CCO spike adds
``g_tde_trg * I_fac`` to ``I_trg`` (CCO -> TDE, one to one), a TDE spike adds ``g_cco`` to the
CCO's ``I`` (TDE -> CCO, one to one); all without delay. A neuron fires when ``v >= v_thr``, is
reset to 0 and holds ``v`` at 0 for its refractory period (``unless refractory``) while its
currents keep decaying.

Brian2 updates in this order every step of length ``dt``: integrate all states over the step,
detect threshold crossings, deliver spikes, reset. So an event that falls inside a step acts on
the state at the step's end, and a spike is time-stamped with the step's start. Within one step
the CCO -> TDE pathway runs before the input pathway, so a CCO spike meets the facilitatory
current from before any input of the same step (the golden rule for simultaneous events).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np

from spll_hw.params import PARAM_NAMES

from .checks import steps

#: CCO neuron: eq. 1 (synapse) and eq. 4 (membrane with offset current).
CCO_EQUATIONS = """
dI/dt = -I / tau_syn : amp
dv/dt = (I + I_offset) / C - v / tau : volt (unless refractory)
tau_syn : second (constant)
tau : second (constant)
C : farad (constant)
I_offset : amp (constant)
v_thr : volt (constant)
t_refr : second (constant)
g_cco : amp (constant)
"""

#: TDE neuron: eqs. 2-3 (facilitatory and trigger synapses) and eq. 5 (membrane).
TDE_EQUATIONS = """
dI_fac/dt = -I_fac / tau_fac : amp
dI_trg/dt = -I_trg / tau_trg : amp
dv/dt = I_trg / C - v / tau : volt (unless refractory)
tau_fac : second (constant)
tau_trg : second (constant)
tau : second (constant)
C : farad (constant)
v_thr : volt (constant)
t_refr : second (constant)
g_fac : amp (constant)
g_trg : 1 (constant)
"""

#: Brian2 variable of each group for each column of the parameter matrix (SI values).
CCO_COLUMNS = {
    "tau_cco_syn": "tau_syn",
    "tau_cco": "tau",
    "c_cco": "C",
    "i_cco_offset": "I_offset",
    "v_cco_thr": "v_thr",
    "t_cco_refr": "t_refr",
    "g_cco": "g_cco",
}
TDE_COLUMNS = {
    "tau_tde_fac": "tau_fac",
    "tau_tde_trg": "tau_trg",
    "tau_tde": "tau",
    "c_tde": "C",
    "v_tde_thr": "v_thr",
    "t_tde_refr": "t_refr",
    "g_tde_fac": "g_fac",
    "g_tde_trg": "g_trg",
}


@dataclass
class Brian2Model:
    """The Brian2 objects of one simulation; ``network`` owns all of them."""

    network: object
    cco: object
    tde: object
    cco_monitor: object
    tde_monitor: object


def input_layers(times: np.ndarray, dt: float) -> np.ndarray:
    """Generator index of each input spike, shape ``(n_spikes,)``.

    A Brian2 SpikeGeneratorGroup neuron may fire only once per step, but a dense input can put
    several spikes into one step. Spike k of a step goes to generator neuron k, and every
    generator neuron drives every TDE, so all of them still add ``g_tde_fac`` in that step.
    ``times`` must be sorted [s]; steps are counted as Brian2 does (:func:`~.checks.steps`).
    """
    if times.size == 0:
        return np.zeros(0, dtype=np.int64)
    bins = steps(times, dt)
    first_of_bin = np.r_[True, bins[1:] != bins[:-1]]
    start = np.maximum.accumulate(np.where(first_of_bin, np.arange(bins.size), 0))
    return np.arange(bins.size) - start


def build(
    b2: ModuleType,
    matrix: np.ndarray,
    inputs: list[np.ndarray],
    dt: float,
    method: str,
    record_spikes: bool,
) -> Brian2Model:
    """Create the Brian2 network on the active device (call after choosing it).

    A batch of samples is one Brian2 network: sample ``s`` has its own copy of the sPLLs
    (neurons ``s * n_spll .. (s + 1) * n_spll - 1`` of each group) and its own input
    generator neurons, which drive only that copy, so the samples run side by side in one
    build (one compilation for ``cpp_standalone``) and each equals a run of its own.

    Args:
        b2: the imported ``brian2`` module.
        matrix: network parameters, shape ``(n_spll, 15)`` in :data:`PARAM_NAMES` order (SI).
        inputs: per sample, sorted input spike times [s] inside the run, shape
            ``(n_spikes,)``.
        dt: time step [s] of every object.
        method: Brian2 integration method for both neuron groups (``"exact"`` is exact between
            steps for these linear equations).
        record_spikes: record spike times (otherwise the monitors only count).
    """
    n_spll = matrix.shape[0]
    tiled = np.tile(matrix, (len(inputs), 1))
    n = tiled.shape[0]
    col = {name: tiled[:, k] for k, name in enumerate(PARAM_NAMES)}
    clock = b2.Clock(dt=dt * b2.second, name="spll_clock")
    groups = {}
    for name, eqs, columns in (
        ("cco", CCO_EQUATIONS, CCO_COLUMNS),
        ("tde", TDE_EQUATIONS, TDE_COLUMNS),
    ):
        group = b2.NeuronGroup(
            n,
            eqs,
            threshold="v >= v_thr",
            reset="v = 0*volt",
            refractory="t_refr",
            method=method,
            clock=clock,
            name=name,
        )
        for column, var in columns.items():
            unit = group.variables[var].dim
            setattr(group, var, b2.Quantity(col[column], dim=unit))
        groups[name] = group
    cco, tde = groups["cco"], groups["tde"]

    # Generator neurons of sample s: first[s] .. first[s] + width[s] - 1 (at least one each).
    layers = [input_layers(np.asarray(x, dtype=float), dt) for x in inputs]
    width = np.array([int(k.max()) + 1 if k.size else 1 for k in layers])
    first = np.concatenate([[0], np.cumsum(width)[:-1]])
    source = b2.SpikeGeneratorGroup(
        int(width.sum()),
        np.concatenate([f + k for f, k in zip(first, layers, strict=True)]).astype(np.int64),
        np.concatenate([np.asarray(x, dtype=float) for x in inputs]) * b2.second,
        clock=clock,
        name="input",
    )
    facilitation = b2.Synapses(
        source, tde, on_pre="I_fac_post += g_fac_post", clock=clock, name="facilitation"
    )
    # Every generator neuron of a sample drives every TDE of that sample's copy.
    owner = np.repeat(np.arange(len(inputs)), width)
    facilitation.connect(
        i=np.repeat(np.arange(owner.size), n_spll),
        j=(owner[:, None] * n_spll + np.arange(n_spll)).reshape(-1),
    )
    trigger = b2.Synapses(
        cco, tde, on_pre="I_trg_post += g_trg_post * I_fac_post", clock=clock, name="trigger"
    )
    trigger.connect(j="i")
    # Both pathways run in the "synapses" slot; the lower order goes first (default -1).
    trigger.pre.order = -2
    feedback = b2.Synapses(tde, cco, on_pre="I_post += g_cco_post", clock=clock, name="feedback")
    feedback.connect(j="i")

    cco_monitor = b2.SpikeMonitor(cco, record=record_spikes, name="cco_spikes")
    tde_monitor = b2.SpikeMonitor(tde, record=record_spikes, name="tde_spikes")
    network = b2.Network(
        cco, tde, source, facilitation, trigger, feedback, cco_monitor, tde_monitor
    )
    return Brian2Model(network, cco, tde, cco_monitor, tde_monitor)
