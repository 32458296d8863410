"""The standard sPLL as a NIR graph of standard nodes only, written the way clocked consumers
(snnTorch, Norse, nirtorch) read them: the builder of ``spll-hw export --to nir-standard``.

Graph of an N-sPLL network with K gate levels (``M = N K``; level k of sPLL i is row
``i K + k``; ``S = M + 6N + 2`` rows: the gate's layout,
:func:`~spll_hw.construction.gate.gate_layout`, the start pulse's and the step guard's fast
relay), node names
prefixed so that their alphabetical order is the execution order (:data:`NODE_NAMES`)::

    a_input (Input 1) ─> b_level_input (Affine S×1, bias) ─> c_level (CubaLIF S)
    c_level ─> d_level_out (Affine S×S, diagonal, bias) ─> e_gate (LIF S)
    e_gate ─> f_synapses (Affine (4N+1)×S, bias) ─> g_spll (CubaLIF 4N+1)
    g_spll ─> h_refractory (Linear 2N×(4N+1)) ─> i_spikes (LIF 2N) ─> l_output (Output 2N)
    i_spikes ─> j_fanout (Linear S×2N) ─> e_gate                  (closes a loop)
    i_spikes ─> k_kicks (Linear S×2N) ─> c_level                  (closes a loop)

``g_spll`` holds the membranes of the N TDEs (rows ``0..N-1``), the N CCOs (rows ``N..2N-1``), 2N
memoryless *hold relays* (rows ``2N..4N-1``, one per TDE and CCO, firing while its refractory unit
holds it) and the step guard's latch (row ``4N``); ``i_spikes`` the TDEs' and CCOs' spikes outside
refractory periods (``h_refractory``: a neuron's spike less twice its hold relay's), the graph's one
output. ``c_level`` holds the level neurons and the refractory units' timers; ``d_level_out`` passes
their spikes on with weight 1 (level neurons) or 2 (timers) to ``e_gate``: the M AND neurons (rows
``0..M-1``: level neuron and CCO spike in the same step) and *relays*, memoryless neurons that
repeat each TDE's and CCO's spike and each timer's: through ``f_synapses`` a TDE relay adds
``g_cco`` to its CCO's current, and the relays of a neuron's spike and of its timers hold it
(refractory periods below). The loops close through ``j_fanout`` and ``k_kicks``: the previous
step's spikes reach the gate and level nodes through them, so every spike between neurons arrives
one step after it was emitted (as on Loihi and in the fixed-point reference), the input in its own
step.

Every consumer runs the graph alike because every node but ``c_level`` and ``e_gate`` has one
input, theirs the other through a loop: snnTorch (nirtorch's interpreter) runs the nodes in
the file's alphabetical order, a loop's input from the previous step; Norse (nirtorch's
``GraphExecutor``) in the order of a walk from the input along the edges in the file's order
(``i_spikes``' edge to ``l_output`` last, so that the output node is the last it runs, whose
value it returns), a node not yet run in this step giving its previous one; spll-hw's executor
(:mod:`mappings.nir.executor`) in topological order, a loop's edge delayed. (A node with two
inputs in the same step from two branches would run before one of them in Norse's walk.) Each
node has one threshold (snnTorch's import takes one per node). No node carries meaning in
metadata: every consumer that runs CubaLIF, LIF, Linear and Affine runs the sPLL.

**Time step and spike size.** NIR states neurons in continuous time; clocked consumers step
them by Euler with a time step ``dt`` and count a spike as 1 in the step it happens (a pulse of
height 1 lasting ``dt``). This graph is written for one ``dt`` (``metadata["dt"]``, default
100 µs, snnTorch's fixed step; pass the same ``dt`` to Norse's ``from_nir``, as the folder's
``load_consumer.py`` does) so that every consumer reads it the same way; stepped by another, its
step guard makes every output spike in every step (:mod:`mappings.nir.step_guard`, below):

* CubaLIF: ``w_in = tau_syn / dt`` and ``r = tau_mem / dt``, so a step is
  ``I <- (1 - dt/tau_syn) I + x`` and ``v <- (1 - dt/tau_mem) v + I`` (snnTorch's ``Synaptic``
  and Norse's ``CubaLIF`` alike); thresholds are 1, resets to 0, ``v_leak = 0``. Every time
  constant ``tau`` of the sPLL is written as ``tau' = dt / (1 - e^(-dt/tau))``, so Euler's
  decay ``1 - dt/tau'`` is the exact one. ``tau' > dt`` for every ``tau > 0`` (snnTorch's
  ``alpha = 1 - dt/tau_syn`` and Norse's step ``dt/tau'`` stay in [0, 1]), so a time constant
  shorter than the step is written exactly too.
* LIF: ``tau = dt``, ``r = 1``: ``v <- x`` (memoryless), threshold 1.5 (the AND neuron and the
  relays) or 0.5 (the output spikes).
* The currents are the potentials they add to their membranes over the next step: the
  consumers add a synapse's value of the step to its membrane (``v <- e^(-dt/tau_mem) v + I``,
  the current held over the step), so the TDE's synaptic current is ``I_trg k / v_tde_thr``
  and the CCO's ``I k / v_cco_thr``, ``k`` the exact one-step propagator of the synapse into
  its membrane (:func:`~spll_hw.model.discrete.exact_propagator`): a kick's charge over every
  later step is the exact one whatever ``tau_syn / dt`` (a current held constant at its
  step-start value would deliver ``dt / (tau (1 - e^(-dt/tau)))`` times it, 1.58 at
  ``tau = dt``). The graph's membranes then integrate as exactly between steps as the
  fine-clocked reference (:mod:`spll_hw.construction.reference`). The offset, a constant current
  into the CCO's membrane, enters as the bias ``b`` of ``f_synapses`` with
  ``b / (1 - e^(-dt/tau_cco_syn)) = I_offset g / v_cco_thr``, ``g`` the membrane's gain of a
  constant current over a step (:func:`~spll_hw.model.discrete.membrane_gain`).
* Level neuron k of sPLL i holds ``I_fac / thresholds[i, k]`` (input weight
  ``g_tde_fac / thresholds[i, k]``, ``tau_syn = tau_tde_fac``) and, with ``tau_mem = dt``,
  fires on every step it exceeds 1.

**Refractory periods** do not exist in NIR. With ``refractory="refractory-unit"`` (the
default) each TDE and CCO has a refractory unit of standard neurons that holds it for
``round(t_refr / dt - 1/2)`` whole steps after each spike (half a step less than the grid's
hold, for the half step by which a spike on the step's end is late on average,
:func:`~spll_hw.model.holds.compensated_hold`): two timers in
``c_level`` that its spike kicks, their relays in ``e_gate``, a current through ``f_synapses``
that makes its membrane fire and reset on every held step (so it starts from 0 after them), its
hold relay in ``g_spll`` (a copy of timer a) and ``h_refractory``, which drops those spikes
from ``i_spikes``
(:class:`~spll_hw.construction.gate.RefractoryTimers` states the arithmetic; the current's
weights are :func:`hold_weights`', chosen so that the file's float32 values leave the synapse as
the hold found it). With
``"self-inhibition"`` (the former stand-in, kept for comparison) each TDE and CCO inhibits its
own synaptic current after each spike by the charge it loses while held at 0 in a golden run
under Poisson input (:func:`~spll_hw.construction.gate.inhibition_weights`), which holds
only near that input's statistics; with ``"none"`` they are dropped. The errors per preset:
docs/backends.md.

**The start pulse.** The offset enters through the bias of ``f_synapses``, filtered by the CCO's
synapse, which starts at 0: alone, it would reach its value only a few ``tau_cco_syn`` into the run,
and every CCO would run about ``tau_cco_syn`` behind golden's for the whole run (2-10 ms on
``vibtac-time-scaled-peak``, whose TDEs fire too rarely to pull the phase back: its check at 10 µs
was 39 % off with that late start, 23 % without it). So the row of ``c_level`` after the gate's is a
*start neuron* (a constant input of :data:`START_DRIVE` through ``b_level_input``'s bias, a synapse
of :data:`START_TAU_STEPS` steps: it fires on every step from step 2 on) and the same row of
``e_gate`` the *start pulse* (``d_level_out``'s bias of :data:`~mappings.nir.step_guard.GATE_GAIN`,
less as much while the start neuron fires: it fires in step 1 only), which adds to each CCO's
synapse, through ``f_synapses``, what tops it up to the bias's stationary value in step 1. The
offset then drives every CCO's membrane fully from the first step, as in golden (whose CCOs start
with the offset at 0 s).

**The step guard** (:mod:`mappings.nir.step_guard`): the rows after the start neuron and pulse
(the *fast row* and its relay) and the last row of ``g_spll`` (the *latch*). The latch fires
when the fast relay fires (a step more than 0.1 % longer than ``dt``) or the start pulse fires
a second time (a step more than 0.1 % shorter: the start neuron is still silent in step 2),
then in every step after, and with it every output. At ``dt`` none of them fires: the graph's
outputs are those of the graph without them, spike for spike.
:func:`~mappings.nir.executor.run_nir` executes such a graph by the consumers' rules with numpy
only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mappings.standalone_counts import Tolerance
from spll_hw.construction.gate import (
    DEFAULT_GATE,
    Gate,
    GateOptions,
    gate_layout,
    gate_levels,
    inhibition_weights,
    refractory_timers,
    target_parameters,
)
from spll_hw.model.discrete import decay_fraction, exact_propagator, membrane_gain
from spll_hw.model.roles import roles
from spll_hw.network import Network

from .consumers import support
from .files import as_imported, nir_package
from .loader import CONSUMERS as CHECKED
from .standalone_check import TOLERANCE
from .step_guard import (
    GATE_GAIN,
    LATCH_HOLD_STEPS,
    LATCH_WEIGHT,
    OUTPUT_WEIGHT,
    PULSE_WEIGHT,
    STEP_TOLERANCE,
    fast_drive,
    start_drive,
)

#: ``metadata["format"]`` of the graph.
FORMAT = "spll-hw standard sPLL, NIR standard nodes v1"
#: Default time step [s]: snnTorch's import assumes 100 µs.
DEFAULT_DT = 1e-4
#: Gate levels of ``spll-hw export --to nir-standard``: with 8 the default preset's export
#: fails its own check (12.7 % TDE-rate error, 34 % on its periodic 199.6 Hz input, where the
#: gate is coarse: standard-exact is 15 % off there with 8 levels, 3 % with 16); with 16 it
#: passes (6.6 %). The graph grows from ``8N + 6N`` to ``16N + 6N`` gate rows.
EXPORT_LEVELS = 16
#: The start neuron (``c_level``'s row after the gate's): its synapse's time constant [steps]
#: and the constant input (``b_level_input``'s bias) that makes it fire from step 2 on (0.527,
#: then 0.527 + 0.9 * 0.527 = 1.0014 > 1; its current settles at 5.27) and not in step 2 at a
#: step 0.1 % shorter (:func:`~mappings.nir.step_guard.start_drive`).
START_TAU_STEPS = 10.0
START_DRIVE = start_drive(START_TAU_STEPS)
#: Refractory realisations.
REFRACTORY = ("refractory-unit", "self-inhibition", "none")
#: The export target's name in messages.
TARGET = "nir-standard"


@dataclass(frozen=True)
class StandardNir:
    """The graph and what it was built from."""

    graph: object
    network: Network
    gate: Gate
    dt: float
    refractory: str

    def info(self) -> dict:
        """The export folder's ``standard.json``: the graph's conventions and gate levels."""
        meta = self.graph.metadata
        return {
            "format": meta["format"],
            "dt": self.dt,
            "n_spll": self.network.n_spll,
            "outputs": meta["outputs"],
            "spike_size": meta["spike_size"],
            "refractory": self.refractory,
            "step_guard": meta["step_guard"],
            "consumers": support(self.dt),
            "nodes": NODE_NAMES,
            "gate": {
                "levels": self.gate.n_levels,
                "placement": self.gate.placement,
                "input_rates_hz": list(self.gate.input_rates),
                "thresholds_A": np.asarray(self.gate.thresholds).tolist(),
                "increments_A": np.asarray(self.gate.increments).tolist(),
            },
        }

    def open_loop(self) -> np.ndarray:
        """The sPLLs whose CCO gets nothing from its TDE, sorted indices, shape ``(k,)``: a 0
        in ``f_synapses`` from the TDE's relay (its row of
        :func:`~spll_hw.construction.gate.gate_layout`) to its CCO (the network's
        ``g_cco`` is 0 there; floats drop none of it). The export check judges such an sPLL
        failed (:mod:`spll_hw.exporters.check`)."""
        n = self.network.n_spll
        relay = gate_layout(n, self.gate.n_levels).relay_tde
        weights = np.asarray(self.graph.nodes[NODE_NAMES["synapses"]].weight)
        return np.flatnonzero(weights[n + np.arange(n), relay] == 0)

    def readme(self) -> str:
        """The export folder's ``README.md``: how to feed and run the graph."""
        n = self.network.n_spll
        consumers = support(self.dt)
        checks = [name for name, line in consumers.items()
                  if name in CHECKED and line.startswith("runs")]  # fmt: skip
        run = (LOADER_RUN.format(consumer=checks[0], consumers=" or ".join(checks), n2=2 * n)
               if checks else NUMPY_RUN.format(n2=2 * n))  # fmt: skip
        check = CHECK_COMMANDS.format(
            commands="\n".join(f"python check_consumer.py {name}" for name in checks),
            tolerance=Tolerance(*TOLERANCE).describe(),
        ) if checks else NO_CHECK  # fmt: skip
        return README.format(
            n=n, n2=2 * n, k=self.gate.n_levels, placement=self.gate.placement, dt=self.dt,
            tolerance=STEP_TOLERANCE,
            consumers="\n".join(f"* {name}: {line}." for name, line in consumers.items()),
            run=run, check=check,
        )  # fmt: skip


