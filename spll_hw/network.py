"""The network description every backend consumes: N independent sPLLs sharing one input train.

A :class:`Network` is an immutable list of per-sPLL parameters plus the layout that produced it
(vary-offset, time-scaled or grouped time-scaled, thesis 2.4.3/2.5 and discussion). Backends read
:meth:`Network.matrix`, an ``(n_spll, 15)`` float64 array in :data:`~spll_hw.params.PARAM_NAMES`
column order.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .params import PARAM_NAMES, SpllParams

#: The thesis's network size.
DEFAULT_N_SPLL = 50
#: Free-running frequency [Hz] at which a time-scaled layout's base sPLL runs unscaled (scale 1).
DEFAULT_REFERENCE_FREQUENCY = 50.0
#: Parameters a spread (:meth:`Network.with_spread`) varies per sPLL: time constants and gains.
SPREAD_PARAMS = (
    "tau_cco_syn", "tau_cco", "g_cco",
    "tau_tde_fac", "tau_tde_trg", "tau_tde", "g_tde_fac", "g_tde_trg",
)  # fmt: skip


def network_frequencies(
    f_start: float, f_end: float, n: int = DEFAULT_N_SPLL, beta: float = math.inf
) -> np.ndarray:
    """Free-running frequencies [Hz] of the ``n`` sPLLs, shape ``(n,)`` (thesis section 2.5).

    ``f_i = (f_end + beta)**(i/(n-1)) * (f_start + beta)**(1 - i/(n-1)) - beta`` for
    ``i = 0 .. n-1``, so the first is ``f_start`` and the last ``f_end``. ``beta`` ("log offset")
    moves from exponential spacing (``beta = 0``) to linear spacing (``beta = inf``).
    """
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        raise ValueError(f"number of sPLLs n must be a whole number >= 1, got {n!r}")
    if n < 1:
        raise ValueError(f"number of sPLLs n must be >= 1, got {n}")
    for name, value in (("f_start", f_start), ("f_end", f_end)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a finite frequency > 0 Hz, got {value!r}")
    if math.isnan(beta) or beta < 0:
        raise ValueError(f"beta (log offset) must be >= 0 or inf, got {beta!r}")
    if n == 1:
        return np.array([float(f_start)])
    x = np.arange(n) / (n - 1)
    if math.isinf(beta):
        return f_start + (f_end - f_start) * x
    return np.exp(x * math.log(f_end + beta) + (1 - x) * math.log(f_start + beta)) - beta


@dataclass(frozen=True)
class Network:
    """N sPLLs sharing one input spike train.

    Attributes:
        spll: per-sPLL parameters, length N.
        layout: ``"vary-offset"``, ``"time-scaled"``, ``"grouped"`` or ``"custom"``.
        scales: time scale of each sPLL relative to the base parameters, shape ``(N,)``.
        groups: group index of each sPLL (grouped layout; all zeros otherwise), shape ``(N,)``.
    """

    spll: tuple[SpllParams, ...]
    layout: str = "custom"
    scales: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]
    groups: np.ndarray = field(default=None, repr=False)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        spll = tuple(self.spll)
        if not spll:
            raise ValueError("a Network needs at least one sPLL")
        for i, p in enumerate(spll):
            if not isinstance(p, SpllParams):
                raise ValueError(f"Network.spll[{i}] must be SpllParams, got {type(p).__name__}")
        object.__setattr__(self, "spll", spll)
        n = len(spll)
        scales = np.ones(n) if self.scales is None else np.asarray(self.scales, dtype=float)
        groups = np.zeros(n, dtype=int) if self.groups is None else np.asarray(self.groups, int)
        if scales.shape != (n,) or groups.shape != (n,):
            raise ValueError(f"scales and groups must have shape ({n},)")
        bad = np.flatnonzero(~(np.isfinite(scales) & (scales > 0)))
        if bad.size:
            i = int(bad[0])
            raise ValueError(
                f"Network scales[{i}] = {float(scales[i])!r}: a time scale must be finite and > 0 "
                "(the factor sPLL i runs faster than the base parameters)"
            )
        scales.setflags(write=False)
        groups.setflags(write=False)
        object.__setattr__(self, "scales", scales)
        object.__setattr__(self, "groups", groups)

    # ------------------------------------------------------------------------------ layouts
    @classmethod
    def single(cls, params: SpllParams, free_frequency: float | None = None) -> Network:
        """One sPLL; ``free_frequency`` [Hz], if given, sets its offset current (eq. 6)."""
        if free_frequency is not None:
            params = params.with_free_frequency(free_frequency)
        return cls((params,), layout="custom")

    @classmethod
    def vary_offset(cls, base: SpllParams, frequencies: Sequence[float]) -> Network:
        """Same parameters for every sPLL; only the CCO offset current sets each free frequency."""
        freqs = _frequencies(frequencies)
        return cls(tuple(base.with_free_frequency(f) for f in freqs), layout="vary-offset")

    @classmethod
    def time_scaled(
        cls,
        base: SpllParams,
        frequencies: Sequence[float],
        reference_frequency: float = DEFAULT_REFERENCE_FREQUENCY,
    ) -> Network:
        """Every sPLL is the base sPLL time-scaled by ``f_i / reference_frequency``.

        The base's offset current is set for ``reference_frequency`` [Hz]; scaling divides time
        constants, capacitances and refractory periods (gains and offset stay), which multiplies
        the free-running frequency by the scale, so sPLL i free-runs at ``f_i`` exactly.
        """
        freqs = _frequencies(frequencies)
        tuned = base.with_free_frequency(reference_frequency)
        scales = freqs / reference_frequency
        return cls(tuple(tuned.time_scaled(s) for s in scales), layout="time-scaled", scales=scales)

    @classmethod
    def grouped(
        cls,
        base: SpllParams,
        frequencies: Sequence[float],
        n_groups: int,
        reference_frequency: float = DEFAULT_REFERENCE_FREQUENCY,
        group_scales: Sequence[float] | None = None,
        boundaries: Sequence[int] | None = None,
    ) -> Network:
        """Grouped time-scaled layout: G groups, one time scale each, offset varied inside a group.

        The sPLLs, sorted by frequency, are cut into ``n_groups`` contiguous groups (equal counts
        unless ``boundaries`` gives the first index of groups 1..G-1). Group g runs the base sPLL
        time-scaled by ``group_scales[g]`` (default: geometric mean of its frequencies over
        ``reference_frequency``) and each member's offset current sets its exact frequency. With
        one group and scale 1 this is the vary-offset layout; with one group per sPLL and default
        scales it is the time-scaled layout.
        """
        freqs = _frequencies(frequencies)
        n = len(freqs)
        if not (1 <= n_groups <= n):
            raise ValueError(
                f"n_groups must be between 1 and the number of sPLLs ({n}), got {n_groups}"
            )
        if np.any(np.diff(freqs) < 0):
            raise ValueError("grouped layout needs frequencies in ascending order")
        if boundaries is None:
            edges = np.linspace(0, n, n_groups + 1).round().astype(int)
        else:
            edges = np.concatenate([[0], np.asarray(boundaries, dtype=int), [n]])
            if len(edges) != n_groups + 1 or np.any(np.diff(edges) <= 0):
                raise ValueError(
                    f"boundaries must be {n_groups - 1} strictly increasing indices in 1..{n - 1}, "
                    f"got {list(boundaries)}"
                )
        groups = np.repeat(np.arange(n_groups), np.diff(edges))
        if group_scales is None:
            scales_g = np.array(
                [np.exp(np.mean(np.log(freqs[groups == g]))) / reference_frequency
                 for g in range(n_groups)]
            )  # fmt: skip
        else:
            scales_g = np.asarray(group_scales, dtype=float)
            if (
                scales_g.shape != (n_groups,)
                or np.any(~np.isfinite(scales_g))
                or np.any(scales_g <= 0)
            ):
                raise ValueError(f"group_scales must be {n_groups} finite values > 0")
        scales = scales_g[groups]
        spll = tuple(
            base.time_scaled(s).with_free_frequency(f) for s, f in zip(scales, freqs, strict=True)
        )
        return cls(spll, layout="grouped", scales=scales, groups=groups)

    def with_spread(self, sigma: float, seed: int = 0) -> Network:
        """Per-sPLL diversity: every sPLL's own time constants and gains times lognormal factors.

        Each of :data:`SPREAD_PARAMS` of each sPLL is multiplied by ``exp(sigma * z)``, ``z`` a
        standard normal drawn from ``numpy.random.default_rng(seed)`` as one ``(N, 8)`` matrix
        (row i: sPLL i, columns in :data:`SPREAD_PARAMS` order); then each CCO offset current is
        solved again (eq. 6) so every sPLL keeps its free-running frequency, i.e. the network's
        frequency placement. This is what analog mismatch does to a chip (with calibrated
        offsets), used on purpose: the sPLLs respond differently to the same input, and the
        feature vector gets richer. On a digital chip it costs one parameter set per sPLL.
        ``sigma = 0`` returns the network unchanged; layout, scales and groups are kept.
        """
        if not (math.isfinite(sigma) and sigma >= 0):
            raise ValueError(f"spread sigma must be a finite number >= 0, got {sigma!r}")
        if sigma == 0:
            return self
        z = np.random.default_rng(seed).standard_normal((self.n_spll, len(SPREAD_PARAMS)))
        factors = np.exp(sigma * z)
        spll = []
        for i, (p, f) in enumerate(zip(self.spll, self.free_frequencies(), strict=True)):
            varied = replace(
                p, **{n: getattr(p, n) * k for n, k in zip(SPREAD_PARAMS, factors[i], strict=True)}
            )
            try:
                spll.append(varied.with_free_frequency(f) if f > 0 else varied)
            except ValueError as exc:
                raise ValueError(
                    f"spread sigma {sigma:g} (seed {seed}): sPLL {i} cannot keep its free "
                    f"frequency {f:g} Hz: {exc}; use a smaller spread"
                ) from None
        return Network(tuple(spll), self.layout, self.scales, self.groups)

    # ------------------------------------------------------------------------------ views
    def __len__(self) -> int:
        return len(self.spll)

    @property
    def n_spll(self) -> int:
        return len(self.spll)

    def matrix(self) -> np.ndarray:
        """Parameters as a C-contiguous ``(n_spll, 15)`` float64 array (:data:`PARAM_NAMES`)."""
        return np.ascontiguousarray([p.as_row() for p in self.spll], dtype=np.float64)

    @classmethod
    def from_matrix(cls, matrix: np.ndarray, layout: str = "custom") -> Network:
        """Inverse of :meth:`matrix`."""
        m = np.asarray(matrix, dtype=float)
        if m.ndim != 2 or m.shape[1] != len(PARAM_NAMES):
            raise ValueError(
                f"parameter matrix must have shape (n, {len(PARAM_NAMES)}), got {m.shape}"
            )
        return cls(tuple(SpllParams.from_row(r) for r in m), layout=layout)

    def free_frequencies(self) -> np.ndarray:
        """Free-running CCO frequency of every sPLL [Hz], shape ``(n_spll,)``."""
        return np.array([p.free_frequency() for p in self.spll])


def _frequencies(frequencies: Sequence[float]) -> np.ndarray:
    freqs = np.asarray(frequencies, dtype=float).reshape(-1)
    if freqs.size == 0:
        raise ValueError("need at least one free-running frequency")
    bad = np.flatnonzero(~np.isfinite(freqs) | (freqs <= 0))
    if bad.size:
        raise ValueError(
            "free-running frequencies must be finite and > 0 Hz; "
            f"index {bad[0]} is {float(freqs[bad[0]])!r}"
        )
    return freqs
