"""The multichannel network's spiking readout as a NIR graph of standard nodes only, for clocked
consumers (snnTorch, Norse, spll-hw's executor :mod:`mappings.nir.executor`).

The readout (:mod:`spll_hw.multichannel.readout`): ``S`` stages (a ``Readout`` is one, switched
on at 0 s) of ``k`` classes over ``d`` TDEs; class ``j`` of stage ``s`` has the membrane
``v_sj(t) = sum_i w_sji N_i(t) + beta_sj t`` [score x s]; stage ``s`` is on over
``[max(starts[s], not_before), starts[s + 1]]`` (the last to the run's end); the first membrane
of a stage that is on to reach ``theta`` decides, one that reached it before its stage was
switched on decides at the switch-on; none: the last stage's largest membrane at the end. The
graph evaluates that rule at the step ends of a clock of ``dt`` [s], on TDE spikes binned by the
grid rule (a spike at ``t`` counts in step ``max(1, ceil(t/dt))``, at its end ``n dt``). Node
names are prefixed so that their alphabetical order is the execution order::

    a_input (Input d) ─> b_readout (Affine R×d, bias) ─> c_cells (CubaLIF R)
    c_cells ─> d_pick (Affine E×R, bias) ─> e_relay (LIF E) ─> g_output (Output E)
    e_relay ─> f_switch (Linear R×E) ─> c_cells                    (closes the loop)

``c_cells`` (``R = 3 S k + S + 2 + C`` rows, :class:`Layout`), every row a CubaLIF with a
memoryless synapse (``tau_syn = dt``, ``w_in = 1``: ``I = x``) and a membrane without leak
(``tau_mem = 2**60 dt``, :data:`MEMBRANE_STEPS`; ``r = tau_mem / dt``: ``v <- v + I``),
threshold 1, reset to 0:

* *crossing rows* ``P`` (``S k``, stage-major, row ``s k + j``): the membrane ``v_sj / theta``
  (input weights ``w / theta``, bias ``beta dt / theta`` a step); it spikes in the step whose end
  it passes 1, the membrane after the step's TDE spikes.
* *ramp rows* ``P'`` (``S k``): the same plus ``beta dt / theta`` (bias ``2 beta dt / theta``,
  less ``beta dt / theta`` a step from the always row from step 2 on): it spikes in step ``n``
  where the membrane reaches theta along its ramp in step ``n + 1``, before that step's TDE
  spikes, which may take it back below.
* *latches* ``Q`` (``S k``): kicked by their ``P`` or ``P'`` (one step later, through the loop)
  and then by themselves: they spike in every step after their membrane reached theta.
* *windows* ``W`` (``S``): stage ``s``'s spikes in every step in which it is on, from step
  ``first_s`` (kicked by the starter or a counter one step earlier, or from step 1 by a bias)
  through ``last_s`` (the next stage's window sends ``-KILL`` from then on).
* the *always* row (bias 1.5: it spikes in every step), the *starter* (bias 1.5, less 1.5 a step
  from the always row: it spikes in step 1 only) and one *counter* per stage switched on in step
  3 or later: bias :data:`COUNT_STEP` (``2**-22``) a step and, from the starter in step 2, the
  offset ``1 + 2**-23 - m 2**-22`` so that it passes 1 in exactly step ``m`` (every value a
  multiple of ``2**-23`` below 2 in magnitude: float32 consumers count exactly); then it sends
  itself ``-KILL``.

``e_relay`` (``E = S k + R`` rows, memoryless LIF: ``tau = dt``, ``r = 1``, threshold 0.5): the
*decision rows* ``O`` first (``S k``, row ``s k + j``), ``2 W_s + P_sj + Q_sj - 2`` (through
``d_pick``'s weights and bias): class ``j`` of stage ``s`` spikes in a step in which its stage is
on and its membrane has reached theta (in the step or before: a membrane above it at switch-on
decides then); then one relay per row of ``c_cells``, repeating its spikes in the same step. The
output is ``e_relay``: the decision rows, then ``c_cells``' spikes. The loop (``f_switch``)
delivers the relays' spikes of the previous step to ``c_cells``.

Why not the membranes switched by offsets (a decision row held at ``v - H`` while its stage is
off): a float32 membrane near ``-H`` rounds every step's increment to ``ulp(H)``, the same way
every step (``H = 64``: steps of ``2**-17``, against increments ``beta dt / theta`` near
``1e-4``), so its crossing drifts by many steps; here every membrane is the readout's own,
from 0, and the switching is logic on exact values.

What the graph does not do: a consumer takes the first step in which a decision row spikes and
settles that step from the input counts (the earlier stage, the earlier crossing in the step, the
larger membrane, the lower class); where none spikes, the last stage's largest membrane at the end
decides. ``mappings/nir/standalone_decide.py`` (numpy only, copied into export folders as
``decide.py``) does both. The graph sums a step's TDE spikes into one jump: where spikes of two
TDEs fall into one step, spll-hw's reference passes them one at a time (TDE order) and can
reach theta between them, which the graph does not see.

**Float32 consumers** (Norse, snnTorch) round each step's sum ``v + I`` to float32: over
thousands of steps a membrane drifts by up to about 1e-4 of theta, so where it creeps up to
theta (by some 1e-5 of it a step) its crossing moves by a few steps. Measured on 800 runs of
0.5 s at 100 µs (5 classes, 10 TDEs, single and 3-stage readouts, thresholds 0.05-0.4 and inf),
Norse 1.1 and snnTorch 1.0 spiked alike and decided as spll-hw's executor (float64) in 799 (the
other: the same class 7 steps early); Norse at 50 µs in 231 of 240 (the others: the same class,
1-8 steps off). A float32 emulation of ``v <- v + I`` moves those decisions alike.

Every consumer runs the graph alike: every node has one input but ``c_cells``, whose second
arrives through the loop (the previous step's); ``c_cells`` holds one time constant of each kind
and one threshold (snnTorch's import takes one per node) and the loop is four nodes long (its
import rewrites two-node LIF/dense cycles into recurrent cells). The graph is written for one
``dt``: snnTorch runs it at 100 µs only.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from spll_hw.multichannel.readout import START, Readout, StagedReadout

from .files import as_imported, nir_package
from .standalone_decide import Windows, save_readout, stage_windows

#: ``metadata["format"]`` of the graph.
FORMAT = "spll-hw multichannel spiking readout, NIR standard nodes v1"
#: Node names in execution order (alphabetical).
NODE_NAMES = {
    "input": "a_input",
    "readout": "b_readout",
    "cells": "c_cells",
    "pick": "d_pick",
    "relay": "e_relay",
    "switch": "f_switch",
    "output": "g_output",
}
#: The membranes' time constant [steps of dt]: no leak, and exactly ``v <- v + I`` in float32
#: consumers too: ``r = 2**60`` and ``dt / tau_mem = 2**-60`` scale by powers of two, and
#: ``r I`` dwarfs ``v`` in Norse's ``dt (1/tau_mem) (r I + v_leak - v)``, so the product is ``I``
#: (with ``1e12`` s instead, it was ``I`` to 1e-7 relative: a counter's offset near 1 then came
#: out a few ulps off, and Norse switched a stage on a step late). Exact where
#: ``float32(dt) * float32(1/float32(dt))`` rounds to 1 (1e-3, 1e-4, 5e-5, 1e-5 s); elsewhere an
#: ulp off, within a counter's margin of half a count step.
MEMBRANE_STEPS = 2.0**60
#: A counter's increment a step: its values stay multiples of 2**-23 (exact in float32).
COUNT_STEP = 2.0**-22
#: The latest step a counter can fire in (its offset stays above -1): a stage can be switched
#: on up to step ``MAX_COUNT + 1`` (839 s at 100 µs); the run itself is not limited.
MAX_COUNT = 2**23
#: A kick that makes a row spike in the step it arrives (threshold 1), and a row's self-kick.
KICK = 1.5
#: What silences a row for good (a window switched off, a counter that fired).
KILL = 2.0**20
#: The relays' threshold (spikes of 0 or 1 and the decision rows' 0, 1 or 2 against <= 0).
RELAY_THRESHOLD = 0.5


@dataclass(frozen=True)
class Layout:
    """Rows of ``c_cells`` and of ``e_relay`` (the output) of a graph of ``stages`` stages of
    ``classes`` classes over ``tdes`` TDEs; ``counters``: the step each counter fires in."""

    stages: int
    classes: int
    tdes: int
    counters: tuple[int, ...]

    @property
    def sk(self) -> int:
        """Decision neurons, ``S k``."""
        return self.stages * self.classes

    def crossing(self, s: int, j: int) -> int:
        """Row of ``c_cells``: class ``j`` of stage ``s``'s membrane (crossing row)."""
        return s * self.classes + j

    def ramp(self, s: int, j: int) -> int:
        """Row of ``c_cells``: its ramp row (the membrane one ramp step ahead)."""
        return self.sk + self.crossing(s, j)

    def latch(self, s: int, j: int) -> int:
        """Row of ``c_cells``: its latch (spikes in every step after the crossing)."""
        return 2 * self.sk + self.crossing(s, j)

    def window(self, s: int) -> int:
        """Row of ``c_cells``: stage ``s``'s window."""
        return 3 * self.sk + s

    @property
    def always(self) -> int:
        """Row of ``c_cells`` that spikes in every step."""
        return 3 * self.sk + self.stages

    @property
    def starter(self) -> int:
        """Row of ``c_cells`` that spikes in step 1 only."""
        return self.always + 1

    def counter(self, c: int) -> int:
        """Row of ``c_cells``: counter ``c`` (it fires in step ``counters[c]``)."""
        return self.starter + 1 + c

    @property
    def cells(self) -> int:
        """Rows of ``c_cells``, ``R``."""
        return self.starter + 1 + len(self.counters)

    @property
    def outputs(self) -> int:
        """Rows of ``e_relay`` and of the output, ``E = S k + R``: the decision rows, then one
        relay per row of ``c_cells``."""
        return self.sk + self.cells

    def relay(self, row: int) -> int:
        """Row of ``e_relay`` (and of the output) that repeats ``c_cells``' row ``row``."""
        return self.sk + row

    def describe(self) -> dict:
        """The output rows by role, ``[first, end)`` ranges (graph metadata)."""
        r = lambda a, b: [self.relay(a), self.relay(b)]  # noqa: E731
        return {
            "decision": [0, self.sk],
            "crossing": r(0, self.sk),
            "ramp": r(self.sk, 2 * self.sk),
            "latch": r(2 * self.sk, 3 * self.sk),
            "window": r(3 * self.sk, 3 * self.sk + self.stages),
            "always": r(self.always, self.always + 1),
            "starter": r(self.starter, self.starter + 1),
            "counter": r(self.starter + 1, self.cells),
        }


