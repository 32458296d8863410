"""Every simulator of an sPLL network behind one call: ``run(backend_spec, network, inputs, T)``.

A backend takes a :class:`~spll_hw.network.Network`, one input spike train [s] and a duration [s]
and returns a :class:`~spll_hw.result.SimulationResult`. Specs are ``NAME`` or
``NAME:key=value:key=value`` (values parsed as numbers where they look like numbers), e.g.
``golden``, ``brian2-cpp_standalone:dt=1e-5``, ``golden-fixed-point:profile=loihi2``; a list
of specs is comma-separated (``golden,lava-fixed,brian2-numpy:dt=1e-6``).

Backends other than ``golden`` live in optional packages; they are imported only when used, and
a missing one is reported with the ``pip install`` extra that provides it.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass

from .network import Network
from .result import SimulationResult


@dataclass(frozen=True)
class Backend:
    """Where a backend's runner lives, its fixed options and which extra installs it."""

    name: str
    target: str  # "module:function", called as function(network, inputs, duration, **options)
    extra: str | None
    description: str
    defaults: tuple[tuple[str, object], ...] = ()

    def load(self) -> Callable[..., SimulationResult]:
        module_name, _, function = self.target.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            hint = f" (install it with: pip install -e '.[{self.extra}]')" if self.extra else ""
            raise ValueError(f"backend {self.name!r} is not available: {exc}{hint}") from exc
        return getattr(module, function)


#: The known backends, in the order reports list them.
BACKENDS: dict[str, Backend] = {
    b.name: b
    for b in (
        Backend("golden", "spll_hw.simulate:simulate", None, "exact event-driven model (Rust)"),
        Backend(
            "golden-fixed-point",
            "quantize:simulate_fixed_point",
            None,
            "discrete-time fixed-point reference of a chip profile (Rust)",
        ),
        *(
            Backend(
                f"brian2-{target}",
                "mappings.brian2:simulate_brian2",
                "brian2",
                f"Brian2 ({target} code generation), clock-driven",
                (("target", target),),
            )
            for target in ("numpy", "cython", "cpp_standalone")
        ),
        Backend(
            "lava-float",
            "mappings.lava:simulate_lava",
            "lava",
            "Lava processes, floating-point models (CPU)",
            (("tag", "floating_pt"),),
        ),
        Backend(
            "lava-fixed",
            "mappings.lava:simulate_lava",
            "lava",
            "Lava processes, bit-accurate fixed-point models (CPU)",
            (("tag", "fixed_pt"),),
        ),
        Backend("usb", "mappings.usb:simulate_usb", "usb", "a USB board (or its emulator)"),
    )
}


def parse_spec(spec: str) -> tuple[str, dict]:
    """``"brian2-numpy:dt=1e-5"`` -> ``("brian2-numpy", {"target": "numpy", "dt": 1e-05})``."""
    name, _, rest = spec.strip().partition(":")
    if name not in BACKENDS:
        raise ValueError(f"unknown backend {name!r}; known: {', '.join(BACKENDS)}")
    options: dict = dict(BACKENDS[name].defaults)
    for item in filter(None, rest.split(":")):
        key, eq, value = item.partition("=")
        if not eq or not key:
            raise ValueError(f"backend option {item!r} in {spec!r} must look like key=value")
        options[key.strip()] = _number_or_text(value.strip())
    return name, options


def parse_specs(specs: str) -> list[str]:
    """Split a comma-separated list of specs, checking each."""
    items = [s.strip() for s in specs.split(",") if s.strip()]
    for item in items:
        parse_spec(item)
    return items


def run(spec: str, network: Network, inputs, duration: float, **extra) -> SimulationResult:
    """Simulate ``inputs`` through ``network`` on the backend ``spec`` (options of the spec and
    ``extra`` keyword arguments are passed to the backend's runner)."""
    name, options = parse_spec(spec)
    return BACKENDS[name].load()(network, inputs, duration, **options, **extra)


def _number_or_text(value: str):
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    return value
