"""The step guard of ``nir-standard`` graphs: a consumer that steps the graph by another ``dt``
than the one it is written for returns every TDE and CCO firing in every step, not a plausible
wrong answer.

Why not NIR's continuous-time meaning: the graph is a discrete construction (memoryless relays
and AND neurons with ``tau = dt``, refractory timers that count whole steps, a start pulse of
one step, every time constant written so that Euler's decay at ``dt`` is the exact one,
``w_in = tau_syn / dt`` and ``r = tau_mem / dt``), so at another step it is another network:
Norse, whose ``from_nir`` takes any ``dt`` (default 1 ms), ran the 100-µs file at 50 µs with no
TDE spike and the 50-µs file at 100 µs with 68 % more (issue 59). snnTorch assumes 100 µs and
rejects a file written for another step by an assertion on ``r``. So the graph carries a guard
built from the same standard nodes, which every consumer runs; at the file's own step it never
fires and changes no count.

A consumer stepping by ``dt'`` multiplies every Euler increment by ``a = dt'/dt`` (Norse:
``I <- I + a/tau_syn' (w_in x - I)``, ``v <- v + a/tau_mem' (r I - v)``, ``tau'`` in steps);
from rest, a ``c_level`` row of one-step synapse and membrane under a constant drive ``x`` holds
``v = a^2 x`` after step 1, and an ``e_gate`` relay ``a`` times its input. The guard's neurons:

* **the fast row** (``c_level``, after the start neuron; drive :func:`fast_drive`): below
  threshold at ``a = 1`` in every step (``v = x < 1``), it fires in step 1 when
  ``a > 1 + STEP_TOLERANCE``; its relay in ``e_gate`` (gain :data:`GATE_GAIN`) repeats it;
* **the start neuron and pulse** (:mod:`.standard`), with the neuron's drive from
  :func:`start_drive`: at ``a = 1`` the neuron fires from step 2 on and the pulse in step 1
  only; when ``a < 1 - STEP_TOLERANCE`` the neuron is still below threshold in step 2 and the
  pulse (gain :data:`GATE_GAIN`, so that it fires at any ``a > 1.5 / GATE_GAIN``) fires again;
* **the latch** (``g_spll``'s last row, after the 2N hold relays): a synapse of
  :data:`LATCH_HOLD_STEPS` steps (its current never decays in float32) and a one-step
  membrane; each pulse adds :data:`PULSE_WEIGHT` (one pulse, the legitimate one of step 1, keeps
  its membrane at 0.99, below threshold; two fire it), the fast relay :data:`LATCH_WEIGHT`.
  Once it fires its current stays, so it fires in every step after, and through
  ``h_refractory`` (weight :data:`OUTPUT_WEIGHT` into every output) every TDE and CCO output
  spikes in every step: a rate of ``1/dt'`` for every neuron, which no run of the sPLLs
  produces (a TDE or CCO is held for its refractory period after each spike).

Measured per consumer and step (Norse, spll-hw's executor; docs/notes/2026-12-06-nir-step.md).
"""

from __future__ import annotations

#: Relative step error the guard lets pass: a step ``dt'`` with ``|dt'/dt - 1|`` below it runs
#: as written (its counts then differ from the file's step by that much of each time constant).
STEP_TOLERANCE = 1e-3
#: Input of the guard's relays in ``e_gate`` (threshold 1.5): one spike, or the start pulse's
#: bias, makes them fire at every step ratio above ``1.5 / GATE_GAIN``.
GATE_GAIN = 1e3
#: The start pulse's weight into the latch's synapse: below 1, so that the one pulse of step 1
#: leaves it silent, above 1/2, so that a second fires it.
PULSE_WEIGHT = 0.99
#: The fast relay's weight into the latch's synapse, and the latch's into every output.
LATCH_WEIGHT = 1e6
OUTPUT_WEIGHT = 1e6
#: The latch's synaptic time constant [steps]: its decay per step, 1e-9, is 0 in float32.
LATCH_HOLD_STEPS = 1e9


def fast_drive(tolerance: float = STEP_TOLERANCE) -> float:
    """The fast row's constant drive: ``a^2 x = 1`` at ``a = 1 + tolerance`` (below threshold
    at the file's step, ``a = 1``, by about ``2 tolerance``)."""
    return 1.0 / (1.0 + tolerance) ** 2


def start_drive(tau_steps: float, tolerance: float = STEP_TOLERANCE) -> float:
    """The start neuron's constant drive (``b_level_input``'s bias; its synapse ``tau_steps``
    steps, its membrane one step): its membrane after step 2, ``a^2 x (3 - a (1 + 1/tau))``,
    reaches the threshold 1 at ``a = 1 - tolerance``, so that at the file's step it fires from
    step 2 on (by about ``1.4 tolerance`` above threshold) and at any step ``tolerance``
    shorter it does not fire in step 2."""
    a = 1.0 - tolerance
    return 1.0 / (a * a * (3.0 - a * (1.0 + 1.0 / tau_steps)))