@dataclass(frozen=True)
class ReadoutArrays:
    """A readout as arrays: ``weights`` ``(S, k, d)`` [score x s per spike], ``bias``
    ``(S, k)`` [score], ``starts`` ``(S,)`` [s] (a single readout: ``(0.0,)``), the ``k``
    ``class_names``."""

    weights: np.ndarray
    bias: np.ndarray
    starts: np.ndarray
    class_names: tuple[str, ...]

    @classmethod
    def of(cls, readout: Readout | StagedReadout) -> ReadoutArrays:
        """The arrays of a ``Readout`` (one stage from 0 s) or ``StagedReadout``."""
        if isinstance(readout, StagedReadout):
            return cls(
                readout.weights.astype(float),
                np.stack([r.bias for r in readout.stages]).astype(float),
                np.asarray(readout.starts, float),
                readout.class_names,
            )
        if isinstance(readout, Readout):
            return cls(
                np.asarray(readout.weights, float)[None],
                np.asarray(readout.bias, float)[None],
                np.zeros(1),
                readout.class_names,
            )
        raise ValueError(
            f"readout must be a Readout or StagedReadout, got {type(readout).__name__}"
        )


def switch_steps(starts, not_before: float, dt: float) -> Windows:
    """The stages' windows [steps] (:func:`.standalone_decide.stage_windows`) after checking
    ``dt`` and ``not_before``; ``ValueError`` naming the parameter where ``dt`` is not a finite
    time > 0, ``not_before`` not a finite time >= 0, or a stage is switched on after step
    ``MAX_COUNT + 1`` (the counters' limit, :func:`latest_switch`)."""
    if not (math.isfinite(float(dt)) and dt > 0):
        raise ValueError(f"dt must be a finite time > 0 s, got {dt!r}")
    if not (math.isfinite(not_before) and not_before >= 0):
        raise ValueError(f"not_before must be a finite time >= 0 s, got {not_before!r}")
    windows = stage_windows(starts, not_before, dt)
    late = windows.first[~windows.empty].max(initial=1)
    if late > MAX_COUNT + 1:
        raise ValueError(
            f"starts/not_before: a stage is switched on in step {late} at dt = {dt!r} s; the "
            f"graph's counters count to step {MAX_COUNT + 1} ({latest_switch(dt):g} s)"
        )
    return windows


