"""The one result type every backend returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class SimulationResult:
    """Output of one simulated sample of an N-sPLL network.

    Attributes:
        tde_counts: TDE spikes per sPLL during the run, shape ``(N,)``, int64.
        cco_counts: CCO spikes per sPLL, shape ``(N,)``, int64.
        duration: simulated time [s].
        backend: which simulator produced it (``"golden"``, ``"brian2-cpp_standalone"``, ...).
        tde_spikes: per-sPLL TDE spike times [s] (``None`` when spikes were not recorded).
        cco_spikes: per-sPLL CCO spike times [s] (``None`` when spikes were not recorded).
        wall_time: seconds spent simulating (run only, excluding setup where the backend allows).
        final_state: backend-specific state to resume from (golden engine: :class:`EngineState`).
        info: free-form backend details (dt, codegen target, warnings about stiffness, ...).
    """

    tde_counts: np.ndarray
    cco_counts: np.ndarray
    duration: float
    backend: str = "golden"
    tde_spikes: list[np.ndarray] | None = None
    cco_spikes: list[np.ndarray] | None = None
    wall_time: float = float("nan")
    final_state: object | None = field(default=None, repr=False)
    info: dict = field(default_factory=dict)

    @property
    def n_spll(self) -> int:
        return int(self.tde_counts.shape[0])

    @property
    def tde_rates(self) -> np.ndarray:
        """TDE firing rate of each sPLL [Hz], shape ``(N,)`` — the thesis's feature vector."""
        return self.tde_counts / self.duration

    @property
    def cco_rates(self) -> np.ndarray:
        """CCO firing rate of each sPLL [Hz], shape ``(N,)``."""
        return self.cco_counts / self.duration
