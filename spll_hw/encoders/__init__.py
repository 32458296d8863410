"""Pressure → spike-time encoders (thesis 2.2).

Every encoder has a ``name`` and ``encode(signals, fs, ids=None) -> list[np.ndarray]``: one row of
``signals`` (shape ``(n, L)``, sampled at ``fs`` Hz) per sample in, one sorted array of spike
times [s] per sample out. ``ids`` name the samples so that stochastic encoders seed their noise
per sample, independent of batching.
"""

from __future__ import annotations

import dataclasses
from typing import Protocol

import numpy as np

from .lif import LIFEncoder
from .pacinian import PacinianEncoder
from .peak_oscillator import PeakOscillatorEncoder


class Encoder(Protocol):
    name: str

    def encode(self, signals: np.ndarray, fs: float, ids=None) -> list[np.ndarray]: ...


#: Encoder classes by CLI name.
ENCODERS: dict[str, type] = {
    "lif": LIFEncoder,
    "pacinian": PacinianEncoder,
    "peak": PeakOscillatorEncoder,
}


def encoder_fields(name: str) -> dict[str, str]:
    """The parameters of encoder ``name`` (a key of :data:`ENCODERS`) with their annotations as
    text (e.g. ``{"gain": "float", "normalize": "str"}``); ``ValueError`` for an unknown name."""
    if name not in ENCODERS:
        raise ValueError(f"unknown encoder {name!r}; choose from {sorted(ENCODERS)}")
    return {f.name: str(f.type) for f in dataclasses.fields(ENCODERS[name])}


def _flag_value(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return str(value).lower()
    return repr(value) if isinstance(value, float) else str(value)


def settings_flags(encoder: Encoder) -> str:
    """The ``--set`` options (of ``spll-hw evaluate``/``tune``) that rebuild ``encoder`` from its
    defaults, e.g. ``--set pacinian.model=2 --set pacinian.rms_um=39.8``; ``""`` for a default
    encoder. Floats are written exactly (``repr``), ``None`` as ``none``."""
    default = type(encoder)()
    return " ".join(
        f"--set {encoder.name}.{f.name}={_flag_value(getattr(encoder, f.name))}"
        for f in dataclasses.fields(encoder)
        if getattr(encoder, f.name) != getattr(default, f.name)
    )


def parse_setting(name: str, param: str, text: str):
    """The value of encoder ``name``'s parameter ``param`` written as ``text`` in the ``--set``
    syntax (``none`` for ``None``, ``true``/``false`` for booleans, numbers as Python reads them).

    ``ValueError`` for an unknown encoder or parameter, or a value of the wrong type (a float
    must be finite: NaN and infinities are refused).
    """
    fields = encoder_fields(name)
    if param not in fields:
        raise ValueError(f"{name} has no parameter {param!r}; it has {sorted(fields)}")
    annotation = fields[param]
    value = text.strip()
    if "None" in annotation and value.lower() == "none":
        return None
    try:
        if annotation.startswith("bool"):
            if value.lower() not in ("true", "false", "1", "0", "yes", "no"):
                raise ValueError
            return value.lower() in ("true", "1", "yes")
        if annotation.startswith("int"):
            return int(value)
        if annotation.startswith("float"):
            number = float(value)
            if not np.isfinite(number):
                raise ValueError
            return number
    except ValueError:
        finite = "a finite " if annotation.startswith("float") else ""
        raise ValueError(f"{name}.{param} must be {finite}{annotation}, got {text!r}") from None
    return value


def settings_table(encoder: Encoder, input_level: float | None = None) -> str:
    """Every setting of ``encoder`` as the ``[encoder]`` table of a network TOML file
    (:func:`spll_hw.config.read_encoder_table` reads it back): its ``name`` and each field,
    ``None`` written as ``"none"``. All fields are written, not only those off their defaults,
    so that the file keeps meaning the same encoder when a default changes. ``input_level``
    (the signal level the encoder was tuned at, :mod:`spll_hw.config`) is written after them."""
    lines = ["[encoder]", f'name = "{encoder.name}"']
    for f in dataclasses.fields(encoder):
        value = getattr(encoder, f.name)
        if value is None or isinstance(value, str):
            value = f'"{_flag_value(value)}"'
        else:
            value = _flag_value(value)
        lines.append(f"{f.name} = {value}")
    if input_level is not None:
        lines.append(f"input_level = {float(input_level)!r}  # the signal level it was tuned at")
    return "\n".join(lines) + "\n"


#: The encoder field that, when set, is the length [s] of its spike trains (:func:`train_duration`).
TRAIN_LENGTH_FIELD = "duration"


def train_duration(encoder: Encoder, sample_duration: float) -> float:
    """Length [s] of the spike trains ``encoder`` makes from samples ``sample_duration`` s long:
    the encoder's own ``duration`` when it sets one (the peak oscillator's trains are stationary
    and can run longer than the sample), else the sample's. Features, phase noise and rates
    use this window."""
    own = getattr(encoder, TRAIN_LENGTH_FIELD, None)
    return float(own) if own is not None else float(sample_duration)


def make_encoder(name: str, **params) -> Encoder:
    """Build the encoder called ``name`` (a key of :data:`ENCODERS`) with keyword ``params``."""
    encoder_fields(name)  # raises on an unknown name
    try:
        return ENCODERS[name](**params)
    except TypeError as exc:
        raise ValueError(f"bad parameters for encoder {name!r}: {exc}") from exc


__all__ = [
    "ENCODERS",
    "Encoder",
    "LIFEncoder",
    "PacinianEncoder",
    "PeakOscillatorEncoder",
    "TRAIN_LENGTH_FIELD",
    "encoder_fields",
    "make_encoder",
    "parse_setting",
    "settings_flags",
    "settings_table",
    "train_duration",
]
