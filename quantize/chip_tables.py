"""The chip tables of a profile: ``[resources]``, ``[timing]`` and ``[energy]``.

Every figure is ``key = { value = ..., source = "..." }``; a price (a time, an energy or a power)
and a placement figure (a count or a flag of ``[resources]``/``[timing]``) may add the range
public sources allow, ``low``/``high`` with ``low_source``/``high_source``. :data:`CHIP_KEYS`
lists every key with its meaning and unit; :class:`ChipSpec` holds the parsed tables and gives
the chip with its prices at either end of their ranges (:meth:`ChipSpec.at`) and with its
placement figures at either end of theirs (:meth:`ChipSpec.placed`). The profile file
format around these tables is :mod:`quantize.profiles`'; every error names the file, the table
and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace


class ProfileError(ValueError):
    """A profile file or value that cannot describe a chip; the message names the key."""


def _check_number(value, where: str, key: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ProfileError(f"{where}: {key} must be a number, got {value!r}")


def _check_int(value, where: str, key: str, low: int, high: int, why: str = "") -> None:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ProfileError(f"{where}: {key} must be an integer, got {value!r}")
    if not low <= value <= high:
        reason = f" ({why})" if why else ""
        raise ProfileError(
            f"{where}: {key} = {value} is impossible: it must be between {low} and {high}{reason}"
        )


# ------------------------------------------------------------------------- chip figures
#: What a source starts with when no public source gives a figure (case-insensitive).
ASSUMED = "assumed"
#: Parameter groups a neuron configuration can fix (``config_shares``): time constants,
#: threshold (with the capacitance, its scale), refractory period, offset current, gains.
CONFIG_GROUPS = ("decay", "threshold", "refractory", "offset", "gain")


#: The ends of a figure's range (:meth:`Figure.at`, :meth:`ChipSpec.at`).
ENDS = ("low", "high")


@dataclass(frozen=True)
class Figure:
    """One number of a chip with where it comes from, and the range public sources allow.

    Attributes:
        value: the number (unit in :data:`CHIP_KEYS`), a flag, or a tuple of group names; for
            a ranged figure the value every single-number report uses.
        source: the public source (paper and table, repository and file), or a text starting
            with ``"assumed"`` that says what the figure was extrapolated from.
        low, high: the ends of the range the sources allow (same unit; ``None``: the figure is
            one number, its range ``[value, value]``); ``low <= value <= high``.
        low_source, high_source: where each end comes from.
    """

    value: object
    source: str
    low: float | None = None
    high: float | None = None
    low_source: str = ""
    high_source: str = ""

    @property
    def assumed(self) -> bool:
        """No public source gives this figure (its source starts with ``"assumed"``)."""
        return self.source.strip().lower().startswith(ASSUMED)

    @property
    def ranged(self) -> bool:
        """The figure carries a low and a high end."""
        return self.low is not None

    def at(self, end: str) -> object:
        """The figure's ``"low"`` or ``"high"`` end (its value when it has no range), or its
        ``"value"``."""
        if end == "value" or not self.ranged:
            return self.value
        return self.low if end == "low" else self.high


@dataclass(frozen=True)
class Key:
    """A key of a chip table: ``kind`` (``"count"`` integer >= 1, ``"seconds"``, ``"joules"``,
    ``"watts"`` number >= 0, ``"flag"`` boolean, ``"groups"`` list of :data:`CONFIG_GROUPS`),
    whether it is ``required``, and what it means (``doc``, with its unit)."""

    kind: str
    doc: str
    required: bool = False


#: Every key of the optional chip tables; a figure is ``key = {value = ..., source = "..."}``.
CHIP_KEYS: dict[str, dict[str, Key]] = {
    "resources": {
        "chips": Key("count", "chips in the system", True),
        "cores_per_chip": Key("count", "neuron cores per chip", True),
        "neurons_per_core": Key("count", "neurons (compartments) per core", True),
        "tde_compartments": Key(
            "count", "compartments (or neurons) one TDE takes on this chip", True
        ),
        "cores_per_tile": Key("count", "cores behind one router of the mesh (default 1)"),
        "mesh_columns": Key("count", "router tiles per row of a chip's 2-D mesh (default: 1 row)"),
        "configs_per_core": Key("count", "distinct neuron configurations per core"),
        "config_shares": Key(
            "groups",
            "what neurons of one configuration share (default decay, refractory, threshold)",
        ),
        "thresholds_per_core": Key(
            "count", "distinct thresholds per core, when the chip keeps them apart"
        ),
        "fan_in_per_core": Key("count", "input axons per core"),
        "fan_out_per_core": Key("count", "output axons per core"),
        "synapses_per_core": Key("count", "synapses per core"),
        "synapses_per_neuron": Key("count", "synapses per neuron (fan-in of one neuron)"),
        "multicast": Key("flag", "a spike leaves its core as one packet whatever its targets"),
    },
    "timing": {
        "neuron_update": Key("seconds", "per neuron update [s]"),
        "synaptic_event": Key("seconds", "per synaptic event [s]"),
        "spike": Key("seconds", "per spike a neuron fires [s]"),
        "message": Key("seconds", "per message sent out of a core [s]"),
        "hop": Key("seconds", "per router hop [s]"),
        "barrier": Key("seconds", "per time-step barrier [s]"),
        "realtime_paced": Key(
            "flag", "steps follow a real-time timer (else the chip runs them back to back)"
        ),
    },
    "energy": {
        "neuron_update": Key("joules", "per neuron update [J]"),
        "synaptic_event": Key("joules", "per synaptic event [J]"),
        "spike": Key("joules", "per spike a neuron fires [J]"),
        "message": Key("joules", "per message (packet) sent out of a core [J]"),
        "hop": Key("joules", "per router hop inside a chip [J]"),
        "chip_hop": Key("joules", "per hop between chips [J]"),
        "step": Key(
            "joules",
            "per time step of a clocked chip, whatever it runs: barrier and step "
            "management, once per step [J]",
        ),
        "static_power": Key("watts", "static power per chip in use [W]"),
        "core_power": Key("watts", "power per core in use while it runs [W]"),
    },
}


#: Kinds of figure that are prices of a chip (energy, time, power): they may carry a range, and
#: every cost grows with each of them, so their two ends bound a cost (:meth:`ChipSpec.at`).
RANGED_KINDS = ("seconds", "joules", "watts")
#: Kinds of figure that shape the placement (capacities, flags): they may carry a range too; a
#: cost need not grow with them, so a cost's range takes the extremes over the placements at
#: their ends (:meth:`ChipSpec.placements`).
PLACEMENT_KINDS = ("count", "flag")
#: The keys of a range beside ``value`` and ``source``.
RANGE_KEYS = ("low", "low_source", "high", "high_source")


@dataclass(frozen=True)
class FigureTable:
    """The figures of one chip table (``[resources]``, ``[timing]`` or ``[energy]``).

    Attributes:
        table: the table's name.
        figures: ``(key, Figure)`` pairs in file order.
    """

    table: str
    figures: tuple[tuple[str, Figure], ...] = ()

    def __contains__(self, key: str) -> bool:
        return any(k == key for k, _ in self.figures)

    def figure(self, key: str) -> Figure | None:
        """The figure of ``key``; ``None`` when the file does not give it."""
        return next((f for k, f in self.figures if k == key), None)

    def value(self, key: str, default=None):
        """The value of ``key``, ``default`` when the file does not give it."""
        found = self.figure(key)
        return default if found is None else found.value


@dataclass(frozen=True)
class ChipSpec:
    """What a chip offers and costs: the optional tables of a profile file.

    Attributes:
        resources, timing, energy: :class:`FigureTable` of each table (empty when absent).
    """

    resources: FigureTable = FigureTable("resources")
    timing: FigureTable = FigureTable("timing")
    energy: FigureTable = FigureTable("energy")

    def tables(self) -> tuple[FigureTable, ...]:
        return (self.resources, self.timing, self.energy)

    def assumed(self) -> list[str]:
        """``table.key`` of every assumed figure."""
        return [f"{t.table}.{k}" for t in self.tables() for k, f in t.figures if f.assumed]

    def assumed_among(self, used) -> tuple[str, ...]:
        """The assumed figures among ``used`` (``table.key``), in first-use order."""
        assumed = set(self.assumed())
        return tuple(k for k in dict.fromkeys(used) if k in assumed)

    def at(self, end: str) -> ChipSpec:
        """The chip with every ranged price at its ``"low"`` or ``"high"`` end (sources kept):
        every energy and time grows with every price, so the two ends bound a cost on one
        placement."""
        return self._moved(end, RANGED_KINDS)

    def placed(self, end: str) -> ChipSpec:
        """The chip with every ranged placement figure (a count or a flag) at its ``"low"`` or
        ``"high"`` end, prices as they are: at ``"low"`` the smallest capacities (the most
        cores), at ``"high"`` the largest."""
        return self._moved(end, PLACEMENT_KINDS)

    def placements(self) -> list[ChipSpec]:
        """The chip as it is, then at each end of its placement ranges where it has any: the
        placements a cost's range is taken over (:func:`quantize.registry` costs)."""
        if not self.ranged_placement():
            return [self]
        return [self, self.placed("low"), self.placed("high")]

    def ranged_placement(self) -> list[str]:
        """``table.key`` of every placement figure that carries a range."""
        return [f"{t.table}.{k}" for t, k, f in self._figures(PLACEMENT_KINDS) if f.ranged]

    def _figures(self, kinds: tuple[str, ...]):
        return [(t, k, f) for t in self.tables() for k, f in t.figures
                if CHIP_KEYS[t.table][k].kind in kinds]  # fmt: skip

    def _moved(self, end: str, kinds: tuple[str, ...]) -> ChipSpec:
        def moved(table: str, key: str, f: Figure) -> Figure:
            return replace(f, value=f.at(end)) if CHIP_KEYS[table][key].kind in kinds else f

        return ChipSpec(*(
            FigureTable(t.table, tuple((k, moved(t.table, k, f)) for k, f in t.figures))
            for t in self.tables()
        ))  # fmt: skip

    def single(self) -> list[str]:
        """``table.key`` of every energy and timing figure given as one number, no range."""
        return [f"{t.table}.{k}" for t, k, f in self._figures(RANGED_KINDS) if not f.ranged]

    def single_assumed(self) -> list[str]:
        """``table.key`` of every assumed figure given as one value, no range: what a report
        on this chip rests on without any bound."""
        return [f"{t.table}.{k}" for t in self.tables() for k, f in t.figures
                if f.assumed and not f.ranged]  # fmt: skip


