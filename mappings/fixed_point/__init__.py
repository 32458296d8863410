"""The fixed-point reference as a backend: a digital chip's integer arithmetic, bit for bit.

:class:`~mappings.fixed_point.backend.FixedPointBackend` (registered as ``golden-fixed-point``)
quantizes a network to a fixed-point chip profile (``quantize``) and steps its integers in the
Rust core (``engine/src/fixed_point.rs``, which specifies the model). Lava's ``fixed_pt`` models
and the USB board emulator reproduce it spike for spike.
"""

from .backend import SATURATION_NAMES, STATE_NAMES, FixedPointBackend

__all__ = ["SATURATION_NAMES", "STATE_NAMES", "FixedPointBackend"]
