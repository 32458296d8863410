"""Time steps as people write them: ``80us``, ``0.08ms``, ``8e-5``; a ladder of them; and the
name of a clocked chip profile at another step.

A clocked chip profile ``NAME`` stepped every ``STEP`` is named ``NAME@STEP`` (``loihi2@80us``);
the provider of the profile resolves it (:mod:`quantize.steps`), so every command that takes a
profile takes one at a step. ``--steps`` ladders (``report``, ``chips``, ``fit``) put every
clocked profile at each step of the ladder (:func:`at_steps`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from decimal import Decimal, InvalidOperation

#: Units a step may be written in: their power of ten in seconds.
_UNITS = {"": 0, "s": 0, "ms": -3, "us": -6, "ns": -9}
_STEP = re.compile(r"^\s*([0-9.]+(?:e[-+]?[0-9]+)?)\s*(s|ms|us|µs|ns)?\s*$", re.IGNORECASE)
#: Sane bounds of a step [s]: below a nanosecond or above a second no chip steps.
STEP_RANGE = (1e-9, 1.0)
#: The default ladder [s] of ``--steps`` (each step twice the last).
DEFAULT_LADDER = (10e-6, 20e-6, 40e-6, 80e-6, 160e-6)


def parse_step(text: str) -> float:
    """A time step [s] from ``"80us"``, ``"80 µs"``, ``"0.08ms"``, ``"8e-5"`` or ``"8e-5 s"``;
    ``ValueError`` naming the text for anything else or a step outside :data:`STEP_RANGE`."""
    match = _STEP.match(str(text))
    if match is None:
        raise ValueError(
            f"time step {text!r}: write a number with a unit, e.g. 80us, 0.08ms or 8e-5 (s)"
        )
    number, unit = match.groups()
    try:  # decimal, so that 80us is 8e-5 exactly as written, not 7.999999999999999e-05
        seconds = float(Decimal(number).scaleb(_UNITS[(unit or "").lower().replace("µ", "u")]))
    except InvalidOperation:
        raise ValueError(f"time step {text!r}: {number!r} is not a number") from None
    return checked_step(seconds, f"time step {text!r} = {seconds:g} s")


def checked_step(seconds: float, what: str) -> float:
    """``seconds`` where it is a finite step within :data:`STEP_RANGE`; else ``ValueError``
    naming ``what`` (the step as given, and where from) and the range."""
    low, high = STEP_RANGE
    if not (math.isfinite(seconds) and low <= seconds <= high):
        raise ValueError(f"{what}: a step lies in [{low:g}, {high:g}] s")
    return seconds


def step_label(dt: float) -> str:
    """``8e-5`` -> ``"80us"``: the step as a profile name's suffix (µs, ns or ms, no spaces)."""
    for unit, scale in (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if dt >= scale or unit == "ns":
            return f"{dt / scale:.6g}{unit}"
    raise AssertionError("unreachable")


def parse_ladder(text: str) -> tuple[float, ...]:
    """``"10,20,40us"`` or ``"1e-5,2e-5"`` -> steps [s], sorted, duplicates dropped; a unit after
    the last number applies to every bare number before it."""
    parts = [p.strip() for p in str(text).split(",") if p.strip()]
    if not parts:
        raise ValueError("--steps needs at least one step, e.g. 10,20,40,80,160us")
    unit = re.sub(r"^[0-9.eE+-]+", "", parts[-1].replace(" ", ""))
    steps = []
    for part in parts:
        bare = re.fullmatch(r"[0-9.]+(?:[eE][-+]?[0-9]+)?", part) is not None
        steps.append(parse_step(part + unit if bare and unit else part))
    return tuple(sorted(set(steps)))


def at_step(source: str, dt: float) -> str:
    """The name of chip profile ``source`` stepped every ``dt`` [s]: ``"loihi2@80us"`` (a name
    at a step already is re-stepped)."""
    return f"{str(source).rpartition('@')[0] or source}@{step_label(dt)}"


def at_steps(sources: Sequence[str], clocked: Sequence[bool], steps: Sequence[float]) -> list[str]:
    """``sources`` with every clocked one (``clocked[i]``) replaced by itself at each of
    ``steps`` [s], in order; unclocked ones (``none``, analog chips) as they are."""
    out: list[str] = []
    for source, has_clock in zip(sources, clocked, strict=True):
        out += [at_step(source, dt) for dt in steps] if has_clock and steps else [source]
    return out
