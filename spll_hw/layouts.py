"""Grouped time-scaled layout under a group budget (thesis discussion), and the partition it uses.

The fully time-scaled network runs sPLL ``i`` at scale ``s_i = f_i / f_ref``: every sPLL is its
own circuit. A chip offers ``G`` circuits (groups); group ``g`` runs the base sPLL at one scale
``S_g``, and the offset current of each member sets its exact free-running frequency. Every sPLL
then runs ``s_i / S_g`` times off its ideal scale, and the layout is chosen to keep those
factors small.

**Method.** Work with ``x_i = ln s_i`` (scale errors are ratios, so they are measured in log
space) and choose contiguous groups of the frequency-sorted sPLLs and one centre per group:

* ``objective="squared"`` (default) minimises ``sum_i (x_i - ln S_g(i))^2``; the best centre of
  a group is its mean log scale (``S_g`` = geometric mean of the members' scales);
* ``objective="max"`` minimises ``max_i |x_i - ln S_g(i)|``; the best centre is the midpoint of
  the group's log range (``S_g = sqrt(s_min s_max)``).

For points on a line both optima use contiguous groups (1-D k-means / k-centre), so dynamic
programming over the ``G - 1`` boundaries finds the exact optimum in ``O(G (n - G)^2)``, each
group's starts taken at once (numpy; 2000 values into 32 groups in 1.4 s, where a loop over
them took 224 s, and a progress bar where it runs longer, :data:`PROGRESS_WORK`):
``best[g][j] = min_i best[g-1][i] (+ or max) cost(i, j)``. With ``G = 1`` the layout is a
vary-offset network of the base sPLL scaled once (by the geometric mean, or the midpoint); with
``G = n`` it is the time-scaled network.

The same partition places a limited number of analog offset currents (``quantize.analog``).
:func:`circuit_count` says how many distinct sPLL circuits a network needs, what a chip's group
budget limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from tqdm.auto import tqdm

from .network import DEFAULT_REFERENCE_FREQUENCY, Network
from .params import PARAM_NAMES, SpllParams

Objective = Literal["squared", "max"]
OBJECTIVES: tuple[str, ...] = ("squared", "max")
#: Work of :func:`partition`'s dynamic programme, ``(G - 1) (n - G + 1)^2`` segment costs,
#: from which it shows a progress bar: about 5 s on the 2-core development machine (2000 values
#: into 128 groups, 4.5e8, took 10-12 s; into 32, 1.2e8, 1.4-2 s).
PROGRESS_WORK = 2.5e8


@dataclass(frozen=True)
class Partition:
    """Contiguous groups of sorted values with one centre each.

    Attributes:
        boundaries: first index of groups ``1 .. G-1``, shape ``(G-1,)``.
        centres: centre of each group (same unit as the values), shape ``(G,)``.
        cost: the objective's value (in squared or absolute natural-log units).
        n: number of values.
    """

    boundaries: np.ndarray
    centres: np.ndarray
    cost: float
    n: int

    @property
    def groups(self) -> np.ndarray:
        """Group index of every value, shape ``(n,)``."""
        return np.searchsorted(self.boundaries, np.arange(self.n), side="right")


def _segment_cost(x: np.ndarray, objective: str):
    """``cost(i, j)`` and ``centre(i, j)`` of the segment ``x[i:j]`` (log values); ``cost``
    also of every segment ``x[i:j]`` at once for an array of starts ``i``."""
    s1 = np.concatenate([[0.0], np.cumsum(x)])
    s2 = np.concatenate([[0.0], np.cumsum(x * x)])

    if objective == "squared":

        def cost(i, j: int):
            mean = (s1[j] - s1[i]) / (j - i)
            return np.maximum(0.0, (s2[j] - s2[i]) - (j - i) * mean * mean)

        def centre(i: int, j: int) -> float:
            return (s1[j] - s1[i]) / (j - i)

    else:

        def cost(i, j: int):
            return (x[j - 1] - x[i]) / 2

        def centre(i: int, j: int) -> float:
            return (x[i] + x[j - 1]) / 2

    return cost, centre


def partition(
    values: Sequence[float], n_groups: int, objective: Objective = "squared"
) -> Partition:
    """Optimal split of ascending positive ``values`` (shape ``(n,)``) into ``n_groups``
    contiguous groups, each represented by one centre, minimising the log-space ``objective``
    (module docstring). A group of one value has that value as its centre, exactly."""
    v = np.asarray(values, dtype=float).reshape(-1)
    n = v.size
    if objective not in OBJECTIVES:
        raise ValueError(f"unknown objective {objective!r}; choose from {OBJECTIVES}")
    if n == 0:
        raise ValueError("nothing to partition: no values")
    if np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise ValueError("values to partition must be finite and > 0")
    if np.any(np.diff(v) < 0):
        raise ValueError("values to partition must be in ascending order")
    if isinstance(n_groups, bool) or not isinstance(n_groups, int | np.integer):
        raise ValueError(f"number of groups must be an integer, got {n_groups!r}")
    if not 1 <= n_groups <= n:
        raise ValueError(f"number of groups must be between 1 and {n} (the values), got {n_groups}")
    x = np.log(v)
    cost, centre = _segment_cost(x, objective)
    combine = np.add if objective == "squared" else np.maximum
    # best[g][j]: optimal cost of x[:j] in g+1 groups; arg[g][j]: start of the last group.
    # Group g ends at j >= g + 1 and leaves a value to each group after it (j <= n - G + 1 + g;
    # the last ends at n); its start i runs over g .. j-1 at once, the first of equal costs kept.
    best = np.full((n_groups, n + 1), math.inf)
    arg = np.zeros((n_groups, n + 1), dtype=int)
    starts = np.arange(n + 1)
    best[0, 1:] = cost(np.zeros(n, dtype=int), starts[1:])
    quick = (n_groups - 1) * (n - n_groups + 1) ** 2 < PROGRESS_WORK
    bar = tqdm(range(1, n_groups), desc=f"partition of {n} values into {n_groups} groups",
               unit="group", disable=quick, leave=False)  # fmt: skip
    for g in bar:
        for j in range(n if g == n_groups - 1 else g + 1, n - n_groups + g + 2):
            c = combine(best[g - 1, g:j], cost(starts[g:j], j))
            k = int(np.argmin(c))
            best[g, j], arg[g, j] = c[k], g + k
    edges = [n]
    for g in range(n_groups - 1, 0, -1):
        edges.append(int(arg[g, edges[-1]]))
    edges.append(0)
    edges = edges[::-1]
    centres = np.array(
        [
            v[i] if j - i == 1 else math.exp(centre(i, j))
            for i, j in zip(edges, edges[1:], strict=False)
        ]
    )
    return Partition(np.array(edges[1:-1], dtype=int), centres, float(best[n_groups - 1, n]), n)


def layout_cost(ideal_scales, used_scales, objective: Objective = "squared") -> float:
    """How far a layout's scales ``used_scales`` are from ``ideal_scales`` (both shape
    ``(n,)``): ``sum (ln ratio)^2`` or ``max |ln ratio|``."""
    r = np.log(np.asarray(used_scales, float)) - np.log(np.asarray(ideal_scales, float))
    if objective not in OBJECTIVES:
        raise ValueError(f"unknown objective {objective!r}; choose from {OBJECTIVES}")
    return float(np.sum(r * r)) if objective == "squared" else float(np.max(np.abs(r)))


@dataclass(frozen=True)
class GroupedLayout:
    """A grouped time-scaled network and how it was chosen.

    Attributes:
        network: the :class:`~spll_hw.network.Network` (layout ``"grouped"``).
        boundaries: first sPLL index of groups ``1 .. G-1``.
        group_scales: time scale of each group, shape ``(G,)``.
        cost: the objective's value (:func:`layout_cost` against the time-scaled network).
        objective: ``"squared"`` or ``"max"``.
    """

    network: Network
    boundaries: tuple[int, ...]
    group_scales: np.ndarray
    cost: float
    objective: str


def grouped_layout(
    base: SpllParams,
    frequencies: Sequence[float],
    n_groups: int,
    reference_frequency: float = DEFAULT_REFERENCE_FREQUENCY,
    *,
    objective: Objective = "squared",
) -> GroupedLayout:
    """The grouped time-scaled network with ``n_groups`` groups closest to the time-scaled
    network of ``base`` (module docstring for the method).

    Args:
        base: the base sPLL, unscaled at ``reference_frequency`` [Hz].
        frequencies: free-running frequencies [Hz], ascending, shape ``(n,)``.
        n_groups: the group budget ``G``; more groups than sPLLs is an error.
        reference_frequency: [Hz] where the base sPLL runs at scale 1.
        objective: ``"squared"`` or ``"max"`` log-scale error.
    """
    freqs = np.asarray(frequencies, dtype=float).reshape(-1)
    if not (math.isfinite(reference_frequency) and reference_frequency > 0):
        raise ValueError(
            f"reference_frequency must be finite and > 0 Hz, got {reference_frequency!r}"
        )
    if freqs.size and np.all(np.isfinite(freqs)) and np.all(freqs > 0):
        if np.any(np.diff(freqs) < 0):
            raise ValueError("grouped layout needs frequencies in ascending order")
    else:
        raise ValueError("frequencies must be finite and > 0 Hz (at least one)")
    scales = freqs / reference_frequency
    part = partition(scales, n_groups, objective)
    net = Network.grouped(
        base,
        freqs,
        n_groups,
        reference_frequency,
        group_scales=part.centres,
        boundaries=part.boundaries,
    )
    return GroupedLayout(
        network=net,
        boundaries=tuple(int(b) for b in part.boundaries),
        group_scales=part.centres,
        cost=layout_cost(scales, net.scales, objective),
        objective=objective,
    )


def circuit_count(network: Network) -> int:
    """Number of distinct sPLL circuits in ``network``: distinct parameter rows apart from the
    CCO offset current (a vary-offset network has 1, a time-scaled one ``n``)."""
    m = np.delete(network.matrix(), PARAM_NAMES.index("i_cco_offset"), axis=1)
    return int(np.unique(m, axis=0).shape[0])
