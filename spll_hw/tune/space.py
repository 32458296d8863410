"""The tuning search space: thesis Table 5 by default, overridable from a TOML file.

Every dimension is a float range (``log`` or linear), a list of choices, or a fixed value. Names are
the :class:`~spll_hw.params.SpllParams` fields (SI units: seconds, dimensionless gains) except
``i_cco_offset`` (set from each sPLL's free-running frequency), plus the network's ``f_start`` and
``f_end`` [Hz] and log offset ``beta`` (thesis 2.5). A file overrides Table 5 entry by entry::

    [space]
    tau_cco = { low = 0.05, high = 0.5, log = true }
    beta = { choices = [1, 10, 100, inf] }
    g_cco = 2.0                 # fixed, not tuned
    spread = { low = 0.0, high = 1.0 }   # optional, beyond the thesis: per-sPLL diversity
    "pacinian.rms_um" = { low = 5.0, high = 80.0, log = true }   # optional: the encoder too
    "pacinian.model" = { choices = [0, 1, 2, 3] }

``spread`` (default 0, the thesis's networks) is the sigma of the per-sPLL lognormal variation of
time constants and gains with calibrated offsets (:meth:`spll_hw.network.Network.with_spread`),
drawn with the study's seed. It is not in Table 5; add it to tune networks whose sPLLs differ.

``<encoder>.<parameter>`` names (quoted in TOML) tune a numeric parameter of the study's encoder
together with the network (:mod:`spll_hw.encoders`; the thesis fixes the encoders, but it does
not say how TouchSim's input was scaled nor which of its four PC models ran). Float parameters take
ranges, integer ones (``pacinian.model``) choices; every trial then re-encodes the samples.

Constraints (thesis 2.4.2): the TDE synapses must forget an input spike before the next one
arrives (``tau_syn < 1 / f_in``) and be faster than the TDE membrane (``tau_syn < tau_tde``). We
read ``f_in`` as each sPLL's own free-running frequency ``f_i``, so for a vary-offset network the
binding bound is ``1 / f_end`` (the "1/f_max" of the thesis) and for a time-scaled one it is
``1 / reference_frequency`` on the base sPLL (Table 5's upper bound, 0.02 s at 50 Hz).
:func:`constraint_values` returns them as ratios minus one, feasible when <= 0. The thesis's own
tuned networks break them (Table 6, e.g. BioTac vary-offset LIF: tau_fac = 12.5 ms at 669 Hz),
so whether they are enforced, penalised or ignored is a study option.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from ..config import NetworkConfig
from ..encoders import TRAIN_LENGTH_FIELD, Encoder, encoder_fields, make_encoder
from ..network import network_frequencies
from ..params import SpllParams, read_toml

NETWORK_PARAMS = ("f_start", "f_end", "beta", "spread")
#: Network parameters a space may leave out, with the value used then (the thesis's networks).
NETWORK_DEFAULTS = {"spread": 0.0}
#: Names a search space may contain: sPLL parameters (not the offset current) and network ones.
KNOWN_PARAMS = tuple(f.name for f in fields(SpllParams) if f.name != "i_cco_offset") + (
    NETWORK_PARAMS
)

#: Separates the encoder from its parameter in an encoder dimension's name (``pacinian.model``).
ENCODER_SEP = "."

#: Constraint names, in the order :func:`constraint_values` returns them.
CONSTRAINTS = ("tau_tde_fac*f", "tau_tde_trg*f", "tau_tde_fac/tau_tde", "tau_tde_trg/tau_tde")
CONSTRAINT_MODES = ("penalise", "enforce", "off")

#: A valid sPLL (Table 6, VibTac vary-offset LIF): dimensions are checked by replacing one field.
PROBE_SPLL = NetworkConfig.preset("vibtac-vary-offset-lif").spll


@dataclass(frozen=True)
class Dimension:
    """One tuned (or fixed) parameter.

    Exactly one of: ``low``/``high`` (float range, ``log`` spacing or linear), ``choices``
    (categorical), ``value`` (fixed). ``ValueError`` names the parameter on bad bounds.
    """

    name: str
    low: float | None = None
    high: float | None = None
    log: bool = False
    choices: tuple[float, ...] | None = None
    value: float | None = None

    def __post_init__(self) -> None:
        where = f"search space: {self.name}"
        if ENCODER_SEP in self.name:
            encoder_field_type(self.name)  # raises on an unknown encoder or parameter
        elif self.name not in KNOWN_PARAMS:
            raise ValueError(
                f"search space: unknown parameter {self.name!r}; known: {list(KNOWN_PARAMS)} "
                f"and <encoder>.<parameter> (e.g. pacinian.rms_um)"
            )
        kinds = [self.low is not None or self.high is not None, self.choices is not None]
        kinds.append(self.value is not None)
        if sum(kinds) != 1:
            raise ValueError(f"{where}: give low and high, or choices, or one fixed value")
        if kinds[0]:
            self._check_range(where)
        if self.choices is not None:
            if len(self.choices) == 0:
                raise ValueError(f"{where}: empty list of choices")
            if len(set(self.choices)) != len(self.choices):
                raise ValueError(f"{where}: repeated choices {list(self.choices)}")
        self._check_numbers(where)

    def _check_range(self, where: str) -> None:
        """A range has both ends, ``low < high``, and ``low > 0`` on a log scale."""
        if self.low is None or self.high is None:
            raise ValueError(f"{where}: a range needs both low and high")
        if not self.low < self.high:
            what = "empty" if self.low == self.high else "reversed"
            raise ValueError(
                f"{where}: {what} range [{self.low!r}, {self.high!r}] (need low < high; "
                "give a single number to fix a parameter)"
            )
        if self.log and self.low <= 0:
            raise ValueError(f"{where}: a log range needs low > 0, got {self.low!r}")

    def _check_numbers(self, where: str) -> None:
        """Every bound is a number the parameter can take (an integer encoder parameter:
        whole numbers, as choices or a fixed value)."""
        for v in self.extremes:
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise ValueError(f"{where}: {v!r} is not a number")
        if ENCODER_SEP in self.name and encoder_field_type(self.name) == "int":
            if self.kind == "range":
                raise ValueError(
                    f"{where}: an integer encoder parameter takes choices (e.g. "
                    "choices = [0, 1, 2, 3]) or one fixed value, not a range"
                )
            if any(float(v) != int(v) for v in self.extremes):
                raise ValueError(f"{where}: {list(self.extremes)} are not all integers")
        _check_values(self.name, self.extremes)

    @property
    def kind(self) -> str:
        """``"range"``, ``"choice"`` or ``"fixed"``."""
        if self.choices is not None:
            return "choice"
        return "fixed" if self.value is not None else "range"

    @property
    def extremes(self) -> tuple[float, ...]:
        """The values that bound this dimension (both ends, every choice, or the fixed value)."""
        if self.kind == "range":
            return (self.low, self.high)
        return self.choices if self.kind == "choice" else (self.value,)

    def contains(self, value: float) -> bool:
        """Whether ``value`` is one this dimension can take (in the range, a choice, the value)."""
        if self.kind == "range":
            return self.low <= value <= self.high
        return value in self.extremes

    def to_dict(self) -> dict:
        """JSON-able description (``inf`` as the string ``"inf"``)."""
        if self.kind == "range":
            return {"low": self.low, "high": self.high, "log": self.log}
        if self.kind == "choice":
            return {"choices": [_json_float(c) for c in self.choices]}
        return {"value": _json_float(self.value)}

    def describe(self) -> str:
        """Short text, e.g. ``[0.05, 0.5] log`` or ``{1, 10, 100, inf}``."""
        if self.kind == "range":
            return f"[{self.low:g}, {self.high:g}] {'log' if self.log else 'linear'}"
        if self.kind == "choice":
            return "{" + ", ".join(f"{c:g}" for c in self.choices) + "}"
        return f"fixed {self.value:g}"

    @classmethod
    def from_spec(cls, name: str, spec, source: str) -> Dimension:
        """From a TOML value: a number (fixed), ``{low, high, log}`` or ``{choices}``."""
        if isinstance(spec, dict):
            unknown = sorted(set(spec) - {"low", "high", "log", "choices"})
            if unknown:
                raise ValueError(
                    f"{source}: {name}: unknown key(s) {unknown}; use low/high/log or choices"
                )
            choices = spec.get("choices")
            if choices is not None and not isinstance(choices, list):
                raise ValueError(f"{source}: {name}: choices must be a list")
            log = spec.get("log", False)
            if not isinstance(log, bool):
                raise ValueError(f"{source}: {name}: log must be true or false")
            return cls(
                name,
                spec.get("low"),
                spec.get("high"),
                log,
                None if choices is None else tuple(choices),
            )
        return cls(name, value=spec)


def encoder_field_type(name: str) -> str:
    """``"int"`` or ``"float"``: the type of encoder dimension ``name`` (``"lif.gain"``);
    ``ValueError`` for an unknown encoder, parameter or a non-numeric parameter."""
    encoder, _, param = name.partition(ENCODER_SEP)
    try:
        types = encoder_fields(encoder)
    except ValueError as exc:
        raise ValueError(f"search space: {name!r}: {exc}") from None
    numeric = {p: t.split()[0] for p, t in types.items() if t.split()[0] in ("int", "float")}
    if param == TRAIN_LENGTH_FIELD:
        raise ValueError(
            f"search space: {name!r}: the spike-train length sets the window every trial is "
            f"scored on and cannot be tuned; fix it with --set {name}=SECONDS"
        )
    if param not in numeric:
        raise ValueError(
            f"search space: {name!r}: {encoder} has no numeric parameter {param!r}; "
            f"tunable: {sorted(numeric)}"
        )
    return numeric[param]


def encoder_settings(params: dict[str, float]) -> dict[str, dict[str, float | int]]:
    """The encoder dimensions of a parameter set, per encoder: ``{"pacinian": {"model": 2}}``
    (integer parameters as ``int``)."""
    out: dict[str, dict[str, float | int]] = {}
    for name, v in params.items():
        if ENCODER_SEP in name:
            encoder, _, param = name.partition(ENCODER_SEP)
            out.setdefault(encoder, {})[param] = (
                int(v) if encoder_field_type(name) == "int" else float(v)
            )
    return out


def trial_encoder(encoder: Encoder | None, params: dict[str, float]) -> Encoder | None:
    """The encoder a trial encoded with: the study's ``encoder`` (its fixed ``--set`` settings)
    with the trial's tuned settings of ``params``; ``None`` when the study's is not known."""
    if encoder is None:
        return None
    tuned = encoder_settings(params).get(encoder.name, {})
    return replace(encoder, **tuned)


def _check_values(name: str, values) -> None:
    """``ValueError`` unless every value is a valid setting of parameter ``name``."""
    for v in values:
        if ENCODER_SEP in name:
            encoder, settings = next(iter(encoder_settings({name: v}).items()))
            try:
                make_encoder(encoder, **settings)
            except ValueError as exc:
                raise ValueError(f"search space: {name} = {v!r}: {exc}") from None
        elif name == "spread":
            try:
                NetworkConfig(spll=PROBE_SPLL, spread=v)
            except ValueError as exc:
                raise ValueError(f"search space: spread = {v!r}: {exc}") from None
        elif name in NETWORK_PARAMS:
            net = {"f_start": 100.0, "f_end": 300.0, "beta": math.inf} | {name: v}
            try:
                network_frequencies(net["f_start"], net["f_end"], 2, net["beta"])
            except ValueError as exc:
                raise ValueError(f"search space: {name} = {v!r}: {exc}") from None
        else:
            try:
                replace(PROBE_SPLL, **{name: v})
            except ValueError as exc:
                raise ValueError(f"search space: {name} = {v!r}: {exc}") from None


def _json_float(v: float):
    return "inf" if isinstance(v, float) and math.isinf(v) else v


class SearchSpace:
    """The dimensions of a study, in :data:`KNOWN_PARAMS` order."""

    def __init__(self, dimensions: list[Dimension] | tuple[Dimension, ...]):
        dims = {d.name: d for d in dimensions}
        missing = [
            n
            for n in (
                "tau_cco_syn",
                "tau_cco",
                "tau_tde_trg",
                "tau_tde_fac",
                "tau_tde",
                "g_cco",
                "g_tde_trg",
                "g_tde_fac",
                *NETWORK_PARAMS,
            )
            if n not in dims and n not in NETWORK_DEFAULTS
        ]
        if missing:
            raise ValueError(f"search space: no value or range for {missing}")
        self.dims = {n: dims[n] for n in KNOWN_PARAMS if n in dims} | {
            n: dims[n] for n in sorted(dims) if ENCODER_SEP in n
        }
        highest_start = max(self.dims["f_start"].extremes)
        lowest_end = min(self.dims["f_end"].extremes)
        if not highest_start < lowest_end:
            raise ValueError(
                f"search space: f_start (up to {highest_start:g} Hz) must stay below f_end "
                f"(from {lowest_end:g} Hz)"
            )

    @classmethod
    def table5(cls) -> SearchSpace:
        """The thesis's Table 5 ranges."""
        return cls(
            [
                Dimension("f_start", 30.0, 100.0),
                Dimension("f_end", 300.0, 700.0),
                Dimension("beta", choices=(1.0, 10.0, 100.0, math.inf)),
                Dimension("tau_cco_syn", 0.005, 0.2, log=True),
                Dimension("tau_cco", 0.05, 0.5, log=True),
                Dimension("tau_tde_trg", 0.0005, 0.02, log=True),
                Dimension("tau_tde_fac", 0.0005, 0.02, log=True),
                Dimension("tau_tde", 0.001, 0.1, log=True),
                Dimension("g_cco", 0.1, 10.0, log=True),
                Dimension("g_tde_trg", 0.1, 5.0, log=True),
                Dimension("g_tde_fac", 500.0, 100000.0, log=True),
            ]
        )

    def with_overrides(self, specs: dict, source: str = "search space") -> SearchSpace:
        """Table entries (module docstring format) replacing this space's dimensions."""
        if not isinstance(specs, dict):
            raise ValueError(f"{source}: expected a table of parameter = range/value")
        new = [Dimension.from_spec(name, spec, source) for name, spec in specs.items()]
        return SearchSpace(list(self.dims.values()) + new)

    @classmethod
    def load(cls, path: str | Path) -> SearchSpace:
        """Table 5 with the ``[space]`` table of a TOML file applied on top."""
        doc = read_toml(Path(path), "search-space file")
        if set(doc) != {"space"}:
            raise ValueError(f"{path}: expected exactly one [space] table, got {sorted(doc)}")
        return cls.table5().with_overrides(doc["space"], source=str(path))

    def to_dict(self) -> dict[str, dict]:
        """JSON-able form, stored with the study to detect a changed space on resume."""
        return {name: d.to_dict() for name, d in self.dims.items()}

    def differences(self, stored: dict) -> list[str]:
        """Human-readable differences between this space and a stored :meth:`to_dict`."""
        mine = json.loads(json.dumps(self.to_dict()))
        out = []
        for name in sorted(set(mine) | set(stored)):
            if mine.get(name) != stored.get(name):
                out.append(f"{name}: stored {stored.get(name)}, now {mine.get(name)}")
        return out

    @property
    def encoders(self) -> set[str]:
        """Encoders this space has dimensions of (usually none, at most the study's)."""
        return {n.partition(ENCODER_SEP)[0] for n in self.dims if ENCODER_SEP in n}

    @property
    def tuned(self) -> list[str]:
        """Names of the dimensions that are sampled (not fixed)."""
        return [n for n, d in self.dims.items() if d.kind != "fixed"]

    def suggest(self, trial) -> dict[str, float]:
        """Sample every dimension from an Optuna trial; fixed ones are returned as they are."""
        out = {}
        for name, d in self.dims.items():
            if d.kind == "range":
                out[name] = trial.suggest_float(name, d.low, d.high, log=d.log)
            elif d.kind == "choice":
                out[name] = float(trial.suggest_categorical(name, list(d.choices)))
            else:
                out[name] = float(d.value)
        return out

    def complete(self, params: dict) -> dict[str, float]:
        """A trial's sampled ``params`` plus the fixed values: every parameter of the network."""
        out = {n: float(d.value) for n, d in self.dims.items() if d.kind == "fixed"}
        out.update({n: float(v) for n, v in params.items()})
        return out


