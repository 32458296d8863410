"""The time step of ``spll-hw export --to nir-standard`` when ``--dt`` is not given: the coarsest
of :data:`LADDER` whose own export check passes, or a refusal that says why none does (the
driver, shared with ``--to lava-standard``, is :mod:`spll_hw.exporters.dt_ladder`).

A clocked consumer's error against the golden model falls with ``dt`` (spikes on step ends,
refractory holds of whole steps, the gate reading ``I_fac`` on the step grid), and how fast
depends on the network: the vary-offset presets pass at 100 µs, the time-scaled ones, whose
fastest sPLLs have ``tau_tde_fac`` and ``tau_tde_trg`` of 85-500 µs and TDEs that fire every
few steps, need 50 µs or less, and ``vibtac-time-scaled-peak`` (about 15 TDE spikes per sPLL
and second; exact integration between steps is 23 % off at 10 µs, 11.5 % at 2 µs and 7 % at
1 µs) passes only at 1 µs, which its check takes about 3 minutes to run. Each step is
checked by the backend that runs the written graph spike for spike
(``nir-numpy``, :func:`trial`). snnTorch runs only 100 µs
(:func:`~mappings.nir.consumers.support`), so a graph of a finer step names Norse and the
spll-hw's executor as its consumers (Norse's loader computes in float64, measured down to 1 µs:
``NORSE_MIN_DT``). A refusal measures exact integration
down to
:data:`FLOOR_STEPS`.
"""

from __future__ import annotations

from spll_hw.construction.gate import DEFAULT_PLACEMENT
from spll_hw.exporters import dt_ladder
from spll_hw.exporters.check_inputs import DURATION
from spll_hw.exporters.dt_ladder import Trial
from spll_hw.network import Network

from .consumers import STEPS_RUN
from .standard import EXPORT_LEVELS, TARGET
from .standard_backend import NirNumpy

#: Time steps [s] the export tries, coarsest first (snnTorch's 100 µs first).
LADDER = (1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6)
#: Finer steps [s] at which a refusal measures exact integration's own error.
FLOOR_STEPS = (5e-7,)


def _backend(dt: float, placement: str, levels: int | None = None, hold: None = None):
    """``nir-numpy`` at ``dt`` [s] with ``levels`` gate levels (``None``: the export's)
    placed by ``placement`` (the graph has one refractory hold: ``hold`` is ``None``)."""
    if hold is not None:
        raise ValueError(f"nir-standard has one refractory hold, not {hold!r}")
    return NirNumpy(dt=dt, levels=levels or EXPORT_LEVELS, placement=placement)


#: What a refusal says beside the measurements.
PARTS = dt_ladder.Parts(
    TARGET,
    _backend,
    finer=lambda network, dt: STEPS_RUN,
    exact="--to nir writes the exact sPLL (run by spll-hw's NIR reader)",
)


def trial(
    network: Network,
    dt: float,
    placement: str = DEFAULT_PLACEMENT,
    levels: int | None = None,
    hold: None = None,
    duration: float = DURATION,
) -> Trial:
    """The export check of ``network`` as it would be written at step ``dt`` [s] (with
    ``levels`` gate levels, ``None`` for :data:`~mappings.nir.standard.EXPORT_LEVELS`, placed by
    ``placement``; the graph's one refractory hold), run from memory by ``nir-numpy``, no
    folder written."""
    return dt_ladder.trial(network, dt, placement, PARTS, levels, hold, duration)


def choose_dt(network: Network, *args, **kwargs) -> Trial:
    """:func:`spll_hw.exporters.dt_ladder.choose_dt` of ``nir-standard`` on :data:`LADDER`:
    ``log``, ``max_error``, ``allow_error`` and ``duration`` as it takes them."""
    return dt_ladder.choose_dt(network, PARTS, LADDER, FLOOR_STEPS, trial, *args, **kwargs)


def choose_placement(
    network: Network, dt: float, log=None, max_error=None, duration: float | None = None
) -> Trial:
    """:func:`spll_hw.exporters.dt_ladder.choose_placement` of ``nir-standard`` at ``dt``."""
    return dt_ladder.choose_placement(network, dt, PARTS, trial, log, max_error, duration)


__all__ = ["FLOOR_STEPS", "LADDER", "PARTS", "Trial", "choose_dt", "choose_placement", "trial"]
