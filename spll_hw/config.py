"""Network configuration files: one TOML file describes a whole sPLL network.

Every command that takes ``--network`` (old spelling ``--params``) reads this format (tuning
writes it)::

    [spll]                      # the base sPLL (SpllParams field names, SI units)
    tau_cco_syn = 0.0075
    tau_cco = 0.314
    ...
    [network]
    layout = "vary-offset"      # "time-scaled", or "grouped:G": G time-scale groups placed
                                # closest to the time-scaled network (spll_hw.layouts)
    f_start = 56.2              # lowest free-running frequency [Hz]
    f_end = 668.0               # highest free-running frequency [Hz]
    n = 50                      # number of sPLLs
    beta = inf                  # log offset: 0 exponential ... inf linear spacing
    reference_frequency = 50.0  # [Hz] where a time-scaled base sPLL runs unscaled
    spread = 0.0                # per-sPLL lognormal diversity of time constants and gains
    spread_seed = 0             # (Network.with_spread); 0.0 is the thesis's networks
    # or, instead of f_start, f_end, n and beta, every free-running frequency [Hz], ascending:
    # frequencies = [40.0, 80.0, 160.0, 320.0]

A file without ``[network]`` gets the defaults above (a warning says so); ``f_start`` above
``f_end`` is refused.

    [encoder]                   # optional: the spike encoder the network was tuned on
    name = "pacinian"           # lif, pacinian or peak; then every setting of that encoder,
    model = 2                   # in the --set syntax ("none" for None)
    rms_um = 43.5
    input_level = 108.9         # optional: the signal level the encoder was tuned at (below)

Instead of a file, ``--network`` also takes a preset name (a file of :mod:`spll_hw.presets`),
such as the thesis's ``biotac-vary-offset-lif`` (Tables 6 and 7).

``spll-hw tune`` writes ``[encoder]`` into ``best.toml``; ``spll-hw evaluate --network`` encodes
with it (``--set`` still overrides) and ``tune --enqueue`` starts tuned encoder settings there.
Commands that only simulate the network ignore it.

**Input level.** Signals reach the encoder divided by one dataset-wide level (the median sample
RMS, :meth:`spll_hw.datasets.SampleSet.normalized`), so tuned encoder gains do not depend on the
dataset's units. Without ``input_level`` that level is the median of whichever samples a run
trains on, so the same network would see other amplitudes when trained on other recordings.
``tune`` records the level it tuned at as ``input_level`` (in the dataset's raw unit), and
``evaluate``, ``report`` and ``tune`` divide by it whenever the file's encoder is used.
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import numpy as np

from . import presets
from .encoders import ENCODERS, make_encoder, parse_setting
from .layouts import grouped_layout
from .limits import check_memory
from .network import DEFAULT_N_SPLL, DEFAULT_REFERENCE_FREQUENCY, Network, network_frequencies
from .params import SpllParams, read_toml

LAYOUTS = ("vary-offset", "time-scaled", "grouped:G")
#: ``[network]`` keys an explicit ``frequencies`` list replaces.
SPACING = ("f_start", "f_end", "n", "beta")
#: Memory [bytes] building one sPLL of a network takes at its peak: its parameters as Python
#: objects and its row of the parameter matrix (measured: about 620 B).
BYTES_PER_SPLL = 1024
#: Name of the optional table holding the encoder a network was tuned on.
ENCODER_TABLE = "encoder"
#: Key of the ``[encoder]`` table: the signal level [the dataset's raw unit] the encoder was
#: tuned at (module docstring).
INPUT_LEVEL = "input_level"


@dataclass(frozen=True)
class NetworkConfig:
    """A base sPLL plus where the network's free-running frequencies go and how it is scaled."""

    spll: SpllParams
    layout: str = "vary-offset"
    f_start: float = 56.2
    f_end: float = 668.0
    n: int = DEFAULT_N_SPLL
    beta: float = math.inf
    reference_frequency: float = DEFAULT_REFERENCE_FREQUENCY
    spread: float = 0.0
    spread_seed: int = 0
    frequencies_hz: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.frequencies_hz is not None:
            self._explicit_frequencies()
        if not isinstance(self.layout, str):
            raise ValueError(f"layout must be a string such as 'vary-offset', got {self.layout!r}")
        _ = self.groups  # raises on an unknown layout string
        for name in ("f_start", "f_end", "reference_frequency"):
            value = getattr(self, name)
            if not (_is_number(value) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number of Hz > 0, got {value!r}")
        if self.f_start > self.f_end:
            raise ValueError(
                f"f_start = {self.f_start:g} Hz is above f_end = {self.f_end:g} Hz: the band runs "
                "from f_start (lowest free-running frequency) up to f_end; swap them"
            )
        if not (_is_number(self.beta) and self.beta >= 0):
            raise ValueError(f"beta must be a number >= 0 (inf: linear spacing), got {self.beta!r}")
        if isinstance(self.n, bool) or not isinstance(self.n, numbers.Integral) or self.n < 1:
            raise ValueError(f"n must be a whole number of sPLLs >= 1, got {self.n!r}")
        object.__setattr__(self, "n", int(self.n))
        if isinstance(self.spread, bool) or not (
            isinstance(self.spread, int | float) and math.isfinite(self.spread) and self.spread >= 0
        ):
            raise ValueError(f"spread must be a number >= 0 (0: no diversity), got {self.spread!r}")
        if isinstance(self.spread_seed, bool) or not (
            isinstance(self.spread_seed, int) and self.spread_seed >= 0
        ):
            raise ValueError(f"spread_seed must be an integer >= 0, got {self.spread_seed!r}")

    def _explicit_frequencies(self) -> None:
        """An explicit list of free-running frequencies: checked, stored as a tuple of floats,
        and ``n``, ``f_start`` and ``f_end`` set from it (``beta`` no longer applies)."""
        values = self.frequencies_hz
        if isinstance(values, str) or not hasattr(values, "__len__") or len(values) == 0:
            raise ValueError(f"frequencies must be a list of Hz, e.g. [40.0, 80.0], got {values!r}")
        for v in values:
            if not (_is_number(v) and math.isfinite(v) and v > 0):
                raise ValueError(f"frequencies must be finite numbers of Hz > 0, got {v!r}")
        freqs = tuple(float(v) for v in values)
        if any(b <= a for a, b in zip(freqs, freqs[1:], strict=False)):
            raise ValueError(f"frequencies must rise strictly (one sPLL each), got {list(freqs)}")
        for name, value in (("frequencies_hz", freqs), ("n", len(freqs)),
                            ("f_start", freqs[0]), ("f_end", freqs[-1])):  # fmt: skip
            object.__setattr__(self, name, value)

    @property
    def groups(self) -> int | None:
        """Number of time-scale groups of a ``grouped:G`` layout (``None`` otherwise)."""
        if self.layout in ("vary-offset", "time-scaled"):
            return None
        kind, _, count = self.layout.partition(":")
        if kind == "grouped" and count.isdigit() and int(count) >= 1:
            return int(count)
        raise ValueError(f"unknown network layout {self.layout!r}; choose from {LAYOUTS}")

    def frequencies(self):
        """Free-running frequencies [Hz], shape ``(n,)``: the explicit list, or ``n`` from
        ``f_start`` to ``f_end`` spaced by ``beta``."""
        if self.frequencies_hz is not None:
            return np.asarray(self.frequencies_hz, dtype=np.float64)
        return network_frequencies(self.f_start, self.f_end, self.n, self.beta)

    def build(self) -> Network:
        """The :class:`Network` this configuration describes (layout, then spread). A network too
        big for the memory is refused before it is built."""
        check_memory(
            self.n * BYTES_PER_SPLL,
            f"building a network of {self.n} sPLLs",
            "use fewer sPLLs (n in the [network] table)",
        )
        return self._layout_network().with_spread(float(self.spread), self.spread_seed)

    def _layout_network(self) -> Network:
        freqs = self.frequencies()
        if self.layout == "vary-offset":
            return Network.vary_offset(self.spll, freqs)
        if self.layout == "time-scaled":
            return Network.time_scaled(self.spll, freqs, self.reference_frequency)
        # Group boundaries and scales closest to the time-scaled network.
        return grouped_layout(self.spll, freqs, self.groups, self.reference_frequency).network

    def to_toml(self) -> str:
        """This configuration in the file format above."""
        network = {k: v for k, v in asdict(self).items() if k != "spll"}
        explicit = network.pop("frequencies_hz")
        if explicit is not None:  # the list replaces the spacing it sets
            network = {k: v for k, v in network.items() if k not in SPACING} | {
                "frequencies": list(explicit)
            }
        lines = [self.spll.to_toml(), "[network]"]
        lines += [f"{k} = {toml_value(v)}" for k, v in network.items()]
        return "\n".join(lines) + "\n"

    @classmethod
    def from_toml(cls, path: str | Path) -> NetworkConfig:
        """Read a configuration file; errors name the file and the offending key."""
        path = Path(path)
        return cls.from_document(read_toml(path, "parameter file"), path)

    @classmethod
    def from_document(cls, doc: dict, path: str | Path) -> NetworkConfig:
        """The configuration of an already parsed file ``doc`` (``path`` names it in errors)."""
        unknown = sorted(set(doc) - {"spll", "network", ENCODER_TABLE})
        if unknown:
            raise ValueError(
                f"{path}: unknown table(s) {unknown}; expected [spll], [network] and an "
                f"optional [{ENCODER_TABLE}]"
            )
        if "spll" not in doc:
            raise ValueError(f"{path}: no [spll] table (the base sPLL parameters)")
        spll = SpllParams.from_dict(doc["spll"], source=f"{path} [spll]")
        if "network" not in doc:
            warnings.warn(
                f"{path}: no [network] table, so the defaults are used: {DEFAULT_N_SPLL} "
                f"vary-offset sPLLs over {cls.f_start:g}-{cls.f_end:g} Hz (the VibTac band); "
                "add [network] with layout, f_start, f_end and n to say what you mean",
                UserWarning,
                stacklevel=2,
            )
        network = dict(doc.get("network", {}))
        known = ({f.name for f in fields(cls)} - {"spll", "frequencies_hz"}) | {"frequencies"}
        bad = sorted(set(network) - known)
        if bad:
            raise ValueError(f"{path} [network]: unknown key(s) {bad}; known: {sorted(known)}")
        if "frequencies" in network:
            given = sorted(set(network) & set(SPACING))
            if given:
                raise ValueError(
                    f"{path} [network]: give frequencies or {', '.join(SPACING)}, not both "
                    f"(found {given} beside frequencies)"
                )
            network["frequencies_hz"] = network.pop("frequencies")
        try:
            return cls(spll=spll, **network)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{path} [network]: {exc}") from exc

    @classmethod
    def preset(cls, name: str) -> NetworkConfig:
        """A network shipped with spll-hw (:mod:`spll_hw.presets`), e.g. the thesis's
        ``"biotac-vary-offset-lif"`` (Tables 6 and 7)."""
        return cls.from_toml(presets.path(name))

    @classmethod
    def load(cls, source: str | Path) -> NetworkConfig:
        """A preset name or a TOML file path (what ``--network`` accepts)."""
        if presets.is_preset(source):
            return cls.preset(str(source))
        return cls.from_toml(source)

    def with_layout(self, layout: str) -> NetworkConfig:
        """The same base sPLL and frequencies under another layout."""
        return replace(self, layout=layout)

    def with_n(self, n: int) -> NetworkConfig:
        """The same network with ``n`` sPLLs over the same frequency range (a network of
        explicit frequencies has no range to re-space: ``ValueError``)."""
        if self.frequencies_hz is not None and n != self.n:
            raise ValueError(
                f"this network lists its {self.n} frequencies; it cannot be re-spaced to {n} "
                "sPLLs (give f_start, f_end and n instead)"
            )
        return replace(self, n=n)


@dataclass(frozen=True)
class NetworkFile:
    """A network file or preset read once (what ``--network`` names): the ``source`` as
    given, its :class:`NetworkConfig`, its ``[encoder]`` table as ``(name, settings)``
    (``None`` without one; see :func:`read_encoder_table`) and that table's ``input_level``
    (the signal level the encoder was tuned at, in the dataset's raw unit; ``None`` without
    one)."""

    source: str
    config: NetworkConfig
    encoder: tuple[str, dict] | None = None
    input_level: float | None = None


def read_network_file(source: str | Path) -> NetworkFile:
    """Parse the preset or TOML file ``source`` once into its configuration and encoder table;
    ``ValueError`` (``FileNotFoundError`` for a missing file) names the file and the bad key."""
    path = _source_path(source)
    doc = read_toml(path, "parameter file")
    return NetworkFile(
        str(source), NetworkConfig.from_document(doc, path), _encoder_table(doc, str(path)),
        _input_level(doc, str(path)),
    )  # fmt: skip


def read_encoder_table(source: str | Path) -> tuple[str, dict] | None:
    """The encoder a network file was tuned on: ``(name, settings)`` from its ``[encoder]``
    table (keyword arguments of :func:`spll_hw.encoders.make_encoder`), or ``None`` for a file
    (or preset) without the table. ``ValueError`` names the file and the bad entry."""
    path = _source_path(source)
    return _encoder_table(read_toml(path, "parameter file"), str(path))


def read_encoder_document(doc: dict, text: str) -> tuple[tuple[str, dict] | None, float | None]:
    """``(encoder, input_level)`` of the ``[encoder]`` table of a parsed network document
    ``doc`` (``(None, None)`` without one; :class:`NetworkFile`); ``text`` names it in errors."""
    return _encoder_table(doc, text), _input_level(doc, text)


def _source_path(source: str | Path) -> Path:
    """The file of a preset name or file path."""
    return presets.path(str(source)) if presets.is_preset(source) else Path(source)


def _encoder_table(doc: dict, text: str) -> tuple[str, dict] | None:
    """The ``[encoder]`` table of the parsed file ``doc`` (``text`` names it in errors)."""
    if ENCODER_TABLE not in doc:
        return None
    if not isinstance(doc[ENCODER_TABLE], dict):
        raise ValueError(f"{text}: {ENCODER_TABLE} must be a table ([{ENCODER_TABLE}])")
    table = dict(doc[ENCODER_TABLE])
    table.pop(INPUT_LEVEL, None)  # not an encoder setting: _input_level
    name = table.pop("name", None)
    if name not in ENCODERS:
        raise ValueError(
            f"{text} [{ENCODER_TABLE}]: name must be one of {sorted(ENCODERS)}, got {name!r}"
        )
    settings = {}
    for param, value in table.items():
        if isinstance(value, bool):
            value = str(value).lower()
        elif not isinstance(value, str | int | float):
            raise ValueError(f"{text} [{ENCODER_TABLE}]: {param} = {value!r} is not a setting")
        try:
            settings[param] = parse_setting(name, param, str(value))
        except ValueError as exc:
            raise ValueError(f"{text} [{ENCODER_TABLE}]: {exc}") from None
    try:  # each setting's range, checked where it is read, not where the encoder is built
        make_encoder(name, **settings)
    except ValueError as exc:
        raise ValueError(f"{text} [{ENCODER_TABLE}]: {exc}") from None
    return name, settings


def _input_level(doc: dict, text: str) -> float | None:
    """The ``input_level`` of the ``[encoder]`` table of ``doc`` (``None`` without one);
    ``ValueError`` naming the file unless it is a finite number > 0."""
    table = doc.get(ENCODER_TABLE)
    value = table.get(INPUT_LEVEL) if isinstance(table, dict) else None
    if value is None:
        return None
    if not _is_number(value) or not math.isfinite(value) or value <= 0:
        raise ValueError(
            f"{text} [{ENCODER_TABLE}]: {INPUT_LEVEL} must be a finite number > 0 (the signal "
            f"level the encoder was tuned at, in the dataset's raw unit), got {value!r}"
        )
    return float(value)


def _is_number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def toml_value(value) -> str:
    """``value`` (a string, number or ``inf``) as a TOML value."""
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return repr(value)
