"""The time step of ``spll-hw export --to lava-standard`` when ``--dt`` is not given: the
coarsest of :data:`LADDER` at which the integers represent the network and whose own export
check passes, or a refusal that says why none does (the driver, shared with ``--to
nir-standard``, is :mod:`spll_hw.exporters.dt_ladder`).

Loihi's integers pull two ways (docs/backends.md, the error per preset). A coarse step puts
spikes on a coarse grid and holds a refractory period of ``t_refr`` in ``round(t_refr / dt -
1/2)`` whole steps, which the refractory unit needs to be 2 or more; a fine step leaves the long
time constants few of the 12 decay bits (``δ = round(4096 dt / tau)``: ``tau_tde_fac``'s is 3
or 4 at 10 µs, 10-25 % off, and a ``tau_cco_syn`` of 0.2 s has none left below 25 µs: it takes
Loihi's longest, ``4096 dt``, with its kicks' charge kept) and makes a trigger more thresholds
per step in 16-bit ``a_in``. Hence :data:`LADDER`:

* 50 µs, where the declared tolerance (7 %) was measured and 7 of the 17 presets pass their
  check (docs/backends.md); a coarser step would only loosen it (it grows in proportion beyond
  50 µs) and hold more of the time-scaled presets' refractory periods in one step.
* 25 µs holds those periods (72-100 µs) in 2 or 3 steps (``dt <= t_refr / 2`` represents
  them) while the slowest ``tau_cco_syn`` of the time-scaled presets keeps a 12-bit decay of 1,
  and halves the grid of the presets that fail at 50 µs.
* 10 µs, the loihi2 profile's step, where ``biotac-tuned-time-scaled-peak``'s trigger fits
  16-bit ``a_in`` (455 TDE thresholds a step at 20 µs) and the refractory periods are held
  finest; below it the 12-bit decays of the longer time constants round still more coarsely.

Where no step passes, the last rung is a clock per sPLL (:func:`clock_trial`,
:mod:`mappings.lava.clocks`): each sPLL at the step that holds its shorter refractory period in
``R + 1/2`` steps, R = 4, with 32 band-quantile gate levels. A time-scaled sPLL then has its
base sPLL's integers, and the hold is exact on average; it took ``biotac-time-scaled-pacinian``
and ``-peak`` within 7 % (docs/backends.md). Where that fails too, the very last rung is the
same clock with graded CCO currents and 64 levels (:func:`graded_clock_trial`,
:mod:`mappings.lava.graded_current`: each CCO's current kept finer than Loihi's ``u`` in a
``GradedVec``), which took ``biotac-time-scaled-lif`` within 7 %. The clock comes last because
a vary-offset network is one part at one coarse step (222 µs at R = 4 on the presets) and
because the folder runs offline only (its README says so: each set's ring buffer holds the
input binned at its own step).

Each step is first built by the writer (:func:`~mappings.lava.standard.lava_standard`, whose
``ValueError`` is the step's refusal) and then checked by ``standard-fixed-point``, the numpy
executor of Loihi's arithmetic that runs the written integers spike for spike: each gate with
the compensated refractory hold, then each with the dithered one (:attr:`PARTS`'s ``holds``:
better on the vary-offset presets, worse on most time-scaled ones, so it comes second;
docs/backends.md). A refusal
measures exact integration at the finest step checked and at :data:`FLOOR_STEPS` (with the
refractory unit's own holds), and where the clock is not the cause it names the time constant
Loihi's decays round most on the worst sPLLs (:func:`decay_rounding`).
"""

from __future__ import annotations

import numpy as np

from spll_hw.construction.gate import DEFAULT_PLACEMENT
from spll_hw.exporters import dt_ladder
from spll_hw.exporters.check_inputs import DURATION
from spll_hw.exporters.dt_ladder import Trial
from spll_hw.model.discrete import realised_tau
from spll_hw.model.roles import roles
from spll_hw.network import Network
from spll_hw.params import PARAM_NAMES

from . import clocks
from .integers import loihi_decays
from .loihi import DECAY_BITS, kept_charge
from .standard import EXPORT_GATE, EXPORT_LEVELS, HOLDS, lava_standard
from .standard_backend import StandardFixedPoint

