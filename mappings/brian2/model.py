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

The equations, the parameters (named as the columns of the parameter matrix) and the
``on_pre`` statements are written from the model's tables (:mod:`spll_hw.model.equations`).

Brian2 updates in this order every step of length ``dt``: integrate all states over the step,
detect threshold crossings, deliver spikes, reset. So an event that falls inside a step acts on
the state at the step's end, and a spike is time-stamped with the step's start. Input spikes
arrive in the step the model's grid says (:mod:`spll_hw.model.grid`). Within one step the
pathways run in the model's order of jumps, so a CCO spike meets the facilitatory current from
before any input of the same step (the golden rule for simultaneous events).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

import numpy as np

from spll_hw.model.equations import CCO, JUMPS, TDE, UNITS, Jump, Neuron
from spll_hw.model.grid import spike_steps
from spll_hw.params import PARAM_NAMES

from .checks import steps


def equations(neuron: Neuron) -> str:
    """Brian2 equations of one neuron of the model (:mod:`spll_hw.model.equations`): its
    synapse currents, its membrane (held while refractory) and every parameter as a per-neuron
    constant named as the column of the parameter matrix."""
    lines = [f"d{s.current}/dt = -{s.current} / {s.tau} : amp" for s in neuron.synapses]
    m = neuron.membrane
    drive = " + ".join(m.drive)
    lines.append(f"dv/dt = ({drive}) / {m.c} - v / {m.tau} : volt (unless refractory)")
    lines += [f"{name} : {UNITS[name]} (constant)" for name in neuron.parameters]
    return "\n".join(lines) + "\n"


def on_pre(jump: Jump) -> str:
    """Brian2 ``on_pre`` statement of a jump: the target's current gains the gain (times the
    target's factor state at that instant)."""
    factor = f" * {jump.factor}_post" if jump.factor else ""
    return f"{jump.current}_post += {jump.gain}_post{factor}"


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


def _input_group(b2: ModuleType, inputs: list[np.ndarray], dt: float, clock):
    """The SpikeGeneratorGroup of a batch's input trains and the sample of each of its neurons
    (shape ``(n_generators,)``).

    Each spike is placed at the start ``(k - 1) dt`` of the Brian2 step that ends at the model's
    arrival step ``k`` (:func:`spll_hw.model.grid.spike_steps`): Brian2 delivers a spike
    time-stamped ``i dt`` after integrating over ``[i dt, (i + 1) dt]``, so it acts at ``k dt``,
    where the model's clocked targets add it. Sample ``s``'s generator neurons are
    ``first[s] .. first[s] + width[s] - 1`` (at least one each)."""
    times = [(spike_steps(np.asarray(x, dtype=float), dt) - 1) * dt for x in inputs]
    layers = [input_layers(t, dt) for t in times]
    width = np.array([int(k.max()) + 1 if k.size else 1 for k in layers])
    first = np.concatenate([[0], np.cumsum(width)[:-1]])
    source = b2.SpikeGeneratorGroup(
        int(width.sum()),
        np.concatenate([f + k for f, k in zip(first, layers, strict=True)]).astype(np.int64),
        np.concatenate(times) * b2.second,
        clock=clock,
        name="input",
    )
    return source, np.repeat(np.arange(len(inputs)), width)


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
    for neuron in (CCO, TDE):
        m = neuron.membrane
        group = b2.NeuronGroup(
            n,
            equations(neuron),
            threshold=f"v >= {m.v_thr}",
            reset="v = 0*volt",
            refractory=m.t_refr,
            method=method,
            clock=clock,
            name=neuron.name,
        )
        for name in neuron.parameters:
            setattr(group, name, b2.Quantity(col[name], dim=group.variables[name].dim))
        groups[neuron.name] = group
    groups["input"], owner = _input_group(b2, inputs, dt, clock)

    # One Synapses object per jump; Brian2 runs a step's pathways in ascending ``order``, so
    # simultaneous events jump in the model's order.
    synapses = []
    for k, jump in enumerate(JUMPS):
        source, target = groups[jump.source], groups[jump.target]
        path = b2.Synapses(
            source, target, on_pre=on_pre(jump), clock=clock, name=f"{jump.source}_{jump.target}"
        )
        if jump.source == "input":
            # Every generator neuron of a sample drives every TDE of that sample's copy.
            path.connect(
                i=np.repeat(np.arange(owner.size), n_spll),
                j=(owner[:, None] * n_spll + np.arange(n_spll)).reshape(-1),
            )
        else:
            path.connect(j="i")
        path.pre.order = k - len(JUMPS)
        synapses.append(path)
    cco, tde = groups["cco"], groups["tde"]

    cco_monitor = b2.SpikeMonitor(cco, record=record_spikes, name="cco_spikes")
    tde_monitor = b2.SpikeMonitor(tde, record=record_spikes, name="tde_spikes")
    # A fixed name, not Brian2's "network*": a standalone project rebuilt in the same folder
    # (mappings.brian2.run.standalone_project) then keeps its headers unchanged.
    network = b2.Network(
        cco, tde, groups["input"], *synapses, cco_monitor, tde_monitor, name="network"
    )
    return Brian2Model(network, cco, tde, cco_monitor, tde_monitor)