def write_readout(
    path, readout: Readout | StagedReadout, threshold: float, dt: float, not_before: float = START
):
    """Write ``readout``'s arrays with ``threshold`` [score x s], ``dt`` [s] and ``not_before``
    [s] to ``path`` (``readout.npz``, :func:`.standalone_decide.save_readout`: what ``decide.py``
    needs beside the graph's output and input). Returns the path."""
    a = ReadoutArrays.of(readout)
    return save_readout(path, a.weights, a.bias, a.starts, threshold, dt, not_before, a.class_names)


def latest_switch(dt: float) -> float:
    """The latest time [s] at which the graph at step ``dt`` [s] can switch a stage on (or
    start deciding, ``not_before``): the end of step ``MAX_COUNT + 1``. The run itself may be
    longer."""
    return (MAX_COUNT + 1) * dt


def to_readout_nir(
    readout: Readout | StagedReadout,
    threshold: float,
    dt: float,
    not_before: float = START,
):
    """The ``nir.NIRGraph`` of ``readout`` deciding at ``threshold`` [score x s] (``inf``: the
    end decides) no earlier than ``not_before`` [s], clocked at ``dt`` [s] (module docstring).
    Input: the ``d`` TDE spike counts of each step, shape ``(d,)`` a step; output: ``E`` spikes
    a step (:class:`Layout`; metadata ``rows``), the ``S k`` decision rows first.

    Raises:
        ValueError: naming the parameter: a ``threshold`` not > 0, non-finite ``weights`` or
            ``bias``, a ``dt`` not a finite time > 0, a ``not_before`` < 0, or a stage switched
            on later than the counters count (:func:`switch_steps`).
    """
    nir = nir_package("readout NIR graph")
    arrays = ReadoutArrays.of(readout)
    theta = float(threshold)
    if not theta > 0:
        raise ValueError(f"threshold must be > 0 (score x s), got {threshold!r}")
    for name in ("weights", "bias"):
        if not np.all(np.isfinite(getattr(arrays, name))):
            raise ValueError(f"readout {name} must be finite")
    windows = switch_steps(arrays.starts, float(not_before), dt)
    n_stages, k, d = arrays.weights.shape
    kicked = [s for s in range(n_stages) if not windows.empty[s] and windows.first[s] >= 3]
    layout = Layout(n_stages, k, d, tuple(int(windows.first[s]) - 1 for s in kicked))
    weight_in, bias_in, loop = _cells(arrays, theta, dt, windows, layout, kicked)
    pick, pick_bias = _pick(layout)
    size, out = layout.cells, layout.outputs
    nodes = {
        NODE_NAMES["input"]: nir.Input(input_type={"input": np.array([d])}),
        NODE_NAMES["readout"]: nir.Affine(weight=weight_in, bias=bias_in),
        NODE_NAMES["cells"]: nir.CubaLIF(
            tau_syn=np.full(size, float(dt)),
            tau_mem=np.full(size, MEMBRANE_STEPS * dt),
            r=np.full(size, MEMBRANE_STEPS),
            v_leak=np.zeros(size),
            v_threshold=np.ones(size),
            v_reset=np.zeros(size),
            w_in=np.ones(size),
        ),
        NODE_NAMES["pick"]: nir.Affine(weight=pick, bias=pick_bias),
        NODE_NAMES["relay"]: nir.LIF(
            tau=np.full(out, float(dt)),
            r=np.ones(out),
            v_leak=np.zeros(out),
            v_threshold=np.full(out, RELAY_THRESHOLD),
            v_reset=np.zeros(out),
        ),
        NODE_NAMES["switch"]: nir.Linear(weight=loop),
        NODE_NAMES["output"]: nir.Output(output_type={"output": np.array([out])}),
    }
    edges = [
        (NODE_NAMES[a], NODE_NAMES[b])
        for a, b in (
            ("input", "readout"),
            ("readout", "cells"),
            ("cells", "pick"),
            ("pick", "relay"),
            ("relay", "switch"),
            ("switch", "cells"),
            ("relay", "output"),  # last: Norse returns the value of the node it runs last
        )
    ]
    metadata = _metadata(arrays, theta, dt, float(not_before), windows, layout)
    return nir.NIRGraph(nodes=as_imported(nodes), edges=edges, metadata=metadata)


