"""Lava as backends ``lava-float`` and ``lava-fixed`` (CPU simulator, every process in its own
OS process).

``lava-fixed`` runs the bit-accurate fixed-point models on the integers of a fixed-point
``quantize`` profile (options ``profile``, default ``loihi2``, and ``dt``), spike for spike the
``golden-fixed-point`` backend. ``lava-float`` runs the same algorithm in real numbers at ``dt``
(default 10 µs; ``profile`` / ``chip_seed`` realise the network on a chip first). A batch runs as
one Lava network with a copy of the sPLLs per sample
(:func:`~mappings.lava.run.simulate_lava_batch`); Lava's Python runtime does about 1-2
thousand steps per second.
"""

from __future__ import annotations

import abc
from dataclasses import replace

from mappings.fixed_point.backend import GRID_ERROR_PER_SECOND, TOLERANCE_MARGIN, FixedPointBackend
from spll_hw.backends.base import PROFILE_OPTIONS, Backend, Capabilities, Option, positive_float
from spll_hw.result import SimulationResult

from .run import simulate_lava_batch

#: Time step [s] of ``lava-float`` when none is given (the Loihi-2-like profile's).
DEFAULT_DT = 1e-5
#: A coarser step for the conformance suite: Lava's runtime is slow.
CONFORMANCE_DT = 5e-5


class _Lava(Backend):
    extra = "lava"
    requires = ("lava",)
    tag: str

    def _run(self, prepared, trains, duration, *, threads, record_spikes) -> list[SimulationResult]:
        # One Lava network for the whole batch. Spikes after the end are not delivered (the
        # protocol); Lava's builder refuses them.
        cut = [x[x <= duration] for x in trains]
        return simulate_lava_batch(prepared, cut, duration, tag=self.tag, **self._settings())

    @abc.abstractmethod
    def _settings(self) -> dict:
        """Keyword arguments of ``simulate_lava`` beside the tag."""


class LavaFloat(_Lava):
    name = "lava-float"
    description = "Lava processes, floating-point models (CPU)"
    tag = "floating_pt"
    OPTIONS = {
        "dt": Option(DEFAULT_DT, "time step [s]", positive_float("dt")),
        **PROFILE_OPTIONS,
    }
    CONFORMANCE_OPTIONS = {"dt": CONFORMANCE_DT}

    @property
    def capabilities(self) -> Capabilities:
        dt = float(self.options["dt"])
        # The fixed-point reference's algorithm in real numbers: only its time grid errs.
        # Measured mean rate error on the conformance reference set at dt = 50 us: 0.028
        # (largest sample 0.060); declared 1.5 * 1000 dt = 0.075 there.
        return Capabilities(
            exact=False, dt=dt, arithmetic="float",
            rate_tolerance=TOLERANCE_MARGIN * GRID_ERROR_PER_SECOND * dt,
        )  # fmt: skip

    def _settings(self) -> dict:
        return {"dt": float(self.options["dt"])}


class LavaFixed(_Lava):
    name = "lava-fixed"
    description = "Lava processes, bit-accurate fixed-point models (CPU)"
    tag = "fixed_pt"
    OPTIONS = {
        "profile": Option("loihi2", "fixed-point chip profile (name or TOML file)", None),
        "dt": Option(None, "time step [s] (default: the profile's)", positive_float("dt")),
    }
    CONFORMANCE_OPTIONS = {"dt": CONFORMANCE_DT}

    def __init__(self, **options: object) -> None:
        super().__init__(**options)
        # The same profile and step as the fixed-point reference, checked the same way.
        self._reference = FixedPointBackend(**options)

    @property
    def capabilities(self) -> Capabilities:
        return replace(self._reference.capabilities, threads=False)

    def realised(self, network):
        """The network as the fixed-point reference of the same profile and step realises it."""
        return self._reference.realised(network)

    def _settings(self) -> dict:
        return {"profile": str(self.options["profile"]), "dt": self.options["dt"]}
