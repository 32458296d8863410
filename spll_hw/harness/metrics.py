"""Errors of a simulation result against the golden model's result for the same sample."""

from __future__ import annotations

import numpy as np

from ..result import SimulationResult

#: Largest time difference [s] at which two spikes count as the same spike.
DEFAULT_MATCH_WINDOW = 5e-4


def rate_error(result: SimulationResult, reference: SimulationResult, part: str = "tde") -> float:
    """Relative L1 error of the TDE (``part="cco"``: the CCO) rate vector:
    ``sum|r - r_ref| / sum r_ref`` (NaN if the reference has no such spike)."""
    if part not in ("tde", "cco"):
        raise ValueError(f"part must be 'tde' or 'cco', got {part!r}")
    ref = getattr(reference, f"{part}_rates")
    total = ref.sum()
    mine = getattr(result, f"{part}_rates")
    return float(np.abs(mine - ref).sum() / total) if total > 0 else float("nan")


def count_error(result: SimulationResult, reference: SimulationResult) -> float:
    """Relative error of the total TDE spike count of the network (signed)."""
    total = reference.tde_counts.sum()
    return float((result.tde_counts.sum() - total) / total) if total > 0 else float("nan")


def spike_time_error(
    result: SimulationResult, reference: SimulationResult, window: float = DEFAULT_MATCH_WINDOW
) -> tuple[np.ndarray, float]:
    """Timing errors [s] of matched TDE spikes and the fraction of reference spikes matched.

    Each reference spike is matched to the nearest spike of the same sPLL in ``result`` when
    they are at most ``window`` apart. Returns ``(abs_errors, matched_fraction)``.
    """
    if result.tde_spikes is None or reference.tde_spikes is None:
        raise ValueError("spike-time errors need both results with recorded spikes")
    errors = []
    n_ref = 0
    for mine, ref in zip(result.tde_spikes, reference.tde_spikes, strict=True):
        n_ref += len(ref)
        if len(mine) == 0 or len(ref) == 0:
            continue
        k = np.clip(np.searchsorted(mine, ref), 1, len(mine) - 1) if len(mine) > 1 else None
        if k is None:
            nearest = np.abs(ref - mine[0])
        else:
            nearest = np.minimum(np.abs(ref - mine[k - 1]), np.abs(ref - mine[k]))
        errors.append(nearest[nearest <= window])
    errs = np.concatenate(errors) if errors else np.empty(0)
    return errs, (len(errs) / n_ref if n_ref else float("nan"))