def _parse_figure(raw, where: str, key: str, spec: Key) -> Figure:
    if not isinstance(raw, dict):
        raise ProfileError(
            f"{where}: {key} must be a figure with its source, "
            f'{key} = {{ value = ..., source = "..." }}; got {raw!r}'
        )
    ranged = spec.kind in RANGED_KINDS + PLACEMENT_KINDS
    allowed = {"value", "source", *(RANGE_KEYS if ranged else ())}
    bad = sorted(set(raw) - allowed)
    if bad:
        raise ProfileError(
            f"{where}: {key} has unknown key(s) {bad}; a figure has "
            + ", ".join(k for k in ("value", "source", *RANGE_KEYS) if k in allowed)
        )
    if "value" not in raw:
        raise ProfileError(f"{where}: {key} has no value")
    source = raw.get("source")
    if not isinstance(source, str) or not source.strip():
        raise ProfileError(
            f"{where}: {key} has no source: give the public source of the figure, or "
            f'source = "{ASSUMED}: <what it was extrapolated from>"'
        )
    value = raw["value"]
    if spec.kind == "count":
        _check_int(value, where, key, 1, 2**40)
    elif spec.kind == "flag":
        if not isinstance(value, bool):
            raise ProfileError(f"{where}: {key} must be true or false, got {value!r}")
    elif spec.kind == "groups":
        if (
            not isinstance(value, list)
            or not value
            or any(v not in CONFIG_GROUPS for v in value)
            or len(set(value)) != len(value)
        ):
            raise ProfileError(
                f"{where}: {key} must be a list of distinct groups from {list(CONFIG_GROUPS)}, "
                f"got {value!r}"
            )
        value = tuple(value)
    else:
        _check_number(value, where, key)
        if not (math.isfinite(value) and value >= 0):
            raise ProfileError(f"{where}: {key} = {value!r} must be a finite number >= 0")
        value = float(value)
    if ranged and any(k in raw for k in RANGE_KEYS):
        return _ranged_figure(raw, where, key, value, source.strip(), spec.kind)
    return Figure(value, source.strip())


