"""Every simulator of an sPLL network behind one registry.

Backends register themselves in the ``spll_hw.backends`` entry-point group (spll-hw's own in its
``pyproject.toml``; a package outside this repository adds one the same way), so the core never
names a mapping module. A backend is chosen by a **spec**: ``NAME`` or
``NAME:key=value:key=value`` (values that look like numbers become numbers), e.g. ``golden``,
``golden:profile=loihi2``, ``golden-fixed-point:profile=loihi2:dt=1e-5``,
``brian2-cpp_standalone:dt=1e-5``; lists of specs are comma-separated.

::

    from spll_hw import backends

    fixed = backends.get("golden-fixed-point:profile=loihi2")
    rates = fixed.rates(network, trains, 2.0)          # (n_samples, n_spll) TDE rates [Hz]
    for entry in backends.listing():                   # what `spll-hw backends` prints
        print(entry.name, entry.unavailable or "available")

The protocol is :class:`~spll_hw.backends.base.Backend`; :mod:`spll_hw.backends.conformance`
checks that a backend keeps it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, lru_cache
from importlib.metadata import entry_points

from ..network import Network
from ..result import SimulationResult
from .base import Backend, Capabilities, Option

#: Entry-point group backends register in.
GROUP = "spll_hw.backends"


@cache
def _entry_points() -> dict:
    return {ep.name: ep for ep in entry_points(group=GROUP)}


def names() -> list[str]:
    """Registered backend names, ``golden`` (the reference) first."""
    return sorted(_entry_points(), key=lambda name: (name != "golden", name))


def backend_class(name: str) -> type[Backend]:
    """The class registered as ``name``; ``ValueError`` for an unknown name or a registration
    that does not load."""
    eps = _entry_points()
    if name not in eps:
        raise ValueError(f"unknown backend {name!r}; known: {', '.join(eps) or 'none'}")
    try:
        cls = eps[name].load()
    except Exception as exc:  # a third-party module that fails to import is reported, not raised
        raise ValueError(
            f"backend {name!r} is registered as {eps[name].value!r}, which does not load: "
            f"{type(exc).__name__}: {exc}"
        ) from exc
    if not (isinstance(cls, type) and issubclass(cls, Backend)) or cls.name != name:
        raise ValueError(
            f"backend {name!r} is registered as {eps[name].value!r}, which is not a "
            f"spll_hw.backends.base.Backend subclass named {name!r}"
        )
    return cls


def parse_spec(spec: str) -> tuple[str, dict]:
    """``"brian2-numpy:dt=1e-5"`` → ``("brian2-numpy", {"dt": 1e-05})``; the name must be
    registered (options are checked by :func:`get`)."""
    name, _, rest = spec.strip().partition(":")
    if name not in _entry_points():
        raise ValueError(f"unknown backend {name!r}; known: {', '.join(names())}")
    options: dict = {}
    for item in filter(None, rest.split(":")):
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise ValueError(f"backend option {item!r} in {spec!r} must look like key=value")
        if key.strip() in options:
            raise ValueError(f"backend option {key.strip()!r} is given twice in {spec!r}")
        options[key.strip()] = _number_or_text(value.strip())
    return name, options


def get(spec: str | Backend, **options: object) -> Backend:
    """The configured backend of ``spec`` (plus keyword ``options``), ready to run.

    Raises ``ValueError`` for an unknown name or option, a bad option value (an unknown chip
    profile, say) or a backend that is not available here (the message says why: a missing
    extra to install, no board attached).

    A spec string is parsed and its options converted once: the same string gives the same
    configured object (configurations are immutable), which keeps what it prepared for a
    network (:meth:`~spll_hw.backends.base.Backend.prepared`), so passing a spec down a long
    workload costs what passing the object does.
    """
    if isinstance(spec, Backend):
        if not options:
            return spec
        own = {k: v for k, v in spec.options.items() if v != spec.OPTIONS[k].default}
        return type(spec)(**(own | options))
    if not options:
        return _configured(spec.strip())
    return _make(spec, options)


@lru_cache(maxsize=64)
def _configured(spec: str) -> Backend:
    """The configured backend of a spec string, made once (:func:`get`)."""
    return _make(spec, {})


def _make(spec: str, options: dict) -> Backend:
    name, parsed = parse_spec(spec)
    cls = backend_class(name)
    reason = cls.unavailable()
    if reason is not None:
        raise ValueError(f"backend {name!r} is not available here: {reason}")
    return cls(**(parsed | options))


def parse_specs(specs: str) -> list[str]:
    """Split a comma-separated list of specs, checking each fully (:func:`get`)."""
    items = [s.strip() for s in specs.split(",") if s.strip()]
    for item in items:
        get(item)
    return items


def label(spec: str | Backend) -> str:
    """Backend ``spec`` as reports and summaries show it (:attr:`~spll_hw.backends.base.
    Backend.label`: also naming a chip profile that is the backend's default); ``spec`` itself
    where it cannot be configured here (a backend not installed on this machine)."""
    try:
        return get(spec).label
    except ValueError:
        return str(spec)


def run(spec: str, network: Network, inputs, duration: float, **kwargs) -> SimulationResult:
    """One input train through ``network`` on backend ``spec``
    (:meth:`~spll_hw.backends.base.Backend.simulate`)."""
    return get(spec).simulate(network, inputs, duration, **kwargs)


@dataclass(frozen=True)
class Entry:
    """One registered backend as ``spll-hw backends`` lists it.

    ``unavailable`` is why it cannot run here (``None``: it can); ``capabilities`` are those of
    its default configuration (``None`` when it does not load).
    """

    name: str
    description: str
    target: str
    extra: str | None
    options: dict[str, Option]
    unavailable: str | None
    capabilities: Capabilities | None


def listing() -> list[Entry]:
    """Every registered backend with its capabilities and availability."""
    out = []
    for name in names():
        ep = _entry_points()[name]
        try:
            cls = backend_class(name)
        except ValueError as exc:
            out.append(Entry(name, "", ep.value, None, {}, str(exc), None))
            continue
        reason = cls.unavailable()
        try:
            caps = cls().capabilities
        except ValueError as exc:
            caps, reason = None, reason or str(exc)
        out.append(Entry(name, cls.description, ep.value, cls.extra, cls.OPTIONS, reason, caps))
    return out


def available() -> list[str]:
    """Names of the backends that can run here."""
    return [e.name for e in listing() if e.unavailable is None]


def _number_or_text(value: str):
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    return value


__all__ = [
    "GROUP",
    "Backend",
    "Capabilities",
    "Entry",
    "Option",
    "available",
    "backend_class",
    "get",
    "label",
    "listing",
    "names",
    "parse_spec",
    "parse_specs",
    "run",
]
