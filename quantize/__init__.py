"""quantize: sPLL networks under hardware constraints (number formats, mismatch, budgets).

* :func:`quantize` constrains a :class:`spll_hw.Network` to a chip profile and reports, per
  parameter, the requested and realised value, the relative error and what saturated; for a
  fixed-point profile it also gives the integer parameters a digital chip runs;
* chip profiles are TOML data files (:func:`load_profile`; bundled: ``loihi2``, ``fixed16``,
  ``analog``; :func:`generic_fixed_point` for any width).

This package describes and does not simulate: the golden model simulates the realised network
(backend ``golden:profile=loihi2``), and the ``golden-fixed-point`` backend runs the integers
(``mappings/fixed_point``). It registers its profiles with the core (``spll_hw.chips``)::

    import quantize
    from spll_hw import backends

    q = quantize.quantize(net, "loihi2")
    print(q.report_markdown())                                   # what the chip does
    exact = backends.get("golden:profile=loihi2").simulate(net, spikes, 2.0)
    chip = backends.get("golden-fixed-point:profile=loihi2").simulate(net, spikes, 2.0)
"""

from spll_hw.model.grid import spike_steps

from .core import QuantizedNetwork, quantize
from .fixed_point import FIXED_PARAM_NAMES, FixedPointNetwork
from .profiles import (
    AnalogProfile,
    FixedPointProfile,
    ProfileError,
    available_profiles,
    generic_fixed_point,
    load_profile,
    parse_profile,
    profile_toml,
)
from .report import ParamReport, QuantizationReport

__all__ = [
    "FIXED_PARAM_NAMES",
    "AnalogProfile",
    "FixedPointNetwork",
    "FixedPointProfile",
    "ParamReport",
    "ProfileError",
    "QuantizationReport",
    "QuantizedNetwork",
    "available_profiles",
    "generic_fixed_point",
    "load_profile",
    "parse_profile",
    "profile_toml",
    "quantize",
    "spike_steps",
]
