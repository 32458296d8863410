"""Brian2 backend: the sPLL network as Brian2 NeuronGroups and Synapses, clock-driven.

:func:`simulate_brian2` runs a :class:`~spll_hw.network.Network` on one input spike train with a
codegen target (``"numpy"``, ``"cython"`` or ``"cpp_standalone"``) and a fixed time step, and
returns the golden engine's result type. Brian2 itself is an optional dependency
(``pip install -e .[brian2]``) imported only when a simulation runs; :func:`dt_warnings` needs
only numpy.
"""

from .checks import DtResolutionWarning, dt_warnings
from .run import TARGETS, simulate_brian2, simulate_brian2_batch

__all__ = [
    "TARGETS",
    "DtResolutionWarning",
    "dt_warnings",
    "simulate_brian2",
    "simulate_brian2_batch",
]
