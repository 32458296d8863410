"""An independent single-loop NumPy implementation of the Lava models' discrete-time algorithm
in floating point (steps 1-4 of ``engine/src/fixed_point.rs`` with real numbers), sharing no
code with the ProcessModels: it checks the Lava process graph (ports, delays, update order)
spike for spike. The fixed-point models are checked against the Rust reference instead."""

from __future__ import annotations

import numpy as np

from mappings.lava.parameters import FloatParameters


def float_reference(p: FloatParameters, counts: np.ndarray) -> tuple[list, list]:
    """Spike steps (1-based) of every TDE and CCO, lists of int arrays; ``counts[k - 1]``
    input spikes arrive at step ``k``."""
    n = len(p.tde_refr)
    f, g, v_t, u, v_c = (np.zeros(n) for _ in range(5))
    refr_t, refr_c = np.zeros(n, int), np.zeros(n, int)
    tde_fired, cco_fired = np.zeros(n, bool), np.zeros(n, bool)
    logs = {"tde": [[] for _ in range(n)], "cco": [[] for _ in range(n)]}
    for k, n_in in enumerate(counts, start=1):
        gate = np.where(cco_fired, p.gate * f, 0.0)
        f = f * (1 - p.d_fac) + n_in * p.fac_weight
        g = g * (1 - p.d_trg) + gate
        u = u * (1 - p.d_cco_syn) + np.where(tde_fired, p.cco_weight, 0.0)
        fired = {}
        for name, v, refr, drive, d, thr, steps in (
            ("tde", v_t, refr_t, g, p.d_tde, p.tde_threshold, p.tde_refr),
            ("cco", v_c, refr_c, u + p.bias, p.d_cco, p.cco_threshold, p.cco_refr),
        ):
            active = refr == 0
            refr[~active] -= 1
            v[active] = v[active] * (1 - d[active]) + drive[active]
            spike = active & (v > thr)
            v[spike] = 0
            refr[spike] = steps[spike]
            for i in np.flatnonzero(spike):
                logs[name][i].append(k)
            fired[name] = spike
        tde_fired, cco_fired = fired["tde"], fired["cco"]
    return ([np.array(s, int) for s in logs["tde"]], [np.array(s, int) for s in logs["cco"]])
