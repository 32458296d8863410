"""Loihi's step (mappings/lava/loihi.py's docstring) in numpy, one step of the whole batch at a
time: the independent statement the Rust core's ``simulate_loihi`` is checked against
(tests/test_loihi_engine.py), on the network as ``_Merged`` lays it out."""

from __future__ import annotations

import numpy as np

from mappings.lava.loihi import UV_MAX, _decay, _Merged


def loihi_steps(net: _Merged, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every neuron's sends ``(B, size)``, the steps each held pair fired together
    ``(B, pairs)`` and the spikes ``(T, B, size)`` (bool; a graded neuron never spikes) of
    ``net`` on ``counts`` (input count per step and sample, ``(T, B)``)."""
    n_steps, batch = counts.shape
    u, v, spikes = (np.zeros((batch, net.size), np.int64) for _ in range(3))
    sent = np.zeros((batch, net.size), np.int64)
    held = np.zeros((batch, net.held_pairs.shape[1]), np.int64)
    raster = np.zeros((n_steps, batch, net.size), dtype=bool)
    for t in range(n_steps):
        a_in = np.asarray(net.w @ spikes.T).T
        for w, e in net.shifted:
            a_in += np.asarray(w @ spikes.T).T >> -e
        if t > 0:
            count = counts[t - 1][:, None]
            a_in += count * net.input_weights
            for cols, w, e in net.input_shifted:
                a_in[:, cols] += (count * w) >> -e
        a = a_in.astype(np.int16).astype(np.int64)  # a 16-bit port
        u = (_decay(u, net.keep_u) + (a << 6) + UV_MAX - 1) % (2 * UV_MAX) - (UV_MAX - 1)
        v = np.clip(_decay(v, net.keep_v) + u + net.bias, -UV_MAX + 1, UV_MAX - 1)
        fired = v > net.threshold
        v[fired] = 0
        fired[:, net.graded] = False
        spikes = fired.astype(np.int64)
        spikes[:, net.graded] = a_in[:, net.graded]
        sent += spikes != 0
        held += fired[:, net.held_pairs[0]] & fired[:, net.held_pairs[1]]
        raster[t] = fired
    return sent, held, raster