def _cells(arrays: ReadoutArrays, theta, dt, windows: Windows, layout: Layout, kicked):
    """``b_readout``'s weight ``(R, d)`` and bias ``(R,)`` and ``f_switch``'s weight ``(R, E)``
    (module docstring)."""
    w, beta = arrays.weights, arrays.bias
    n_stages, k, d = w.shape
    size = layout.cells
    weight_in, bias_in = np.zeros((size, d)), np.zeros(size)
    loop = np.zeros((size, layout.outputs))

    def to(row: int, source: int, value: float) -> None:  # c_cells row <- source's spike
        loop[row, layout.relay(source)] += value

    scale = 0.0 if math.isinf(theta) else 1.0 / theta  # inf: the membranes never rise
    for s in range(n_stages):
        for j in range(k):
            p, q, ramp = layout.crossing(s, j), layout.latch(s, j), layout.ramp(s, j)
            weight_in[[p, ramp]] = w[s, j] * scale
            bias_in[p] = beta[s, j] * dt * scale
            bias_in[ramp] = 2 * beta[s, j] * dt * scale
            to(ramp, layout.always, -beta[s, j] * dt * scale)
            for source in (p, ramp, q):
                to(q, source, KICK)
        win = layout.window(s)
        to(win, win, KICK)
        if s + 1 < n_stages:
            to(win, layout.window(s + 1), -KILL)
    for s in range(n_stages):
        if windows.empty[s]:
            continue
        if windows.first[s] == 1:
            bias_in[layout.window(s)] = KICK
        elif windows.first[s] == 2:
            to(layout.window(s), layout.starter, KICK)
    for c, (s, m) in enumerate(zip(kicked, layout.counters, strict=True)):
        row = layout.counter(c)
        bias_in[row] = COUNT_STEP
        to(row, layout.starter, 1.0 + COUNT_STEP / 2 - m * COUNT_STEP)
        to(row, row, -KILL)
        to(layout.window(s), row, KICK)
    bias_in[layout.always] = KICK
    bias_in[layout.starter] = KICK
    to(layout.starter, layout.always, -KICK)
    return weight_in, bias_in, loop