def _check_end(value, where: str, key: str, kind: str) -> None:
    """One end of a range, of the figure's own kind: an integer >= 1 for a count, a boolean
    for a flag (``low = false``, ``high = true``), a finite number >= 0 for a price."""
    if kind == "count":
        _check_int(value, where, key, 1, 2**40)
    elif kind == "flag":
        if not isinstance(value, bool):
            raise ProfileError(f"{where}: {key} must be true or false, got {value!r}")
    else:
        _check_number(value, where, key)
        if not (math.isfinite(value) and value >= 0):
            raise ProfileError(f"{where}: {key} = {value!r} must be a finite number >= 0")


def _ranged_figure(
    raw: dict, where: str, key: str, value, source: str, kind: str = "joules"
) -> Figure:
    """A figure with ``low``/``high`` and their sources, checked: all four keys, each end of
    the figure's kind, ``low <= value <= high``."""
    missing = [k for k in RANGE_KEYS if k not in raw]
    if missing:
        raise ProfileError(
            f"{where}: {key} gives a range without {missing}: a range is low, high and the "
            'source of each, e.g. low = 1e-12, low_source = "...", high = 2e-12, '
            'high_source = "..."'
        )
    ends = {}
    for end in ENDS:
        _check_end(raw[end], where, f"{key}.{end}", kind)
        text = raw[f"{end}_source"]
        if not isinstance(text, str) or not text.strip():
            raise ProfileError(
                f"{where}: {key}.{end}_source must say where the {end} end comes from"
            )
        ends[end] = (raw[end] if kind in PLACEMENT_KINDS else float(raw[end]), text.strip())
    (low, low_source), (high, high_source) = ends["low"], ends["high"]
    if not low <= value <= high:
        raise ProfileError(
            f"{where}: {key} must hold low <= value <= high; got low = {low!r}, value = "
            f"{value!r}, high = {high!r}"
        )
    return Figure(value, source, low, high, low_source, high_source)


