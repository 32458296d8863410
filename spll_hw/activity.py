"""Runs that are almost always a mistake: every sPLL silent, or every sPLL at its refractory
limit. :func:`warn_if_silent` says so with a :class:`SilentNetworkWarning` naming how many sPLLs
did what and what usually causes it; the result itself is returned unchanged."""

from __future__ import annotations

import warnings

import numpy as np

from .params import PARAM_NAMES

#: Input spikes from which a network with no TDE spike at all is suspicious (when they also
#: come at least as fast as the slowest sPLL free-runs: a sparser input may leave every TDE
#: silent in a sound network).
MIN_INPUTS = 10
#: Free-running CCO periods of the fastest sPLL from which no CCO spike at all is suspicious.
MIN_FREE_PERIODS = 2
#: Share of the refractory limit (one spike per refractory period) from which a neuron counts
#: as firing at it.
LIMIT_SHARE = 0.9

CAUSES = {
    "tde": "parameters that do not suit the layout (time-scaled and grouped layouts divide each "
    "sPLL's time constants by its scale but keep the gains, so parameters tuned for a "
    "vary-offset network may leave every TDE below threshold), gains g_tde_fac or g_tde_trg "
    "far too small, or an input far from the free-running frequencies",
    "cco": "CCO offset currents at or below the rheobase (SpllParams default i_cco_offset = 0: "
    "set free-running frequencies with a Network layout or with_free_frequency) or a "
    "threshold v_cco_thr the CCO never reaches",
    "limit": "gains or offset currents so large that each neuron fires again as soon as its "
    "refractory period ends (a unit error, e.g. g_tde_fac or i_cco_offset scaled wrongly)",
}


class SilentNetworkWarning(UserWarning):
    """Every sPLL of a run stayed silent (no TDE spike despite input, or no CCO spike), or
    every sPLL fired at its refractory limit: the features carry no information."""


def at_refractory_limit(counts: np.ndarray, t_refr: np.ndarray, duration: float) -> np.ndarray:
    """Which neurons fired at least :data:`LIMIT_SHARE` of one spike per refractory period
    ``t_refr`` [s] over ``duration`` [s] (and at least twice); shape as ``counts``."""
    with np.errstate(divide="ignore"):
        limit = np.where(t_refr > 0, duration / t_refr, np.inf)
    return (counts >= 2) & (counts >= LIMIT_SHARE * limit)


def silent_reasons(
    net, matrix: np.ndarray, tde: np.ndarray, cco: np.ndarray, n_inputs: int, duration: float
) -> list[tuple[str, str]]:
    """The reasons a run of ``net`` (:class:`~spll_hw.network.Network`, parameter matrix
    ``matrix``) lasting ``duration`` [s] with ``n_inputs`` input spikes and TDE/CCO spike counts
    ``tde``, ``cco`` (shape ``(n_spll,)``) looks like a mistake: a list of ``(what, cause
    key)``. A TDE only fires after CCO spikes, so with every CCO silent only that is named."""
    n = len(tde)
    reasons = []
    free = net.free_frequencies()
    fastest = float(np.max(free))
    slowest = float(np.min(free, initial=np.inf, where=free > 0))
    if not cco.any() and (fastest == 0 or fastest * duration >= MIN_FREE_PERIODS):
        reasons.append((f"{n} of {n} sPLLs gave no CCO spike in {duration:g} s", "cco"))
    elif n_inputs >= max(MIN_INPUTS, slowest * duration) and not tde.any():
        reasons.append((f"{n} of {n} sPLLs gave no TDE spike from {n_inputs} input spikes", "tde"))
    limit = at_refractory_limit(
        tde, matrix[:, PARAM_NAMES.index("t_tde_refr")], duration
    ) | at_refractory_limit(cco, matrix[:, PARAM_NAMES.index("t_cco_refr")], duration)
    if limit.all():
        reasons.append((f"{n} of {n} sPLLs fired at their refractory limit", "limit"))
    return reasons


def warn_if_silent(net, matrix: np.ndarray, result, n_inputs: int, stacklevel: int = 3) -> None:
    """Warn (:class:`SilentNetworkWarning`) when ``result`` (a run of ``net``, parameter matrix
    ``matrix``, with ``n_inputs`` input spikes) is silent or saturated in every sPLL
    (:func:`silent_reasons`)."""
    counts = (result.tde_counts, result.cco_counts)
    reasons = silent_reasons(net, matrix, *counts, n_inputs, float(result.duration))
    if not reasons:
        return
    what = "; ".join(text for text, _ in reasons)
    causes = "; or ".join(CAUSES[key] for _, key in reasons)
    warnings.warn(
        f"{what}: the rates carry no information. This usually means {causes}.",
        SilentNetworkWarning,
        stacklevel=stacklevel,
    )