#: The export folder's ``README.md`` (:meth:`StandardNir.readme` fills it in).
README = """# sPLL network from standard NIR nodes

`network.nir` holds {n} sPLLs built from CubaLIF, LIF, Linear and Affine nodes only (no
metadata semantics), with a {k}-level gate ({placement} levels); written for a time step of
dt = {dt:g} s, a spike counting 1 in its step. Output: one vector of {n2} spikes per step, the
{n} TDEs first, then the {n} CCOs. Feed it the number of input spikes in each step, binned by
`spll_grid.py` (spll-hw's grid rule: a spike at `t` counts in step `max(1, ceil(t/dt))`, one on
a step's end in that step; numpy only):

```python
import nir, numpy as np
from spll_grid import arrival_counts, n_steps
graph = nir.read("network.nir")
dt = {dt!r}                                          # the file's own time step [s]
counts = arrival_counts(spike_times, n_steps(duration, dt), dt)   # (steps,)
{run}```

**The step.** The graph is a discrete construction for dt = {dt!r} s (relays of one step,
refractory timers that count steps, every decay exact at that step), not a continuous-time
network a consumer may step as it likes: `load_consumer.py` passes that step and refuses
another. Loading it yourself, give Norse `dt={dt!r}` (its `from_nir` defaults to 1 ms); at a
step more than {tolerance:.1%} off, the graph's step guard makes every output spike in every
step, which `load_consumer.run` reports as an error.

Gate levels and the construction: `standard.json`.

## Consumers at dt = {dt:g} s

{consumers}

## Check a consumer against `check.json`

`check_inputs.npz` holds the inputs of the export's check and `check.json` the TDE and CCO
spike count of every sPLL on each, as spll-hw's executor of the consumers' stepping
counted them. {check}.
"""

