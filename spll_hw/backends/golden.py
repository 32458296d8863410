"""``golden``: the exact event-driven model of the Rust core as a backend.

Every other backend is judged against it. Options: ``profile`` (simulate the network as a chip
profile realises it: the exact behaviour of the quantized or mismatched parameters),
``chip_seed`` (an analog profile's mismatch draw), ``exact`` (parameters the profile leaves at
their requested values, e.g. ``golden:profile=loihi2:exact=tau_tde_fac``: what that format
costs) and ``max_events`` (the event limit per sPLL
and run, past which a run is an error rather than a hang).
"""

from __future__ import annotations

import numpy as np

from ..result import SimulationResult
from ..simulate import DEFAULT_MAX_EVENTS, simulate, simulate_batch
from .base import EXACT_OPTION, PROFILE_OPTIONS, Backend, Capabilities, Option, positive_int


class GoldenBackend(Backend):
    """The golden model (:func:`spll_hw.simulate` / :func:`spll_hw.simulate_batch`)."""

    name = "golden"
    description = "exact event-driven model (Rust core)"
    OPTIONS = {
        **PROFILE_OPTIONS,
        "exact": EXACT_OPTION,
        "max_events": Option(
            DEFAULT_MAX_EVENTS,
            "event limit of a run (an error past it)",
            positive_int("max_events"),
        ),
    }

    @property
    def capabilities(self) -> Capabilities:
        return Capabilities(
            exact=True, dt=None, arithmetic="float", resume=True, probes=True, threads=True
        )

    def gate(self, network):
        """The gate the engine applies in place of the product ``g_tde_trg * I_fac`` for
        ``network`` (``None``: the golden product; see the ``gate`` argument of
        :func:`spll_hw.simulate`). Backends of constructions override it."""
        return None

    def _run(
        self, prepared, trains: list[np.ndarray], duration: float, *, threads, record_spikes,
        **extras,
    ) -> list[SimulationResult]:  # fmt: skip
        gate = self.gate(prepared)
        if extras or (len(trains) == 1 and threads is None):
            # One sample: the engine spreads its sPLLs over the cores (and resumes, probes).
            probes = extras.get("probe_times")
            return [
                simulate(
                    prepared, trains[0], duration, record_spikes=record_spikes,
                    state=extras.get("state"), probe_times=probes,
                    max_events=self.options["max_events"], gate=gate,
                )
            ]  # fmt: skip
        return simulate_batch(
            prepared, trains, duration, record_spikes=record_spikes, threads=threads,
            max_events=self.options["max_events"], gate=gate,
        )  # fmt: skip
