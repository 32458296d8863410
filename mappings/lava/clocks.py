"""A clock per set of sPLLs: the standard sPLL on Loihi's integers with every sPLL at the step
that holds its refractory period in exactly ``R + 1/2`` steps (``spll-hw export --to
lava-standard``'s last rung, :mod:`mappings.lava.dt_choice`; backends ``standard-fixed-point``
and ``lava-standard`` with ``clock=per-spll``).

One Loihi step cannot hold a time-scaled network: a step fine enough for its fast sPLLs'
refractory periods leaves its slow sPLLs' long time constants few of the 12 decay bits
(docs/backends.md, the lava-standard table). A time-scaled sPLL is its base sPLL with every
time constant scaled by one factor, so at a step scaled alike it has the base sPLL's integers.
:func:`clocked_standard` writes each set of sPLLs that share a step
(:func:`spll_steps`: ``dt_i = min(t_tde_refr, t_cco_refr)_i / (R + 1/2)``, at which the
compensated hold of ``round(t_refr/dt - 1/2) = R`` steps is exact on average) as its own
:class:`~mappings.lava.standard.LavaStandard` at that step, with its rows of the whole
network's gate; :func:`run_clocked` runs each part by :func:`~mappings.lava.loihi.run_trains`
on the input binned at its own step. A vary-offset network is one part: one step for all.
:meth:`ClockedStandard.arrays` is the folder's ``params.npz`` (each clock's integers under
``clock<c>.``, read by the folder's ``run.py``, :func:`~mappings.lava.standalone_run.load_clocks`),
:meth:`ClockedStandard.info` its ``standard.json`` and :meth:`ClockedStandard.readme` its README.

On a chip this is one network on one clock run offline: each part's input ring buffer holds the
recording binned at its own step, and its counts are its spikes in its first ``T / dt`` steps;
it is not a real-time stream. Measured on the four presets ``lava-standard`` refuses:
``benchmarks/bench_clock_per_spll.py`` and docs/backends.md.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from spll_hw.construction.gate import Gate, GateOptions, gate_levels
from spll_hw.network import Network
from spll_hw.neuron_graph import COUNTS_KEY
from spll_hw.params import PARAM_NAMES
from spll_hw.result import SimulationResult
from spll_hw.simulate import as_network

from .integers import spll_ranges
from .loihi import run_trains
from .standard import (
    CHECK_SECTION,
    CURRENT_WORDS,
    HOLD_WORDS,
    NEEDS,
    LavaStandard,
    cost_words,
    difference,
    gate_info,
    lava_standard,
)

#: The lava-standard backends' ``clock`` option: one step for all sPLLs, or one per sPLL.
CLOCKS = ("one", "per-spll")
#: Refractory steps of every sPLL (``R``): within 7 % on ``biotac-time-scaled-pacinian`` and
#: ``-peak`` at every ``R`` from 3 to 8 (docs/backends.md); 4 is the closest on both.
DEFAULT_HOLDS = 4
#: The gate: 32 levels on the network's band (``lava-standard``'s finest export gate).
DEFAULT_LEVELS = 32
DEFAULT_PLACEMENT = "band-quantile"
#: :func:`clocked_standard`'s gate where none is asked for.
CLOCKED_GATE = GateOptions(DEFAULT_LEVELS, DEFAULT_PLACEMENT)


def spll_steps(network: Network, holds: float = DEFAULT_HOLDS) -> np.ndarray:
    """Each sPLL's step [s], shape ``(N,)``: its shorter refractory period (TDE or CCO) in
    ``holds + 1/2`` steps.

    Raises:
        ValueError: where ``holds`` is under 2 (Loihi's refractory unit holds 2 or more steps).
    """
    if not holds >= 2:
        raise ValueError(
            f"holds = {holds!r}: the refractory unit holds 2 or more steps (use holds >= 2)"
        )
    p = dict(zip(PARAM_NAMES, network.matrix().T, strict=True))
    return np.minimum(p["t_tde_refr"], p["t_cco_refr"]) / (holds + 0.5)


class ClockPart(NamedTuple):
    """One set of sPLLs at one step: ``spll``, their numbers in the network, shape ``(n,)``,
    ascending; ``params``, their integers at step ``params.dt`` [s] (sPLL ``k`` of them is the
    network's ``spll[k]``)."""

    spll: np.ndarray
    params: LavaStandard


def sub_network(network: Network, spll: np.ndarray) -> Network:
    """The sPLLs ``spll`` (numbers in ``network``) as a network of their own."""
    return Network.from_matrix(network.matrix()[spll], layout=network.layout)


#: What a clocked folder is on a chip (its README and ``standard.json``).
OFFLINE = (
    "one network on one clock, run offline: each set of sPLLs' input ring buffer holds the "
    "recording binned at that set's own step, and its counts are its spikes in its first "
    "round(T / dt) steps; its spikes are not in the recording's time, so it computes the "
    "features of recorded inputs, not of a live stream"
)

#: The folder's ``README.md`` (:meth:`ClockedStandard.readme` fills it in).
README = """# sPLL network on Lava's own processes, a clock per set of sPLLs

{n} sPLLs as the standard-neuron construction ({k} gate levels) on `lava.proc.lif` LIF,
`lava.proc.dense` Dense and `lava.proc.io` ring buffers, with their bit-accurate fixed-point
models; {hold}.{graded}
Each sPLL runs at its own step, the one that holds its shorter refractory period (TDE or
CCO) in {r:g} steps and a half: `dt = min(t_tde_refr, t_cco_refr) / {r2:g}`,
{span} (table below), so that every sPLL has the integers of one
step of Loihi's 12-bit decays.

{offline}

{needs}

    python run.py spikes.npy 1.0     # input spike times [s] (.npy), duration [s]

prints JSON with `tde_counts` and `cco_counts` per sPLL and each sPLL's `dt` and `steps`.
`params.npz`: the integers of each clock `c` under `clock<c>.` (`dt`; `spll`: its sPLLs;
`lif.POP.*`: du, dv, vth, bias_mant, bias_exp; `dense.NAME.weights` / `.meta`: source,
target, weight_exp, num_message_bits; `members.POP`: the sPLLs, numbered in the whole network);
`standard.json`: what they stand for; `spll_grid.py`: the step each input spike counts in
(spll-hw's grid rule).

| sPLLs | dt [µs] | steps in 1 s | Lava processes |
|---|---|---|---|
{table}

`run.py` runs the independent parts of all clocks, `--jobs` at a time (a worker process
each), at most {most} Lava processes in a part (run.py puts the populations that share `du`,
`dv` and `vth` in one LIF process, and the synapses between the same two with the same
`weight_exp` and sign in one Dense). {cost}
{notes}
{check}"""


@dataclass(frozen=True)
class ClockedStandard:
    """The integers of a network whose sets of sPLLs run at their own steps.

    Attributes:
        parts: the sets, in the order of their step, coarsest first.
        n_spll: N.
        holds: ``R``, every sPLL's refractory steps.
        gate: the whole network's gate (each part has its rows).
    """

    parts: tuple[ClockPart, ...]
    n_spll: int
    holds: float
    gate: Gate

    @property
    def steps(self) -> np.ndarray:
        """Each sPLL's step [s], shape ``(N,)``."""
        out = np.zeros(self.n_spll)
        for part in self.parts:
            out[part.spll] = part.params.dt
        return out

    @property
    def levels(self) -> int:
        return self.parts[0].params.levels

    @property
    def hold(self) -> str:
        return self.parts[0].params.hold

    @property
    def current(self) -> str:
        return self.parts[0].params.current

    @property
    def n_processes(self) -> int:
        """Lava processes of all clocks in the exported ``run.py``."""
        return sum(part.params.n_processes for part in self.parts)

    def open_loop(self) -> np.ndarray:
        """The sPLLs whose CCO gets nothing from its TDE at their clock's step, numbered in the
        whole network, sorted, shape ``(k,)``: each clock's own
        (:meth:`LavaStandard.open_loop`), so that the export check's per-sPLL verdict judges a
        clock per sPLL as it judges one step."""
        found = [part.spll[part.params.open_loop()] for part in self.parts]
        return np.sort(np.concatenate([np.zeros(0, dtype=int), *found])).astype(int)

    def arrays(self) -> dict[str, np.ndarray]:
        """Flat ``name -> array`` form (the folder's ``params.npz``): ``n_spll``, ``clocks``,
        ``holds`` and each clock ``c``'s :meth:`LavaStandard.arrays` under ``clock<c>.``, with
        its ``spll`` and its ``members`` numbered in the whole network."""
        out = {"n_spll": np.array(self.n_spll), "clocks": np.array(len(self.parts)),
               "holds": np.array(self.holds)}  # fmt: skip
        for c, part in enumerate(self.parts):
            out[f"clock{c}.spll"] = np.asarray(part.spll)
            for key, value in part.params.arrays().items():
                if key != "n_spll":
                    whole = part.spll[value] if key.startswith("members.") else value
                    out[f"clock{c}.{key}"] = np.asarray(whole)
        return out

    def info(self) -> dict:
        """The folder's ``standard.json``: the gate, ``R``, and each clock's step, sPLLs,
        populations and notes (which number sPLLs among the clock's own)."""
        clocks = []
        for part in self.parts:
            info = part.params.info()
            keep = ("populations", "lava_processes", "notes")
            clocks.append({"dt": info["dt"], "spll": part.spll.tolist()}
                          | {k: info[k] for k in keep})  # fmt: skip
        return {
            "clock": "per-spll",
            "holds": self.holds,
            "offline": OFFLINE,
            **gate_info(self.n_spll, self.levels, self.gate, self.hold, self.current),
            "lava_processes": self.n_processes,
            "clocks": clocks,
        }

    def difference(self, other) -> str | None:
        """Where these integers first differ from ``other``'s (as
        :meth:`LavaStandard.difference`), or ``None`` where they are the same."""
        if not isinstance(other, ClockedStandard):
            return "a clock per set of sPLLs against one clock"
        return difference(self, other)

    def readme(self) -> str:
        """The folder's ``README.md``: what it holds, each clock's step, how to run it."""
        rows, sizes, neurons, per_second = [], [], [], []
        for part in self.parts:
            these = part.params.part_processes()
            dt = part.params.dt
            rows.append(f"| {spll_ranges(part.spll)} | {dt * 1e6:.4g} | "
                        f"{round(1 / dt)} | {sum(these)} |")  # fmt: skip
            sizes += these
            neurons += part.params.part_neurons()
            per_second += [round(1 / dt)] * len(these)
        notes = "".join(
            f"\n* the clock of {spll_ranges(part.spll)} (numbering its own from 0): {note}"
            for part in self.parts
            for note in part.params.notes
        )
        steps = self.steps * 1e6
        return README.format(
            n=self.n_spll, k=self.levels, hold=HOLD_WORDS[self.hold], r=self.holds,
            graded=CURRENT_WORDS[self.current],
            r2=self.holds + 0.5, span=_span(steps, len(self.parts)), needs=NEEDS,
            offline=textwrap.fill(f"**Offline, not real time.** On a chip this is {OFFLINE}.",
                                  width=92),
            table="\n".join(rows), most=max(sizes), cost=cost_words(sizes, neurons, per_second),
            notes=f"\nWhat the integers leave out:\n{notes}\n" if notes else "",
            check=CHECK_SECTION,
        )  # fmt: skip


def _span(steps: np.ndarray, n: int) -> str:
    """``n`` clocks of ``steps`` [µs] in words: ``one step, 222 µs`` or ``50 clocks, from
    16.6 to 253 µs``."""
    if n == 1:
        return f"one step, {steps[0]:.3g} µs"
    return f"{n} clocks, from {steps.min():.3g} to {steps.max():.3g} µs"


def clocked_standard(
    network: Network, holds: float = DEFAULT_HOLDS, options: GateOptions = CLOCKED_GATE, **choices
) -> ClockedStandard:
    """``network`` on Loihi's integers, each set of sPLLs at its step of :func:`spll_steps`
    (``holds`` refractory steps), with the gate ``options`` say
    (:class:`~spll_hw.construction.gate.GateOptions`, by default :data:`CLOCKED_GATE`) placed
    on the whole network (or given); each set written by
    :func:`~mappings.lava.standard.lava_standard` with ``choices``, its refractory ``hold`` and
    CCO ``current`` by name.

    Raises:
        ValueError: ``network`` not a :class:`~spll_hw.network.Network` (or one sPLL's
            parameters), ``holds`` under 2, or :func:`~mappings.lava.standard.lava_standard`'s
            refusal of a part, prefixed with the network's numbers of its sPLLs.
    """
    if extra := sorted(choices.keys() - {"hold", "current"}):
        raise TypeError(f"clocked_standard takes a hold and a current, not {extra}")
    network = as_network(network)
    steps = spll_steps(network, holds)
    gate = options.gate
    if gate is None:
        gate = gate_levels(network, options.levels, options.placement, options.input_rate)
    parts = []
    for dt in np.unique(steps)[::-1]:
        idx = np.flatnonzero(steps == dt)
        part = sub_network(network, idx)
        rows = Gate(gate.thresholds[idx], gate.increments[idx], gate.placement, gate.input_rates)
        try:
            params = lava_standard(part, GateOptions(gate=rows), dt=float(dt), **choices)
        except ValueError as exc:
            raise ValueError(
                f"the network's sPLLs {idx.tolist()} at their step dt = {dt:g} s (numbered from 0 "
                f"among them below): {exc}"
            ) from exc
        parts.append(ClockPart(idx, params))
    return ClockedStandard(tuple(parts), network.n_spll, float(holds), gate)


def run_integers(
    params: LavaStandard | ClockedStandard,
    trains,
    duration: float,
    backend: str,
    record_spikes: bool = False,
) -> list[SimulationResult]:
    """Every train through Loihi's integers ``params``: :func:`run_clocked` where each set of
    sPLLs has its own clock, else :func:`~mappings.lava.loihi.run_trains` at their one step."""
    run = run_clocked if isinstance(params, ClockedStandard) else run_trains
    return run(params, trains, duration, backend, record_spikes)


def run_clocked(
    clocked: ClockedStandard,
    trains,
    duration: float,
    backend: str = "standard-fixed-point",
    record_spikes: bool = False,
) -> list[SimulationResult]:
    """Every train (sorted input spike times [s]) for ``duration`` [s] through every part at
    its own step (:func:`~mappings.lava.loihi.run_trains`); one result per train,
    ``info["dt"]`` each sPLL's step [s], with ``record_spikes`` each sPLL's spike times (a
    spike in step ``k`` of its own clock at ``k dt``)."""
    trains = list(trains)
    n = clocked.n_spll
    tde = np.zeros((len(trains), n), np.int64)
    cco = np.zeros_like(tde)
    spikes = [([None] * n, [None] * n) for _ in trains]
    neurons: list[list[np.ndarray]] = [[] for _ in trains]  # every neuron's, part by part
    for part in clocked.parts:
        runs = run_trains(part.params, trains, duration, backend, record_spikes)
        for b, res in enumerate(runs):
            tde[b, part.spll], cco[b, part.spll] = res.tde_counts, res.cco_counts
            neurons[b].append(res.info[COUNTS_KEY])
            if record_spikes:
                for k, i in enumerate(part.spll):
                    spikes[b][0][i], spikes[b][1][i] = res.tde_spikes[k], res.cco_spikes[k]
    steps = clocked.steps.tolist()
    results = []
    for b in range(len(trains)):
        info = {"dt": steps, COUNTS_KEY: np.concatenate(neurons[b])}
        res = SimulationResult(tde_counts=tde[b], cco_counts=cco[b], duration=duration,
                               backend=backend, info=info)  # fmt: skip
        if record_spikes:
            res.tde_spikes, res.cco_spikes = spikes[b]
        results.append(res)
    return results
