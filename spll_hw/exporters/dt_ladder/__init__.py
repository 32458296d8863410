"""The time step of a clocked export of the standard sPLL when ``--dt`` is not given: the
coarsest step of a ladder whose own export check passes, or a refusal that says why none does.

Both targets of the construction choose this way (``spll-hw export --to nir-standard`` in
:mod:`mappings.nir.dt_choice`, ``--to lava-standard`` in :mod:`mappings.lava.dt_choice`); each
passes its steps, its :func:`trial` and its :class:`Parts`: the backend that runs what it would
write at a step (whose declared tolerance is the limit), and what it tells a user about finer
steps and the exact construction. :func:`choose_dt` tries each step with :func:`trial`: the
writer's own refusal where the network is not representable at that step (a ``ValueError``
naming the parameter), else the export's check (:func:`spll_hw.exporters.check.check_run`: the
network's reference inputs, the total TDE-rate error against the declared tolerance, or against
the user's limit where given: ``spll-hw export --max-error``, :func:`judged`; inputs of
``spll-hw export --check-duration``, 1 s by default, for this and every other check below) run
from memory by that backend, no folder written, and where none passes the target's last rungs in
order (:attr:`Parts.last`: Lava's clock per sPLL, then that clock with graded CCO currents). At
each step it tries the gates of :data:`EXPORT_GATES` in order, with each of the target's
refractory holds (:attr:`Parts.holds`: Lava's dithered hold after its compensated one;
:func:`step_trials`) and returns the first step, hold and gate that pass; where a hold's first
gate fails at a step at which exact integration between steps (:func:`floor_check`, seconds) is
itself beyond the limit, its other gates are not tried there, unless the user keeps the closest
of a failing ladder (``--allow-error``, below; on ``vibtac-time-scaled-peak`` the NIR ladder
then writes 1 µs in 330 s instead of 647 s). The backends' default placement comes first (levels
for 300 Hz Poisson input), then levels on the network's own band of free-running frequencies:
placed for 300 Hz Poisson, a slow sPLL's facilitatory current at the CCO's spikes stays within
one level at the network's lowest frequencies, the gate passes no phase and its TDEs fall silent
(``biotac-time-scaled-lif``; docs/backends.md); last, twice as many levels on that band
(:data:`FINE_LEVELS`: a staircase half as coarse, at twice the level and AND neurons). With
``--dt`` the export still chooses the gate (:func:`choose_placement`). Where no step passes but
the user keeps an export whose check fails (``--allow-error``), it returns the trial whose check
came closest to golden (the smallest error of those the writer represents: on Loihi's integers
the finest step is not always the closest), with a note for the folder's README
(:attr:`Trial.note`).

Each check runs on 1 s of each reference input unless the user gives another length
(``--check-duration``). On 1 s, golden itself moves by more than half a 7 % limit on three
presets when its inputs move 0.5 ms (the check's resolution), so a verdict there may be
golden's own variation: :func:`judge_by` checks such a step again on :data:`LONGER` (10 s)
where that resolves the limit, and judges it by that, pass or fail (``biotac-vary-offset-peak`` and
``-time-scaled-peak`` then pass lava-standard's first rung, 50 µs, instead of 10 µs and a clock
per sPLL; docs/backends.md, "The step chosen on 10 s").

The ladder stops where finer steps stop helping (:func:`stalled`): where
:data:`STALLED_STEPS` successive steps come no closer to golden than the best step before them,
the finer ones are not tried and the refusal (or ``--allow-error``'s note) says which, so a
network that no step represents is refused in a minute, not after an hour of checks down to
1 µs (a 50-sPLL time-scaled network with the vary-offset preset's sPLLs: 100 % off at 100,
50 and 20 µs with its first gate, 57 % at 10 and 5 µs with its last; refused after 23 s instead
of running past 1200 s). A user's limit that lies below golden's own resolution on the
check's inputs (``--max-error 0``, say) is refused before any step is tried
(:func:`refuse_unjudgeable`).

Where none passes, :func:`refusal` names each step's outcome and the worst sPLLs at the finest
step the check ran at, with their ``tau_tde_fac`` and ``tau_tde_trg``, and measures the clock's
own floor, which no construction at that step beats: **exact integration between steps**
(:func:`spll_hw.construction.reference.simulate_reference`, golden product gate, the NIR graph's
refractory holds of ``round(t_refr/dt - 1/2)`` steps, :data:`FLOOR_HOLD`) checked as the export
is (:func:`floor_check`: the check's total TDE-rate error on the whole network, the metric its
limit judges, beside each named sPLL's own error) at that step and at the target's finer floor
steps. Where that total exceeds the limit it blames the clock and says which smaller ``--dt``
the floor allows, or that none of the floor steps does; where it is within, it blames the
construction and gives its 16-level gate's own error (``standard-exact``, the last placement
tried) on the worst sPLLs (both targets hold as the floor does). A worst sPLL's own error is no
floor: it is above the total by construction, and on a periodic train at that sPLL's own free
frequency (the check's highest) it follows the clocked CCO's whole-step period (at 10 µs
``biotac-time-scaled-peak``'s fastest CCO runs at 495 Hz instead of 497 Hz, and its TDE count
on the 497 Hz train is 910 instead of golden's 298; 228 at 5 µs)."""

from __future__ import annotations

from .choosing import (
    STALLED_STEPS,
    at_step,
    choose_dt,
    choose_placement,
    stalled,
    step_trials,
    write_chosen,
)
from .floor import FLOOR_HOLD, Floor, floor_check, floor_errors, gate_error
from .judging import Judge, judge_by, judged, refuse_unjudgeable, refuse_unjudgeable_check
from .refusals import NAMED, refusal
from .trials import (
    EXPORT_GATES,
    FINE_LEVELS,
    Parts,
    TargetTrial,
    Trial,
    backend_trial,
    gate_words,
    more_levels,
    trial,
)

__all__ = [
    "EXPORT_GATES",
    "FINE_LEVELS",
    "FLOOR_HOLD",
    "NAMED",
    "STALLED_STEPS",
    "Floor",
    "Judge",
    "Parts",
    "TargetTrial",
    "Trial",
    "at_step",
    "backend_trial",
    "choose_dt",
    "choose_placement",
    "floor_check",
    "floor_errors",
    "gate_error",
    "gate_words",
    "judge_by",
    "judged",
    "more_levels",
    "refusal",
    "refuse_unjudgeable",
    "refuse_unjudgeable_check",
    "stalled",
    "step_trials",
    "trial",
    "write_chosen",
]