#: The README's check section where consumers ``check_consumer.py`` knows run the file's dt.
CHECK_COMMANDS = """With numpy, nir, torch and the consumer installed (not spll-hw):

```bash
{commands}
```

runs them through the consumer, prints a table and exits 0 when every count is `check.json`'s
within its tolerance ({tolerance}: the file's values are float32, as the consumers import
them; Norse's loader computes in float64 as the executor does, snnTorch in float32, where a
threshold crossing rounded the other way moves a few spikes), 1 naming the inputs and sPLLs
that are further off"""

#: The README's lines that run the file in a torch consumer that runs its dt, through the
#: folder's loader (:mod:`.loader`), as ``check_consumer.py`` does.
LOADER_RUN = """from load_consumer import load, run   # needs numpy, nir, torch and the consumer
module, dt = load("{consumer}")     # {consumers}, at the file's dt (another dt is refused)
spikes = run(module, counts[:, None], dt)            # (steps, 1, {n2}) spikes per step
"""
#: The README's lines where no torch consumer runs the file's dt: spll-hw's executor.
NUMPY_RUN = """# No torch consumer runs this dt (below); spll-hw's executor does:
from mappings.nir.executor import run_nir            # needs spll-hw
spikes = run_nir(graph, counts.astype(float), dt)    # (steps, {n2}) spikes per step
"""
#: The README's check section where no consumer ``check_consumer.py`` knows runs the dt.
NO_CHECK = """No consumer that `check_consumer.py` runs (Norse, snnTorch) runs this dt (above);
`spll-hw export --check <this folder>` runs the check again with spll-hw's executor"""