#: The export target.
TARGET = "lava-standard"
#: Time steps [s] the export tries, coarsest first (the module docstring says why these).
LADDER = (5e-5, 2.5e-5, 1e-5)
#: Finer steps [s] at which a refusal measures exact integration's own error (below 10 µs
#: Loihi's 12-bit decays hold few of the presets' time constants).
FLOOR_STEPS = (5e-6,)


def _backend(dt: float, placement: str, levels: int | None = None, hold: str | None = None):
    """``standard-fixed-point`` at ``dt`` [s] with ``levels`` gate levels (``None``: the
    export's) placed by ``placement`` and refractory hold ``hold`` (``None``: compensated)."""
    return StandardFixedPoint(dt=dt, levels=levels or EXPORT_LEVELS, placement=placement,
                              hold=hold or HOLDS[0])  # fmt: skip


def trial(
    network: Network,
    dt: float,
    placement: str = DEFAULT_PLACEMENT,
    levels: int | None = None,
    hold: str | None = None,
    duration: float = DURATION,
) -> Trial:
    """The export check of ``network`` as it would be written at step ``dt`` [s] (with
    ``levels`` gate levels, ``None`` for :data:`~mappings.lava.standard.EXPORT_LEVELS`, placed by
    ``placement``, refractory hold ``hold``, ``None`` for the compensated one), run from memory
    by ``standard-fixed-point``, no folder written; the writer's refusal where the integers
    cannot represent the network at ``dt``."""
    return dt_ladder.trial(network, dt, placement, PARTS, levels, hold, duration)


def decay_rounding(network: Network, spll: np.ndarray, dt: float) -> str:
    """Where Loihi's 12-bit decays at ``dt`` [s] are furthest from the time constants of sPLLs
    ``spll``: the clause a refusal adds after the gate's error."""
    p, worst = dict(zip(PARAM_NAMES, network.matrix().T, strict=True)), (0.0, "", 0, 0.0, 0.0)
    delta = loihi_decays(p, roles(), dt)
    for name in roles().time_constants:
        tau = p[name][spll]
        realised = realised_tau(delta[name][spll], dt, DECAY_BITS)
        off = np.abs(realised / tau - 1)
        k = int(np.argmax(off))
        if off[k] > worst[0]:
            worst = (float(off[k]), name, int(spll[k]), float(tau[k]), float(realised[k]))
    off, name, i, tau, realised = worst
    if not name:
        return ""
    acts = (
        "leak nothing (a decay of 0)" if np.isinf(realised) else f"act as {realised * 1e6:.0f} µs"
    )
    return (
        f"; Loihi's 12-bit decays at {dt * 1e6:g} µs make sPLL {i}'s {name} of "
        f"{tau * 1e6:.0f} µs {acts} ({100 * off:.0f} % off)"
    ) + feedback_resolution(network, spll, dt)


#: A feedback kick that keeps less of its charge than this is named by a refusal.
KEPT_CHARGE = 0.8


def feedback_resolution(network: Network, spll: np.ndarray, dt: float) -> str:
    """Where the TDE's feedback kick into the CCO of one of sPLLs ``spll``, as the integers
    write it at ``dt`` [s], is so few units of ``u`` that Loihi's whole-unit decay takes away
    much of its charge (:func:`~mappings.lava.loihi.kept_charge` under :data:`KEPT_CHARGE`):
    the clause naming the sPLL that keeps least, or ``""``."""
    try:
        params = lava_standard(network, EXPORT_GATE, dt=dt)
    except ValueError:
        return ""
    kick, delta = feedback_kicks(params)
    kept = kept_charge(kick[spll], delta[spll])
    k = int(np.argmin(kept))
    if kept[k] >= KEPT_CHARGE:
        return ""
    i = int(spll[k])
    return (
        f"; sPLL {i}'s feedback kick into its CCO is {kick[i]} units of u decaying by "
        f"{delta[i]}/4096 a step, which Loihi's whole-unit decay cuts to {100 * kept[k]:.0f} % "
        "of its charge (a CCO current is a potential per step: a slow CCO's is few units)"
    )


def feedback_kicks(params) -> tuple[np.ndarray, np.ndarray]:
    """Per sPLL of the integers ``params``: the units of ``u`` one TDE spike adds to its CCO
    (the gate's relay into the CCO, every exponent's ``Dense`` summed, ``64 w 2^e``) and the
    CCO current's 12-bit decay ``δ`` (``du + 1``), int arrays of shape ``(N,)``."""
    kick = np.zeros(params.n_spll, np.int64)
    delta = np.ones(params.n_spll, np.int64)
    for pop, idx in params.members.items():
        if pop.startswith("cco"):
            delta[idx] = int(params.lif[pop]["du"]) + 1
    for name, (src, dst, w, e, _) in params.dense.items():
        if src == "gate" and dst.startswith("cco") and "_start_" not in name:
            units = (np.asarray(w, np.int64).sum(axis=1) * 2**e * 64).astype(np.int64)
            kick[params.members[dst]] += units
    return kick, delta