def _pick(layout: Layout) -> tuple[np.ndarray, np.ndarray]:
    """``d_pick``'s weight ``(E, R)`` and bias ``(E,)``: the decision rows
    ``2 W + P + Q - 2``, then a copy of every row of ``c_cells``."""
    pick = np.zeros((layout.outputs, layout.cells))
    bias = np.zeros(layout.outputs)
    for s in range(layout.stages):
        for j in range(layout.classes):
            o = layout.crossing(s, j)
            pick[o, layout.window(s)] = 2.0
            pick[o, layout.crossing(s, j)] = 1.0
            pick[o, layout.latch(s, j)] = 1.0
            bias[o] = -2.0
    pick[layout.sk + np.arange(layout.cells), np.arange(layout.cells)] = 1.0
    return pick, bias


#: What the graph's metadata says a consumer must do outside the graph.
DECISION_RULE = (
    "output rows 0..S*k-1 are the decision neurons, stage-major (row s*k+j: class j of stage "
    "s); one spikes in a step in which its stage is on once its membrane w_sj.N + beta_sj*t has "
    "reached the threshold, in that step or before (before the switch-on: it decides at the "
    "switch-on). Take the first step in which a decision row spikes; settle a step with several "
    "from the input counts: the earlier stage first (two stages are on in the step of a switch; "
    "one switched off within the step counts where its crossing came before its end), then the "
    "earlier crossing within the step (membranes rise by beta between step ends, TDE spikes "
    "jump at step ends), then the larger membrane, then the lower class. No decision row spikes "
    "in the run: the last stage's largest membrane w.N(T) + beta*T*dt at the end decides "
    "(fired = false). standalone_decide.py (decide.py in an export folder) does this with numpy"
)


def _metadata(arrays, theta, dt, not_before, windows: Windows, layout: Layout) -> dict:
    s, k, d = arrays.weights.shape
    return {
        "format": FORMAT,
        "dt": float(dt),
        "spike_size": "a spike is 1 in the time step it happens (a pulse of height 1 for dt)",
        "inputs": f"input[i] = spikes of TDE i in the step (d = {d}), binned at max(1, ceil(t/dt))",
        "outputs": (
            f"output[:{layout.sk}] = decision neurons (stage-major, {s} stages x {k} classes); "
            f"output[{layout.sk}:] = the spikes of c_cells' {layout.cells} rows (metadata rows)"
        ),
        "rows": json.dumps(layout.describe()),
        "decision": DECISION_RULE,
        "threshold": float(theta),
        "not_before": float(not_before),
        "starts": np.asarray(arrays.starts, float),
        "stage_steps": json.dumps(
            [
                [int(a), int(b) if b < 2**62 else None] if not e else None
                for a, b, e in zip(windows.first, windows.last, windows.empty, strict=True)
            ]
        ),
        "classes": json.dumps(list(arrays.class_names)),
        "n_stages": int(s),
        "n_classes": int(k),
        "n_tdes": int(d),
    }
