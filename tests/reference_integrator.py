"""An independent sPLL simulator for the tests: scipy's ``solve_ivp`` (DOP853) on the model as
stated in :mod:`spll_hw.model.equations` (thesis eqs. 1-5), with event detection for the
thresholds, sharing no code with the engine.

It reads the model's tables: every synapse current and membrane of :data:`NEURONS` is a state,
its derivative is the table's equation, and a spike applies the table's :data:`JUMPS` (an input
spike adds ``g_tde_fac`` to the facilitatory current, a CCO spike adds ``g_tde_trg * I_fac`` to
the trigger current, a TDE spike adds ``g_cco`` to the CCO synapse current); a neuron that fires
is reset to 0 and held there for its refractory period. So the golden engine, tested against
this, is tested against the model's statement. With ``gate`` (a function of the jump's factor,
e.g. the standard-neuron sPLL's K-level staircase of ``I_fac``) a jump with a factor adds
``gain * gate(factor)`` instead. Simultaneous events are not handled (they have probability zero
here). ``solve_ivp`` only sees a threshold crossing where one of its steps straddles it, so
maxima are detected as events too and a maximum above threshold is bracketed with ``brentq``.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from spll_hw.model import JUMPS, NEURONS
from spll_hw.params import SpllParams

#: State index of each ``(neuron, state)``: the synapse currents of every neuron, then its ``v``.
INDEX = {
    (n.name, name): i
    for i, (n, name) in enumerate(
        (n, name) for n in NEURONS for name in [s.current for s in n.synapses] + ["v"]
    )
}
#: Index of each neuron's membrane potential.
V = {n.name: INDEX[n.name, "v"] for n in NEURONS}


def _derivative(p: SpllParams):
    """``rhs(t, y, held)``: the model's equations; ``held[name]``: that membrane is refractory."""
    value = p.to_dict()
    terms = []
    for n in NEURONS:
        for s in n.synapses:
            terms.append((INDEX[n.name, s.current], None, s.tau, None))
        m = n.membrane
        drive = [(INDEX[n.name, d], None) if (n.name, d) in INDEX else (None, d) for d in m.drive]
        terms.append((V[n.name], drive, m.tau, (n.name, m.c)))

    def rhs(t, y, held):
        out = np.empty(len(INDEX))
        for index, drive, tau, membrane in terms:
            if membrane is None:  # a synapse current decays
                out[index] = -y[index] / value[tau]
            elif held[membrane[0]]:
                out[index] = 0.0
            else:
                current = sum(y[i] if i is not None else value[name] for i, name in drive)
                out[index] = current / value[membrane[1]] - y[index] / value[tau]
        return out

    return rhs


def _jump(y: np.ndarray, source: str, p: SpllParams, gate) -> None:
    """Apply the model's jumps of a ``source`` spike to the state ``y`` in place."""
    value = p.to_dict()
    for j in JUMPS:
        if j.source != source:
            continue
        size = value[j.gain]
        if j.factor is not None:
            factor = y[INDEX[j.target, j.factor]]
            size *= factor if gate is None else gate(factor)
        y[INDEX[j.target, j.current]] += size


def _crossings(sol, t: float, names: list[str], held: dict, thresholds: dict) -> list:
    """``(time, neuron)`` of each threshold crossing in the solver's interval from ``t``: the
    solver's threshold events, and a maximum above threshold that no solver step straddled
    (bracketed); a held neuron does not cross."""
    fired = []
    for n, name in enumerate(names):
        if held[name]:
            continue
        if len(sol.t_events[n]):
            fired.append((sol.t_events[n][0], name))
        i = V[name]
        for t_peak in sol.t_events[len(names) + n]:
            if sol.sol(t_peak)[i] >= thresholds[name]:
                crossing = brentq(
                    lambda u, i=i, f=sol.sol, thr=thresholds[name]: f(u)[i] - thr,
                    t, t_peak, xtol=1e-15, rtol=4 * np.finfo(float).eps,
                )  # fmt: skip
                fired.append((crossing, name))
                break
    return fired


def reference_spll(
    p: SpllParams, inputs: np.ndarray, t_end: float, rtol: float = 1e-12, gate=None
) -> tuple[np.ndarray, np.ndarray]:
    """TDE and CCO spike times [s] of one sPLL driven by ``inputs`` up to ``t_end``
    (``gate``: what a jump with a factor multiplies its gain by, as a function of that factor,
    here ``I_fac`` [A]; ``None``: the factor itself)."""
    value = p.to_dict()
    y = np.zeros(len(INDEX))
    names = [n.name for n in NEURONS]
    refr_end = dict.fromkeys(names, -np.inf)
    spikes: dict[str, list[float]] = {name: [] for name in names}
    thresholds = {n.name: value[n.membrane.v_thr] for n in NEURONS}
    refractory = {n.name: value[n.membrane.t_refr] for n in NEURONS}
    scale = np.ones(len(INDEX))
    for j in JUMPS:
        scale[INDEX[j.target, j.current]] += value[j.gain] * (
            value["g_tde_fac"] if j.factor else 1.0
        )
    taus = [value[s.tau] for n in NEURONS for s in n.synapses] + [
        value[n.membrane.tau] for n in NEURONS
    ]
    max_step = 0.25 * min(taus)
    rhs = _derivative(p)

    def threshold(name):
        def event(t, y, *_):
            return y[V[name]] - thresholds[name]

        event.terminal = True
        event.direction = 1
        return event

    def peak(name):
        # dV/dt falling through 0: a maximum, where a crossing between two solver steps hides.
        def event(t, y, held):
            return rhs(t, y, held)[V[name]]

        event.direction = -1
        return event

    events = [threshold(name) for name in names] + [peak(name) for name in names]
    t = 0.0
    k = 0
    while t < t_end:
        held = {name: t < refr_end[name] for name in names}
        bounds = [t_end]
        if k < len(inputs):
            bounds.append(inputs[k])
        bounds += [r for r in refr_end.values() if r > t]
        t_next = min(bounds)
        fired = []
        if t_next > t:
            sol = solve_ivp(
                rhs, (t, t_next), y, method="DOP853", rtol=rtol, atol=rtol * scale,
                events=events, args=(held,), max_step=max_step, dense_output=True,
            )  # fmt: skip
            fired = _crossings(sol, t, names, held, thresholds)
        if fired:
            t, name = min(fired)
            y = sol.sol(t).copy()
            y[V[name]] = 0.0
            refr_end[name] = t + refractory[name]
            spikes[name].append(t)
            _jump(y, name, p, gate)
            continue
        if t_next > t:
            y = sol.y[:, -1].copy()
        t = t_next
        if k < len(inputs) and inputs[k] == t:
            _jump(y, "input", p, gate)
            k += 1
        for name, end in refr_end.items():
            if end == t:
                y[V[name]] = 0.0
    return np.array(spikes["tde"]), np.array(spikes["cco"])
