"""spll-hw: exact golden model and hardware mappings for networks of spiking phase-locked loops.

The main entry points::

    from spll_hw import SpllParams, Network, network_frequencies, simulate, simulate_batch
"""

from .activity import SilentNetworkWarning
from .network import Network, network_frequencies
from .params import PARAM_NAMES, SpllParams, free_frequency, offset_for_frequency
from .result import SimulationResult
from .simulate import (
    EngineState,
    Trace,
    UnverifiedStateWarning,
    frequency_response,
    periodic_spikes,
    simulate,
    simulate_batch,
)

__all__ = [
    "PARAM_NAMES",
    "EngineState",
    "Network",
    "SilentNetworkWarning",
    "SimulationResult",
    "SpllParams",
    "Trace",
    "UnverifiedStateWarning",
    "free_frequency",
    "frequency_response",
    "network_frequencies",
    "offset_for_frequency",
    "periodic_spikes",
    "simulate",
    "simulate_batch",
]