#: What the graph's metadata and ``standard.json`` say of its step guard.
STEP_GUARD = (
    "written for dt = {dt!r} s only: stepped by any dt more than {tolerance:.1%} off it, every "
    "output spikes in every step (the step guard: mappings/nir/step_guard.py)"
)


#: Node names in execution order: snnTorch's import runs the nodes in the file's order, which
#: is alphabetical, so the letter prefix sets it (Norse's: the module docstring).
NODE_NAMES = {
    "input": "a_input",
    "level_input": "b_level_input",
    "level": "c_level",
    "level_out": "d_level_out",
    "gate": "e_gate",
    "synapses": "f_synapses",
    "spll": "g_spll",
    "refractory": "h_refractory",
    "spikes": "i_spikes",
    "fanout": "j_fanout",
    "kicks": "k_kicks",
    "output": "l_output",
}


#: The grid of the hold currents' weights [thresholds] (:func:`hold_weights`): every multiple
#: of it below 4 in magnitude is a float32 value, so the weights, as the file holds them, and
#: their sums are exact.
HOLD_GRID = 2.0**-22
#: How many float32 values below ``2 - m`` :func:`hold_weights` tries for the relay's weight.
HOLD_SEARCH = 4096
#: Synapses :func:`hold_weights` searches at once.
HOLD_ROWS = 256
#: The current [thresholds] a refractory unit holds in its neuron's synapse: twice the
#: threshold, so the membrane fires on every held step.
HOLD_CURRENT = 2.0


