"""An independent sPLL simulator for the tests: scipy's ``solve_ivp`` (DOP853) on the raw ODEs
(thesis eqs. 1-5) with event detection for the thresholds, sharing no code with the engine.

Spike semantics are the same as the golden model's: an input spike adds ``g_tde_fac`` to the
facilitatory current, a CCO spike adds ``g_tde_trg * I_fac`` to the trigger current, a TDE spike
adds ``g_cco`` to the CCO synapse current; a neuron that fires is reset to 0 and held there for its
refractory period. With ``gate`` (a function of ``I_fac``, e.g. the standard-neuron sPLL's K-level
staircase) a CCO spike adds ``g_tde_trg * gate(I_fac)`` instead. Simultaneous events are not
handled (they have probability zero here).
``solve_ivp`` only sees a threshold crossing where one of its steps straddles it, so maxima are
detected as events too and a maximum above threshold is bracketed with ``brentq``.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from spll_hw.params import SpllParams

I_FAC, I_TRG, V_TDE, I_CCO, V_CCO = range(5)


def reference_spll(
    p: SpllParams, inputs: np.ndarray, t_end: float, rtol: float = 1e-12, gate=None
) -> tuple[np.ndarray, np.ndarray]:
    """TDE and CCO spike times [s] of one sPLL driven by ``inputs`` up to ``t_end``
    (``gate``: what a CCO spike multiplies by ``g_tde_trg``, as a function of ``I_fac`` [A];
    ``None``: ``I_fac`` itself)."""
    y = np.zeros(5)
    refr_end = {V_TDE: -np.inf, V_CCO: -np.inf}
    spikes: dict[int, list[float]] = {V_TDE: [], V_CCO: []}
    scale = np.array([p.g_tde_fac, p.g_tde_fac * p.g_tde_trg, 1.0, p.g_cco, 1.0]) + 1.0
    max_step = 0.25 * min(p.tau_tde_fac, p.tau_tde_trg, p.tau_tde, p.tau_cco_syn, p.tau_cco)

    def rhs(t, y, held_tde, held_cco):
        return [
            -y[I_FAC] / p.tau_tde_fac,
            -y[I_TRG] / p.tau_tde_trg,
            0.0 if held_tde else y[I_TRG] / p.c_tde - y[V_TDE] / p.tau_tde,
            -y[I_CCO] / p.tau_cco_syn,
            0.0 if held_cco else (y[I_CCO] + p.i_cco_offset) / p.c_cco - y[V_CCO] / p.tau_cco,
        ]

    def threshold(index, v_thr):
        def event(t, y, *_):
            return y[index] - v_thr

        event.terminal = True
        event.direction = 1
        return event

    def peak(index):
        # dV/dt falling through 0: a maximum, where a crossing between two solver steps hides.
        def event(t, y, held_tde, held_cco):
            return rhs(t, y, held_tde, held_cco)[index]

        event.direction = -1
        return event

    thresholds = {V_TDE: p.v_tde_thr, V_CCO: p.v_cco_thr}
    events = [threshold(V_TDE, p.v_tde_thr), threshold(V_CCO, p.v_cco_thr)]
    peaks = [peak(V_TDE), peak(V_CCO)]
    t = 0.0
    k = 0
    while t < t_end:
        held = {V_TDE: t < refr_end[V_TDE], V_CCO: t < refr_end[V_CCO]}
        bounds = [t_end]
        if k < len(inputs):
            bounds.append(inputs[k])
        bounds += [r for r in refr_end.values() if r > t]
        t_next = min(bounds)
        fired = []
        if t_next > t:
            sol = solve_ivp(
                rhs, (t, t_next), y, method="DOP853", rtol=rtol, atol=rtol * scale,
                events=events + peaks, args=(held[V_TDE], held[V_CCO]),
                max_step=max_step, dense_output=True,
            )  # fmt: skip
            for n, index in enumerate((V_TDE, V_CCO)):
                if held[index]:
                    continue
                if len(sol.t_events[n]):
                    fired.append((sol.t_events[n][0], index))
                # A maximum above threshold that no solver step straddled: bracket it.
                for t_peak in sol.t_events[2 + n]:
                    if sol.sol(t_peak)[index] >= thresholds[index]:
                        crossing = brentq(
                            lambda u, i=index, f=sol.sol: f(u)[i] - thresholds[i], t, t_peak,
                            xtol=1e-15, rtol=4 * np.finfo(float).eps,
                        )  # fmt: skip
                        fired.append((crossing, index))
                        break
        if fired:
            t, index = min(fired)
            y = sol.sol(t).copy()
            y[index] = 0.0
            refr_end[index] = t + (p.t_tde_refr if index == V_TDE else p.t_cco_refr)
            spikes[index].append(t)
            if index == V_CCO:
                y[I_TRG] += p.g_tde_trg * (y[I_FAC] if gate is None else gate(y[I_FAC]))
            else:
                y[I_CCO] += p.g_cco
            continue
        if t_next > t:
            y = sol.y[:, -1].copy()
        t = t_next
        if k < len(inputs) and inputs[k] == t:
            y[I_FAC] += p.g_tde_fac
            k += 1
        for index, end in refr_end.items():
            if end == t:
                y[index] = 0.0
    return np.array(spikes[V_TDE]), np.array(spikes[V_CCO])
