"""quantize: sPLL networks under hardware constraints.

* :func:`quantize` constrains a :class:`spll_hw.Network` to a chip profile and reports, per
  parameter, the requested and realised value, the relative error and what saturated;
* chip profiles are TOML data files (:func:`load_profile`; bundled: ``loihi2``, ``fixed16``,
  ``analog``; :func:`generic_fixed_point` for any width);
* :func:`simulate_fixed_point` runs the discrete-time fixed-point reference in the Rust core,
  the behaviour a digital chip shows, bit for bit;
* :func:`grouped_layout` places G time-scale groups as close as possible to the time-scaled
  network.

::

    import quantize
    from spll_hw import simulate

    q = quantize.quantize(net, "loihi2")
    print(q.report_markdown())                    # what the chip does to each parameter
    exact = simulate(q.network, spikes, 2.0)      # golden model of the quantized values
    chip = quantize.simulate_fixed_point(q, spikes, 2.0)   # integer, discrete time
"""

from .core import ParamReport, QuantizationReport, QuantizedNetwork, quantize
from .fixed_point import (
    FIXED_PARAM_NAMES,
    SATURATION_NAMES,
    STATE_NAMES,
    FixedPointNetwork,
    simulate_fixed_point,
    simulate_fixed_point_batch,
    spike_steps,
)
from .layouts import GroupedLayout, circuit_count, grouped_layout, partition
from .profiles import (
    AnalogProfile,
    FixedPointProfile,
    ProfileError,
    available_profiles,
    generic_fixed_point,
    load_profile,
    parse_profile,
)

__all__ = [
    "FIXED_PARAM_NAMES",
    "SATURATION_NAMES",
    "STATE_NAMES",
    "AnalogProfile",
    "FixedPointNetwork",
    "FixedPointProfile",
    "GroupedLayout",
    "ParamReport",
    "ProfileError",
    "QuantizationReport",
    "QuantizedNetwork",
    "available_profiles",
    "circuit_count",
    "generic_fixed_point",
    "grouped_layout",
    "load_profile",
    "parse_profile",
    "partition",
    "quantize",
    "simulate_fixed_point",
    "simulate_fixed_point_batch",
    "spike_steps",
]
