"""Chip profiles, reached through a registry: the core never imports the package that
implements them.

A chip profile says what a chip does to a network: rounds its parameters to number formats,
mismatches them, limits its circuits. The package that knows profiles (``quantize``) registers a
provider in the ``spll_hw.profiles`` entry-point group; this module asks it to

* :func:`describe` a profile (name or TOML file) — its name, kind and description, failing with
  a clear error for an unknown or broken one before any work;
* :func:`realise` a network on a profile — the network the chip implements, in SI units, and a
  Markdown report of what changed; a network that does not fit raises ``ValueError``;
* list the bundled profiles (:func:`names`).

A provider is any object with ``names()``, ``describe(source)`` and
``realise(network, source, seed)`` returning :class:`ProfileInfo` / :class:`Realisation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib.metadata import entry_points

from .network import Network

#: Entry-point group of profile providers.
GROUP = "spll_hw.profiles"
#: Profile kinds: digital chips with integer formats, mixed-signal chips with mismatch.
KINDS = ("fixed-point", "analog")


@dataclass(frozen=True)
class ProfileInfo:
    """What a profile is: ``name``, ``kind`` (one of :data:`KINDS`) and a one-line
    ``description``."""

    name: str
    kind: str
    description: str


@dataclass(frozen=True)
class Realisation:
    """A network as a chip implements it.

    Attributes:
        network: the realised network (SI units), simulated exactly by the golden model.
        profile: the profile it was realised on.
        report: Markdown: requested against realised value of every parameter, warnings.
        detail: the provider's own object (``quantize.QuantizedNetwork``), for backends of
            the same package (e.g. the integer parameters of a fixed-point profile).
    """

    network: Network
    profile: ProfileInfo
    report: str
    detail: object = None


@cache
def provider():
    """The registered profile provider; ``ValueError`` when none is installed."""
    found = list(entry_points(group=GROUP))
    if not found:
        raise ValueError(
            f"no chip profiles are installed (nothing registers the {GROUP!r} entry-point "
            "group; reinstall spll-hw: pip install -e .)"
        )
    return found[0].load()


def names() -> list[str]:
    """Bundled profile names."""
    return list(provider().names())


def describe(source: str) -> ProfileInfo:
    """The profile ``source`` (a bundled name or a TOML path); ``ValueError`` naming what is
    wrong when it is unknown or broken."""
    return provider().describe(source)


def realise(network: Network, source: str, seed: int | None = None) -> Realisation:
    """``network`` as chip profile ``source`` implements it; ``seed`` picks an analog
    profile's mismatch draw (default: the profile's own). ``ValueError`` when it does not fit."""
    return provider().realise(network, source, seed)