def _parse_chip(doc: dict, source: str) -> ChipSpec | None:
    """The ``[resources]``, ``[timing]`` and ``[energy]`` tables of a profile document;
    ``None`` when it has none of them."""
    if not any(name in doc for name in CHIP_KEYS):
        return None
    tables = {}
    for name, keys in CHIP_KEYS.items():
        raw = doc.get(name, {})
        where = f"{source} [{name}]"
        if not isinstance(raw, dict):
            raise ProfileError(f"{where}: must be a table")
        bad = sorted(set(raw) - set(keys))
        if bad:
            raise ProfileError(f"{where}: unknown key(s) {bad}; known: {sorted(keys)}")
        missing = sorted(k for k, spec in keys.items() if spec.required and k not in raw)
        if missing:
            raise ProfileError(f"{where}: missing key(s) {missing}")
        figures = tuple((k, _parse_figure(v, where, k, keys[k])) for k, v in raw.items())
        tables[name] = FigureTable(name, figures)
    chip = ChipSpec(**tables)
    resources = chip.resources
    where = f"{source} [resources]"
    if "config_shares" in resources and "configs_per_core" not in resources:
        raise ProfileError(f"{where}: config_shares needs configs_per_core")
    shares = resources.value("config_shares", DEFAULT_CONFIG_SHARES)
    if "thresholds_per_core" in resources and "threshold" in shares:
        raise ProfileError(
            f"{where}: thresholds_per_core counts thresholds apart from the configurations, "
            "so config_shares must not contain 'threshold'"
        )
    return chip


#: What a neuron configuration fixes when ``config_shares`` is not given.
DEFAULT_CONFIG_SHARES = ("decay", "refractory", "threshold")
