"""Pinned outputs of the fixed-point reference: any change to its integer arithmetic shows here.

``tests/data/fixed_point_pinned.npz`` was generated once, from the scalar implementation of
``engine/src/fixed_point.rs`` as of commit 445987f (before it was vectorised), by a one-off
script kept out of the tree. It stores, per case, everything needed to call
``spll_hw._engine.simulate_fixed_point`` directly (no ``quantize`` call at test time, so a
refactor of that package cannot move the inputs):

* ``<case>/matrix``: the (n, 16) int64 parameter matrix; ``<case>/meta``: state bits, decay
  bits, keep_spikes; ``<case>/timing``: dt [s], duration [s]; ``<case>/threads``: the thread
  counts to run with; ``<case>/train<k>``: the input spike times [s] of sample ``k``;
* expected ``tde_counts``, ``cco_counts`` ((samples, n)), ``saturations`` ((samples, n, 5)),
  ``state`` ((samples, n, 9)), ``n_steps`` and, for cases that keep spikes, the spike steps
  ``k`` (time ``k · dt``) of every sample and sPLL concatenated in ``<which>_steps`` with the
  per-(sample, sPLL) lengths in ``<which>_lengths``.

The cases (how the script made them):

* ``loihi2_ref50``, ``loihi2_ref50_batch``: ``quantize.quantize(net, "loihi2")`` of the
  benchmark's 50-sPLL vary-offset network (VibTac vary offset LIF, 56.2-668 Hz), 300 Hz
  Poisson input (1 s, one sample; 0.5 s, three samples, one with bursts of many spikes in one
  step);
* ``loihi2_one``: the one-sPLL network of the same kind, one Poisson and one empty train;
* ``fixed16_bio12``: ``"fixed16"`` (dt = 100 us, current shifts > 0) on 12 BioTac sPLLs, 2 s,
  saturating the trigger current, the TDE potential and the CCO current;
* ``generic12/16/32``: ``quantize.generic_fixed_point(bits, dt)`` on 9 sPLLs (current shifts
  up to 8 bits; 8 bits cannot represent the network);
* ``random_sat_<state>_<decay>``, ``random_one_16_12``: random valid rows (11 or 1 sPLL) for
  formats from 2/1 to 32/30 bits, including decay constants 0 and ``2^D``, refractory periods
  0, large weights, trigger and current shifts, under dense input with bursts of up to 200
  spikes in one step (every saturation counter is hit somewhere).

Every case runs with 1 and 2 threads (a single sample parallelises over sPLLs, several over
samples) and must reproduce the stored arrays exactly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from spll_hw import _engine

DATA = Path(__file__).parent / "data" / "fixed_point_pinned.npz"


def _cases() -> dict[str, dict[str, np.ndarray]]:
    with np.load(DATA) as z:
        flat = {key: z[key] for key in z.files}
    cases: dict[str, dict[str, np.ndarray]] = {}
    for name in flat["names"].tolist():
        prefix = f"{name}/"
        cases[name] = {k[len(prefix) :]: v for k, v in flat.items() if k.startswith(prefix)}
    return cases


CASES = _cases()


def _run(case: dict[str, np.ndarray], threads: int, keep_spikes: bool) -> dict:
    state_bits, decay_bits, _ = (int(x) for x in case["meta"])
    dt, duration = (float(x) for x in case["timing"])
    trains = [case[f"train{k}"] for k in range(int(case["n_trains"]))]
    return _engine.simulate_fixed_point(
        case["matrix"], trains, dt, duration, state_bits, decay_bits, keep_spikes, threads
    )


def _split(steps: np.ndarray, lengths: np.ndarray) -> list[np.ndarray]:
    return np.split(steps.astype(np.int64), np.cumsum(lengths)[:-1])


@pytest.mark.parametrize("name", sorted(CASES))
def test_outputs_are_the_pinned_ones(name: str) -> None:
    case = CASES[name]
    keep = bool(case["meta"][2])
    dt = float(case["timing"][0])
    assert case["matrix"].dtype == np.int64 and case["matrix"].shape[1] == 16
    for threads in case["threads"].tolist():
        out = _run(case, threads, keep)
        for key in ("tde_counts", "cco_counts", "saturations", "state"):
            np.testing.assert_array_equal(out[key], case[key], err_msg=f"{key}, {threads} threads")
        assert out["n_steps"] == int(case["n_steps"])
        if not keep:
            assert out["tde_spikes"] is None and out["cco_spikes"] is None
            continue
        for which in ("tde", "cco"):
            want = _split(case[f"{which}_steps"], case[f"{which}_lengths"])
            got = [times for sample in out[f"{which}_spikes"] for times in sample]
            assert len(got) == len(want)
            for j, (g, w) in enumerate(zip(got, want, strict=True)):
                # Times are k · dt in float64, exactly.
                np.testing.assert_array_equal(
                    g, w.astype(np.float64) * dt, err_msg=f"{which} spikes of record {j}"
                )


def test_counts_do_not_depend_on_keeping_spikes() -> None:
    case = CASES["fixed16_bio12"]
    out = _run(case, 1, False)
    for key in ("tde_counts", "cco_counts", "saturations", "state"):
        np.testing.assert_array_equal(out[key], case[key])


def test_every_saturation_counter_is_exercised() -> None:
    total = sum(case["saturations"].sum(axis=(0, 1)) for case in CASES.values())
    assert np.all(total > 0), total