def finer(network: Network, dt: float) -> str:
    """Whether the integers represent ``network`` at the finer step ``dt`` [s] a refusal's
    floor allows (the writer's reason where they do not)."""
    try:
        lava_standard(network, EXPORT_GATE, dt=dt)
    except ValueError as exc:
        return f"it is not representable there: {str(exc).split(';')[0]}"
    return "the integers represent it there"


#: The last rungs in words.
CLOCK = f"a clock per sPLL (R = {clocks.DEFAULT_HOLDS})"
GRADED_CLOCK = f"{CLOCK} with graded CCO currents"
#: Gate levels of the graded rung: a graded current is worth its cost with a finer gate
#: (``biotac-time-scaled-lif``: 8.1 % with 32 levels, 6.6 % with 64; docs/backends.md).
GRADED_LEVELS = 64


def clock_trial(network: Network, current: str = "lif", duration: float = DURATION) -> Trial:
    """The export check of ``network`` with a clock per sPLL (:mod:`mappings.lava.clocks`:
    each sPLL's shorter refractory period in ``R + 1/2`` of its own steps, R =
    :data:`~mappings.lava.clocks.DEFAULT_HOLDS`), its CCOs' currents kept as ``current`` says
    (:data:`~mappings.lava.standard.CURRENTS`; ``graded`` with :data:`GRADED_LEVELS`
    band-quantile gate levels, else 32), run from memory by ``standard-fixed-point`` with
    ``clock=per-spll`` on reference inputs of ``duration`` [s]; the writer's refusal where a
    set of sPLLs is not representable at its step."""
    levels = GRADED_LEVELS if current == "graded" else clocks.DEFAULT_LEVELS
    gate = {"levels": levels, "placement": clocks.DEFAULT_PLACEMENT}
    backend = StandardFixedPoint(clock="per-spll", holds=clocks.DEFAULT_HOLDS, current=current,
                                 **gate)  # fmt: skip
    where = GRADED_CLOCK if current == "graded" else CLOCK
    base = Trial(float("nan"), None, float("nan"), clock=where, **gate)
    return dt_ladder.backend_trial(network, backend, TARGET, base, where, duration)


def graded_clock_trial(network: Network, duration: float = DURATION) -> Trial:
    """:func:`clock_trial` with graded CCO currents (:mod:`mappings.lava.graded_current`)."""
    return clock_trial(network, "graded", duration)


#: What a refusal says beside the measurements.
PARTS = dt_ladder.Parts(
    TARGET,
    _backend,
    finer=finer,
    exact="--to lava writes the exact sPLL (spll-hw's TDE and CCO processes on Lava)",
    construction=decay_rounding,
    holds=(None, "dithered"),
    last=(clock_trial, graded_clock_trial),
)


def choose_dt(network: Network, *args, **kwargs) -> Trial:
    """:func:`spll_hw.exporters.dt_ladder.choose_dt` of ``lava-standard`` on :data:`LADDER`,
    then its clocks per sPLL (:data:`PARTS`' last rungs): ``log``, ``max_error``,
    ``allow_error`` and ``duration`` as it takes them."""
    return dt_ladder.choose_dt(network, PARTS, LADDER, FLOOR_STEPS, trial, *args, **kwargs)


def choose_placement(
    network: Network, dt: float, log=None, max_error=None, duration: float | None = None
) -> Trial:
    """:func:`spll_hw.exporters.dt_ladder.choose_placement` of ``lava-standard`` at ``dt``,
    each gate with both refractory holds."""
    return dt_ladder.choose_placement(network, dt, PARTS, trial, log, max_error, duration)


__all__ = [
    "FLOOR_STEPS",
    "finer",
    "LADDER",
    "PARTS",
    "TARGET",
    "Trial",
    "choose_dt",
    "choose_placement",
    "clock_trial",
    "graded_clock_trial",
    "decay_rounding",
    "feedback_kicks",
    "feedback_resolution",
    "trial",
]