def network_config(
    params: dict[str, float], layout: str, n: int, reference_frequency: float, seed: int = 0
) -> NetworkConfig:
    """The :class:`~spll_hw.config.NetworkConfig` of a full parameter set (:meth:`complete`);
    ``seed`` draws the spread (if any)."""
    spll = SpllParams(
        **{k: v for k, v in params.items() if k not in NETWORK_PARAMS and ENCODER_SEP not in k}
    )
    return NetworkConfig(
        spll=spll,
        layout=layout,
        f_start=params["f_start"],
        f_end=params["f_end"],
        n=n,
        beta=params["beta"],
        reference_frequency=reference_frequency,
        spread=params.get("spread", NETWORK_DEFAULTS["spread"]),
        spread_seed=seed,
    )


def network_values(config: NetworkConfig) -> dict[str, float]:
    """Every network parameter a search space can name, as ``config`` sets it: the base sPLL's
    fields and :data:`NETWORK_PARAMS` (the inverse of :func:`network_config`)."""
    return config.spll.to_dict() | {
        "f_start": config.f_start,
        "f_end": config.f_end,
        "beta": config.beta,
        "spread": config.spread,
    }


def constraint_values(config: NetworkConfig) -> tuple[float, ...]:
    """The :data:`CONSTRAINTS` of a network as ``ratio - 1`` (feasible when <= 0).

    ``max_i tau_syn_i * f_i - 1`` for both TDE synapses (sPLL ``i`` of the built network, ``f_i``
    its free-running frequency [Hz]) and ``tau_syn / tau_tde - 1`` (layout-independent).
    """
    net = config.build()
    freqs = config.frequencies()
    fac = np.array([p.tau_tde_fac for p in net.spll])
    trg = np.array([p.tau_tde_trg for p in net.spll])
    base = config.spll
    return (
        float(np.max(fac * freqs) - 1.0),
        float(np.max(trg * freqs) - 1.0),
        base.tau_tde_fac / base.tau_tde - 1.0,
        base.tau_tde_trg / base.tau_tde - 1.0,
    )


def breaks_constraints(trial) -> bool:
    """Whether an Optuna trial's network broke one of the :data:`CONSTRAINTS` (a value > 0 in
    its ``constraints`` user attribute; a trial without one breaks none)."""
    return max(trial.user_attrs.get("constraints", [0.0])) > 0