def hold_weights(a: np.ndarray, steps: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The weights [thresholds] from a refractory unit's neuron relay, timer a and timer b into
    its neuron's synapse (``f_synapses``), shape ``(2N,)`` each, for synapses that keep
    ``1 - a`` of their current per step (``a = dt / tau_syn``, shape ``(2N,)``, of the float32
    ``tau_syn`` the file holds) and holds of ``steps`` whole steps (shape ``(2N,)``; 0: no unit,
    weights 0).

    After the neuron's spike of step ``s`` the relay fires in step ``s+1``, timer a in
    ``s+1..s+steps``, timer b in ``s+1..s+steps+1`` (:class:`~spll_hw.construction.gate.
    RefractoryTimers`), adding ``r + A + B``, then ``m = A + B`` a step, then ``B``. The held
    part of the current is :data:`HOLD_CURRENT` in step ``s+1`` (``r = 2 - m``); ``m``, about
    ``2a``, keeps it near 2 (within ``|m - 2a| steps``); ``B`` removes what is held in step
    ``s+steps+1``, ``(1 - a) h`` with ``h`` the held part of step ``s+steps``. ``m`` and ``B``
    are multiples of :data:`HOLD_GRID`, so ``r``, ``A = m - B`` and ``B`` are float32 values
    and what the consumers add is exactly what ``h`` was computed from: the current left after
    the hold is at most ``HOLD_GRID / 2`` = 1.2e-7 thresholds, from rounding ``B`` once. ``r``
    is the one of the :data:`HOLD_SEARCH` + 1 float32 values at and below ``2 - m`` (apart by
    ``HOLD_GRID / 2``) that puts ``(1 - a) h`` nearest a multiple of the grid: 3e-11 is left
    in the TDEs' and CCOs' synapses of ``vibtac-time-scaled-peak`` at 1 µs; the search finds
    little where ``(1 - a)^steps`` is within ``2 / HOLD_SEARCH`` of 1 (a hold of 1 step with
    ``a = 1e-4``: 2.7e-8), where the hold is too short to accumulate much either.

    (The weights ``2 (1 - a), 2, -2 (1 - a)``, exact in float64, hold 2 with ``m = 2a``; in
    float32, ``m = 2 - float32(2 (1 - a))`` is off ``2a`` by up to 6e-8, which the hold
    accumulates over its steps: up to 4e-5 thresholds left in a CCO's synapse after each
    spike at 1 µs on ``vibtac-time-scaled-peak`` (709 steps, ``a = 1e-4``), half its offset
    current of 8e-5, and the check 57.9 % off golden instead of 9.3 %.)
    """
    a, steps = np.asarray(a, dtype=float), np.asarray(steps)
    on = steps > 0
    m = np.round(HOLD_CURRENT * a / HOLD_GRID) * HOLD_GRID
    r, b = np.empty_like(m), np.empty_like(m)
    # HOLD_ROWS synapses at a time: each tries HOLD_SEARCH + 1 values (32 kB per synapse per
    # array), so a group of thousands of sPLLs stays within tens of MB.
    for start in range(0, a.size, HOLD_ROWS):
        rows = slice(start, start + HOLD_ROWS)
        r[rows], b[rows] = _hold_relay(a[rows], steps[rows], m[rows])
    return (np.where(on, r, 0.0), np.where(on, m - b, 0.0), np.where(on, b, 0.0))


def _hold_relay(a: np.ndarray, steps: np.ndarray, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`hold_weights`' relay weight ``r`` and timer b's weight ``B`` for synapses that
    keep ``1 - a`` a step, hold ``steps`` and get ``m`` a held step (shape ``(n,)`` each)."""
    # r: 2 - m less k float32 steps of HOLD_GRID / 2 (k = 0..HOLD_SEARCH), shape (n, k).
    r = (HOLD_CURRENT - m)[:, None] - np.arange(HOLD_SEARCH + 1) * (HOLD_GRID / 2)
    # (1 - a) h, h the held part of step s+steps:
    # (1-a)^(steps-1) (r + m) + m (1 - (1-a)^(steps-1)) / a.
    log_kept = (np.maximum(steps - 1, 0) * np.log1p(-a))[:, None]
    removed = (1 - a)[:, None] * (
        np.exp(log_kept) * (r + m[:, None]) - (m / a)[:, None] * np.expm1(log_kept)
    )
    left = removed - np.round(removed / HOLD_GRID) * HOLD_GRID
    k = np.argmin(np.abs(left), axis=1)  # the first r whose removal is nearest the grid
    rows = np.arange(a.size)
    return r[rows, k], -np.round(removed[rows, k] / HOLD_GRID) * HOLD_GRID


def to_standard_nir(
    network: Network,
    options: GateOptions = DEFAULT_GATE,
    *,
    dt: float = DEFAULT_DT,
    refractory: str = "refractory-unit",
) -> StandardNir:
    """The NIR graph of ``network`` from standard nodes (layout in the module docstring),
    written for the step ``dt`` [s], its refractory periods realised as ``refractory`` (one of
    :data:`REFRACTORY`) says; the gate as ``options`` says
    (:class:`~spll_hw.construction.gate.GateOptions`, e.g. ``GateOptions(levels=16)``), placed
    for ``network`` or given.

    Raises:
        ValueError: naming the parameter and the target when the network cannot be
            represented: a refractory realisation not in :data:`REFRACTORY`, a ``dt`` longer
            than every time constant, a gate that does not fit the network, or a parameter the
            construction cannot use (:func:`~spll_hw.construction.gate.target_parameters`).
    """
    nir = nir_package(f"{TARGET} export")
    p, r = target_parameters(network, dt, TARGET), roles()
    if refractory not in REFRACTORY:
        raise ValueError(f"{TARGET}: refractory must be one of {REFRACTORY}, got {refractory!r}")
    longest = max(float(np.max(p[name])) for name in r.time_constants)
    if dt > longest:
        raise ValueError(
            f"{TARGET}: dt = {dt:g} s is longer than every time constant of the network (the "
            f"longest is {longest:g} s): every state would decay to nothing within one step; "
            "use a dt well below the time constants (or no --dt: the export chooses one)"
        )
    gate = options.gate
    if gate is None:
        gate = gate_levels(network, options.levels, options.placement, options.input_rate)
    n, k = network.n_spll, gate.n_levels
    if gate.thresholds.shape[0] != n:
        raise ValueError(f"{TARGET}: gate has {gate.thresholds.shape[0]} sPLLs, network {n}")
    layout = gate_layout(n, k)
    m, spll_of_row = layout.n_and, layout.spll_of_and
    # The gate's rows, the start pulse's and the step guard's fast relay (module docstring).
    size_gate, start, fast = layout.size + 2, layout.size, layout.size + 1
    # Time constants as written: Euler's decay 1 - dt/tau' equals the exact one, e^(-dt/tau).
    tau = {name: dt / decay_fraction(p[name], dt) for name in r.time_constants}
    # A synaptic current [A] as the potential / thr it adds to its membrane over the next
    # step (the exact propagator's k: the consumers add the synapse's value of the step to the
    # membrane, held constant over it, so its value is the step's exact charge).
    k_tde = exact_propagator(p[r.trg.tau], p[r.tde.tau], p[r.tde.c], dt)[1]
    k_cco = exact_propagator(p[r.cco_syn.tau], p[r.cco.tau], p[r.cco.c], dt)[1]
    tde_scale, cco_scale = k_tde / p[r.tde.v_thr], k_cco / p[r.cco.v_thr]
    # The offset [A], a constant current into the CCO's membrane: its exact gain over a step,
    # reached by the synapse's stationary value bias / (1 - e^(-dt/tau_cco_syn)).
    offset_gain = membrane_gain(p[r.cco.tau], p[r.cco.c], dt) / p[r.cco.v_thr]
    tde_rows, cco_rows = np.arange(n), n + np.arange(n)  # rows of the spll node

    # fanout: the spikes (TDEs, then CCOs) to the gate node.
    fanout = np.zeros((size_gate, 2 * n))
    fanout[: layout.size] = np.hstack([layout.from_tde, layout.from_cco])
    # synapses: gate node -> spll node. AND neurons add g_trg * increment to the trigger
    # current; TDE relays add g_cco to the CCO's current; the bias is the CCO's offset. Rows
    # 2N..4N-1 of the spll node are memoryless copies of the timers a (the hold relays).
    synapses = np.zeros((4 * n + 1, size_gate))
    synapses[tde_rows[spll_of_row], np.arange(m)] = (
        (p[r.gated.gain] * tde_scale)[:, None] * gate.increments
    ).reshape(m)
    synapses[cco_rows, layout.relay_tde] = p[r.fed.gain] * cco_scale
    decay_cco_syn = decay_fraction(p[r.cco_syn.tau], dt)
    # The offset's stationary value in the CCO's synapse, reached from the bias; the start
    # pulse (step 1) adds the rest of it to the bias, so the offset drives the membrane fully
    # from the first step, as golden's does.
    offset = p[r.offset] * offset_gain
    bias = np.r_[np.zeros(n), offset * decay_cco_syn, np.zeros(2 * n + 1)]
    synapses[cco_rows, start] = offset - bias[cco_rows]
    # The refractory units (or their stand-in) act on each TDE's and CCO's own synapse.
    units, relays = np.arange(2 * n), np.r_[layout.relay_tde, layout.relay_cco]
    timers = refractory_timers(network, dt)
    kicks = np.zeros((size_gate, 2 * n))  # the spikes -> the timers (in the level node)
    # The spikes are the neurons' spikes but those while their timer a fires (its hold relay).
    suppress = np.hstack([np.eye(2 * n), -2.0 * np.eye(2 * n), np.zeros((2 * n, 1))])
    if refractory == "refractory-unit":
        # The decay per step the consumers compute from the float32 time constants written.
        a = dt / np.float32(np.r_[tau[r.trg.tau], tau[r.cco_syn.tau]]).astype(float)
        relay_w, a_w, b_w = hold_weights(a, timers.steps)
        synapses[units, relays], synapses[units, layout.refr_a] = relay_w, a_w
        synapses[units, layout.refr_b] = b_w
        held = timers.steps > 0
        kicks[layout.refr_a, units] = timers.kick_a
        kicks[layout.refr_b, units] = timers.kick_b
        synapses[2 * n + units, layout.refr_a] = np.where(held, 2.0, 0.0)
    elif refractory == "self-inhibition":
        w = inhibition_weights(network, options.input_rate)
        synapses[tde_rows, layout.relay_tde] = -w["tde"] * dt
        synapses[cco_rows, layout.relay_cco] = -w["cco"] * dt

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

    def memoryless(threshold):
        size = len(threshold)
        return nir.LIF(
            tau=np.full(size, dt), r=np.ones(size), v_leak=np.zeros(size),
            v_threshold=np.asarray(threshold, dtype=float), v_reset=np.zeros(size),
        )  # fmt: skip

    # Level neurons sit in the rows of their AND neurons, the timers in the rows of their
    # relays; the spikes' relays' rows get no input.
    level_weight = np.zeros((size_gate, 1))
    level_weight[:m, 0] = (p[r.driven.gain][:, None] / gate.thresholds).reshape(m)
    level_tau = np.full(size_gate, dt)
    level_tau[:m] = np.repeat(tau[r.fac.tau], k)
    level_tau[layout.refr_a] = level_tau[layout.refr_b] = timers.tau
    level_tau[start] = START_TAU_STEPS * dt
    level_bias = np.zeros(size_gate)
    level_bias[start] = START_DRIVE
    level_bias[fast] = fast_drive()
    # The level node's spikes reach the gate with weight 1 (a level neuron: one of the AND
    # neuron's two inputs) or 2 (a timer: its relay's only input), so that every gate neuron
    # has the threshold 1.5 (snnTorch's import takes one threshold per node).
    level_out = np.ones(size_gate)
    level_out[layout.refr_a] = level_out[layout.refr_b] = 2.0
    level_out[start] = -GATE_GAIN  # the start neuron silences the pulse from step 2 on
    level_out[fast] = GATE_GAIN
    gate_bias = np.zeros(size_gate)
    gate_bias[start] = GATE_GAIN
    # The step guard's latch (the last row of the spll node): a second start pulse or the fast
    # relay fire it, and it every output (mappings.nir.step_guard).
    latch = 4 * n
    synapses[latch, start] = PULSE_WEIGHT
    synapses[latch, fast] = LATCH_WEIGHT
    suppress[:, latch] = OUTPUT_WEIGHT
    nodes = {
        NODE_NAMES["input"]: nir.Input(input_type={"input": np.array([1])}),
        NODE_NAMES["level_input"]: nir.Affine(weight=level_weight, bias=level_bias),
        NODE_NAMES["level"]: cuba(level_tau, np.full(size_gate, dt)),
        NODE_NAMES["level_out"]: nir.Affine(weight=np.diag(level_out), bias=gate_bias),
        NODE_NAMES["gate"]: memoryless(np.full(size_gate, 1.5)),
        NODE_NAMES["synapses"]: nir.Affine(weight=synapses, bias=bias),
        NODE_NAMES["spll"]: cuba(
            np.r_[tau[r.trg.tau], tau[r.cco_syn.tau], np.full(2 * n, dt), LATCH_HOLD_STEPS * dt],
            np.r_[tau[r.tde.tau], tau[r.cco.tau], np.full(2 * n + 1, dt)],
        ),
        NODE_NAMES["refractory"]: nir.Linear(weight=suppress),
        NODE_NAMES["spikes"]: memoryless(np.full(2 * n, 0.5)),
        NODE_NAMES["fanout"]: nir.Linear(weight=fanout),
        NODE_NAMES["kicks"]: nir.Linear(weight=kicks),
        NODE_NAMES["output"]: nir.Output(output_type={"output": np.array([2 * n])}),
    }
    edges = [
        (NODE_NAMES[a], NODE_NAMES[b])
        for a, b in (
            ("input", "level_input"),
            ("level_input", "level"),
            ("level", "level_out"),
            ("level_out", "gate"),
            ("gate", "synapses"),
            ("synapses", "spll"),
            ("spll", "refractory"),
            ("refractory", "spikes"),
            ("spikes", "fanout"),
            ("fanout", "gate"),
            ("spikes", "kicks"),
            ("kicks", "level"),
            ("spikes", "output"),
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
        "step_guard": STEP_GUARD.format(dt=dt, tolerance=STEP_TOLERANCE),
    }
    graph = nir.NIRGraph(nodes=as_imported(nodes), edges=edges, metadata=metadata)
    return StandardNir(graph, network, gate, float(dt), refractory)
