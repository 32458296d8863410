"""Chip profiles: the constraints a chip puts on an sPLL network, read from TOML files.

Two kinds exist. A **fixed-point** profile describes a digital chip (Loihi-2-like or a generic
N-bit datapath): a time step and the bit widths of state words, decay constants, weights, biases
and thresholds; the network becomes integer parameters for the discrete-time reference in the
Rust core (:mod:`quantize.fixed_point`, ``engine/src/fixed_point.rs``). An **analog** profile
describes a mixed-signal chip: per-neuron lognormal mismatch of time constants and gains, a
limited number of distinct offset currents and a maximum number of distinct sPLL circuits
(time-scale groups).

File format (every key required but ``tolerance``, no others allowed)::

    [profile]
    name = "loihi2"
    kind = "fixed-point"            # or "analog"
    description = "..."

    [fixed_point]                   # for kind = "fixed-point"
    dt = 1e-5                       # time step [s]
    state_bits = 24                 # signed, saturating state words (currents and potentials)
    decay_bits = 12                 # decay constant delta: x <- x (2^D - delta) >> D
    refractory_bits = 8             # refractory counter [steps]
    weight_mantissa_bits = 8        # signed weight mantissa (magnitude < 2^(bits-1))
    weight_exponent_min = 0         # weight = mantissa << exponent  [state LSB]
    weight_exponent_max = 13
    trigger_shift_max = 24          # trigger weight = mantissa >> shift, shift in 0..max
    current_shift_max = 0           # fractional bits of a current: the membrane adds u >> c
    bias_mantissa_bits = 13         # signed bias mantissa
    bias_exponent_min = 0           # bias = mantissa << exponent  [potential LSB per step]
    bias_exponent_max = 7
    threshold_mantissa_bits = 17    # unsigned threshold mantissa
    threshold_shift = 6             # threshold = mantissa << shift  [potential LSB]
    headroom_bits = 6               # one input spike fills 2^-headroom of the facilitatory word
    tolerance = 0.12                # optional: the export check's default limit (see below)

    [analog]                        # for kind = "analog"
    tau_sigma = 0.1                 # lognormal sigma of every time constant, per neuron
    gain_sigma = 0.1                # lognormal sigma of every gain, per neuron
    offset_levels = 16              # distinct CCO offset currents the chip can provide
    max_groups = 8                  # distinct sPLL circuits (time-scale groups)
    seed = 0                        # seed of the mismatch draw

**Chip tables** (optional, any kind): ``[resources]``, ``[timing]`` and ``[energy]`` say
whether a network fits a chip and what a sample costs on it (:mod:`quantize.resources`). Every
figure carries its source, and a figure no public source gives says so::

    [resources]
    chips = { value = 1, source = "..." }
    cores_per_chip = { value = 128, source = "Davies et al., IEEE Micro 2018" }
    neurons_per_core = { value = 1024, source = "nengo-loihi block.py MAX_COMPARTMENTS" }
    tde_compartments = { value = 1, source = "mappings/lava: one programmable neuron" }

    [energy]
    synaptic_event = { value = 23.6e-12, source = "Davies et al. 2018, Table 2" }
    static_power = { value = 0.03, source = "assumed: <what it was extrapolated from>" }

**A variant of another profile** names it as ``base`` and gives only what differs: a new name
and description, and the keys it changes (the other tables and keys are the base's; a chip
table's figures are replaced one by one). ``base`` is a bundled name or a path (relative to
the variant's own file); chains are allowed, cycles are an error::

    [profile]
    base = "loihi2"
    name = "loihi2-40us"
    description = "loihi2 stepped every 40 us: its 12-bit decays reach tau = 164 ms"

    [fixed_point]
    dt = 4e-5

**The declared tolerance** of a fixed-point profile, the largest total TDE-rate error against
golden that its integer reference (``golden-fixed-point``, ``lava-fixed``) declares and the
default limit of ``spll-hw export --to lava``'s check, is its optional ``tolerance`` key (a
fraction in (0, 1], at every time step; a variant inherits its base's, as any key) where it has
one; else that of the bundled profile whose integer formats (:meth:`FixedPointProfile.formats`)
it has, whatever its name and step; else the worst measured
(:func:`mappings.fixed_point.backend.declared_tolerance`).

Units are SI (seconds, joules, watts); :data:`CHIP_KEYS` lists every key with its meaning, and
which are required once the table is there. A figure whose source starts with ``assumed`` is
shown as assumed in every report.

Bundled profiles (``quantize/profiles/*.toml``): ``loihi2``, ``loihi1``, ``spinnaker``,
``dynapse2``, ``fixed16``, ``analog``; see :func:`available_profiles`.
:func:`generic_fixed_point` builds the generic N-bit profile for any width and time step. Every
error names the file, the table and the key.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, fields, replace
from importlib import resources
from pathlib import Path
from typing import ClassVar

from spll_hw.timestep import at_step as stepped_name
from spll_hw.timestep import parse_step, step_label

from .chip_tables import (
    CHIP_KEYS,
    RANGE_KEYS,
    ChipSpec,
    ProfileError,
    _check_int,
    _check_number,
    _parse_chip,
)

#: Widest state word the Rust reference supports (products stay below 2^62).
MAX_STATE_BITS = 32
#: Widest decay constant the Rust reference supports.
MAX_DECAY_BITS = 30
#: Largest trigger shift the Rust reference supports.
MAX_TRIGGER_SHIFT = 62
#: Most fractional bits of a current the Rust reference supports.
MAX_CURRENT_SHIFT = 30


class ProfileKind:
    """What every profile class declares besides its fields: its ``kind`` label and its
    capabilities, which the core reads through :class:`spll_hw.chips.ProfileInfo`
    (``quantize/registry.py``)."""

    kind: ClassVar[str]
    #: Each chip is a mismatch draw: a realisation depends on a seed.
    draws_mismatch: ClassVar[bool] = False


@dataclass(frozen=True)
class FixedPointProfile(ProfileKind):
    """A digital chip: discrete time step and integer formats (module docstring for the keys).

    Attributes:
        name: short name (``"loihi2"``).
        description: one line for reports.
        dt: time step [s].
        state_bits: width of every state word, sign included.
        decay_bits: width ``D`` of the decay constants.
        refractory_bits: width of the refractory counter [steps].
        weight_mantissa_bits: width of a signed weight mantissa (also the trigger mantissa).
        weight_exponent_min, weight_exponent_max: range of the weight exponent (left shift).
        trigger_shift_max: largest right shift after the facilitatory × trigger product.
        current_shift_max: most fractional bits a synaptic current may carry (the membrane
            adds ``u >> c``; 0 = Loihi's ``v += u``).
        bias_mantissa_bits: width of the signed bias mantissa.
        bias_exponent_min, bias_exponent_max: range of the bias exponent (left shift).
        threshold_mantissa_bits: width of the unsigned threshold mantissa.
        threshold_shift: fixed left shift of the threshold mantissa.
        headroom_bits: the facilitatory weight is ``2^(state_bits - 1 - headroom_bits)``, so
            ``2^headroom_bits`` coincident input spikes fill the facilitatory word.
        chip: the chip's resources, timing and energy (:class:`ChipSpec`), ``None`` when the
            file has no such tables.
        tolerance: the declared largest total TDE-rate error of this chip's integer reference
            against golden, a fraction in (0, 1] at every step (the export check's default
            limit); ``None``: that of the measured bundled profile of the same
            :meth:`formats` (module docstring).
    """

    kind: ClassVar[str] = "fixed-point"

    name: str
    description: str
    dt: float
    state_bits: int
    decay_bits: int
    refractory_bits: int
    weight_mantissa_bits: int
    weight_exponent_min: int
    weight_exponent_max: int
    trigger_shift_max: int
    current_shift_max: int
    bias_mantissa_bits: int
    bias_exponent_min: int
    bias_exponent_max: int
    threshold_mantissa_bits: int
    threshold_shift: int
    headroom_bits: int
    chip: ChipSpec | None = None
    tolerance: float | None = None

    def __post_init__(self) -> None:
        _validate_fixed(self, f"profile {self.name!r} [fixed_point]")

    def formats(self) -> tuple[int, ...]:
        """Its integer formats: every ``[fixed_point]`` key but ``dt`` and ``tolerance``, in
        the table's order (two profiles with equal formats compute alike at any one step)."""
        return tuple(getattr(self, f.name) for f in fields(self) if f.name not in _NOT_FORMATS)

    @property
    def state_max(self) -> int:
        """Largest state value ``2^(state_bits-1) - 1`` [LSB]."""
        return 2 ** (self.state_bits - 1) - 1

    @property
    def threshold(self) -> int:
        """Threshold ``θ`` in potential LSBs: the largest power of two the threshold format
        holds that leaves one bit of headroom in the state word."""
        return 2 ** min(
            self.threshold_mantissa_bits - 1 + self.threshold_shift, self.state_bits - 2
        )

    @property
    def fac_weight(self) -> int:
        """Facilitatory weight in LSBs (a power of two the weight format holds exactly)."""
        top = self.weight_mantissa_bits - 2 + self.weight_exponent_max
        return 2 ** min(self.state_bits - 1 - self.headroom_bits, top)

    def with_dt(self, dt: float) -> FixedPointProfile:
        """The same chip at another time step [s]."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        return FixedPointProfile(**{**values, "dt": dt})


@dataclass(frozen=True)
class AnalogProfile(ProfileKind):
    """A mixed-signal chip (module docstring for the keys).

    Attributes:
        name, description: as for :class:`FixedPointProfile`.
        tau_sigma: sigma of ``ln`` of each time constant's mismatch factor (per neuron, per
            time constant; 0 = none).
        gain_sigma: the same for each gain.
        offset_levels: number of distinct CCO offset currents available.
        max_groups: number of distinct sPLL circuits (parameter sets apart from the offset).
        seed: seed of the mismatch draw.
        chip: as for :class:`FixedPointProfile`.
    """

    kind: ClassVar[str] = "analog"
    draws_mismatch: ClassVar[bool] = True

    name: str
    description: str
    tau_sigma: float
    gain_sigma: float
    offset_levels: int
    max_groups: int
    seed: int
    chip: ChipSpec | None = None

    def __post_init__(self) -> None:
        where = f"profile {self.name!r} [analog]"
        for key in ("tau_sigma", "gain_sigma"):
            value = getattr(self, key)
            _check_number(value, where, key)
            if not (math.isfinite(value) and 0 <= value <= 3):
                raise ProfileError(
                    f"{where}: {key} = {value!r} is impossible: a lognormal sigma must be "
                    "between 0 and 3"
                )
        _check_int(self.offset_levels, where, "offset_levels", 1, 1_000_000)
        _check_int(self.max_groups, where, "max_groups", 1, 1_000_000)
        _check_int(self.seed, where, "seed", 0, 2**63 - 1)


Profile = FixedPointProfile | AnalogProfile

_TABLES = {"fixed-point": ("fixed_point", FixedPointProfile), "analog": ("analog", AnalogProfile)}
_HEADER_KEYS = {"name", "kind", "description"}
#: Keys of a kind's table a file may leave out (``None`` then).
_OPTIONAL_KEYS = {"tolerance"}
#: The fields of a :class:`FixedPointProfile` that are no integer format.
_NOT_FORMATS = {"name", "description", "dt", "chip", "tolerance"}


def _validate_fixed(p: FixedPointProfile, where: str) -> None:
    _check_number(p.dt, where, "dt")
    if not (math.isfinite(p.dt) and p.dt > 0):
        raise ProfileError(f"{where}: dt = {p.dt!r} must be a finite time step > 0 s")
    s = p.state_bits
    _check_int(s, where, "state_bits", 8, MAX_STATE_BITS, "signed state word")
    _check_int(p.decay_bits, where, "decay_bits", 2, MAX_DECAY_BITS)
    _check_int(p.refractory_bits, where, "refractory_bits", 1, 32)
    _check_int(
        p.weight_mantissa_bits,
        where,
        "weight_mantissa_bits",
        2,
        32,
        "signed mantissa; 32 keeps the trigger product below 2^62",
    )
    _check_int(
        p.weight_exponent_min,
        where,
        "weight_exponent_min",
        0,
        s - 2,
        "a weight must be a whole number of state LSBs below the largest state",
    )
    _check_int(
        p.weight_exponent_max,
        where,
        "weight_exponent_max",
        p.weight_exponent_min,
        s - 2,
        "from weight_exponent_min up to state_bits - 2",
    )
    _check_int(p.trigger_shift_max, where, "trigger_shift_max", 0, MAX_TRIGGER_SHIFT)
    _check_int(p.current_shift_max, where, "current_shift_max", 0, MAX_CURRENT_SHIFT)
    _check_int(p.bias_mantissa_bits, where, "bias_mantissa_bits", 2, 32, "signed mantissa")
    _check_int(
        p.bias_exponent_min,
        where,
        "bias_exponent_min",
        0,
        s - 2,
        "a bias must be a whole number of potential LSBs",
    )
    _check_int(
        p.bias_exponent_max,
        where,
        "bias_exponent_max",
        p.bias_exponent_min,
        s - 2,
        "from bias_exponent_min up to state_bits - 2",
    )
    _check_int(p.threshold_mantissa_bits, where, "threshold_mantissa_bits", 1, 32)
    _check_int(
        p.threshold_shift,
        where,
        "threshold_shift",
        0,
        s - 2,
        "the shifted threshold must fit below the largest state value",
    )
    _check_int(
        p.headroom_bits,
        where,
        "headroom_bits",
        0,
        s - 3,
        "an input spike must add at least 4 LSBs to the facilitatory word",
    )
    if p.tolerance is not None:
        _check_number(p.tolerance, where, "tolerance")
        if not 0 < p.tolerance <= 1:
            raise ProfileError(
                f"{where}: tolerance = {p.tolerance!r} must be a fraction in (0, 1] (0.12 is "
                "12 %): the largest total TDE-rate error against golden the chip's integer "
                "reference declares; leave the key out for that of the bundled profile of the "
                "same integer formats"
            )
    if p.fac_weight < 2**p.weight_exponent_min:
        raise ProfileError(
            f"{where}: headroom_bits = {p.headroom_bits} leaves no facilitatory weight the weight "
            f"format holds (weights start at 2^{p.weight_exponent_min} LSB)"
        )


#: Longest chain of ``base`` profiles (a longer one is almost surely a cycle).
MAX_BASE_DEPTH = 8


def _base_document(name: str, source: str) -> tuple[dict, str]:
    """The TOML document of profile ``name`` (bundled, or a path relative to the directory of
    ``source``) and the source it is read from."""
    where = Path(source).parent / name if source != "<string>" else Path(name)
    if name.endswith(".toml") or where.is_file():
        if not where.is_file():
            raise ProfileError(f"{source} [profile]: base = {name!r}: no such file {where}")
        text, origin = _read_text(where), str(where)
    elif name in available_profiles():
        resource = _bundled_dir() / f"{name}.toml"
        text, origin = resource.read_text(encoding="utf-8"), f"profiles/{name}.toml"
    else:
        raise ProfileError(
            f"{source} [profile]: base = {name!r} is neither a bundled profile "
            f"({available_profiles()}) nor a .toml file"
        )
    try:
        return tomllib.loads(text), origin
    except tomllib.TOMLDecodeError as exc:
        raise ProfileError(f"{origin} (base of {source}): not valid TOML: {exc}") from exc


def _resolve_base(doc: dict, source: str, seen: tuple[str, ...] = ()) -> dict:
    """``doc`` with its ``[profile] base`` merged in (recursively): the base's tables, each
    key (or chip figure) of ``doc`` replacing the base's; ``doc``'s header without ``base``."""
    header = doc.get("profile")
    if not isinstance(header, dict) or "base" not in header:
        return doc
    name = header["base"]
    if not isinstance(name, str) or not name.strip():
        raise ProfileError(f"{source} [profile]: base must be a profile name or .toml path")
    if name in seen or len(seen) >= MAX_BASE_DEPTH:
        chain = " -> ".join((*seen, name))
        raise ProfileError(
            f"{source} [profile]: base profiles form a cycle or too long a chain: {chain}"
        )
    base_doc, origin = _base_document(name, source)
    merged = _resolve_base(base_doc, origin, (*seen, name))
    for table, values in doc.items():
        if table == "profile":
            continue
        if not isinstance(values, dict) or not isinstance(merged.get(table), dict):
            merged[table] = values
        else:
            merged[table] = merged[table] | values
    base_header = merged.get("profile", {})
    if "kind" in header and header["kind"] != base_header.get("kind"):
        raise ProfileError(
            f"{source} [profile]: kind = {header['kind']!r} differs from its base {name!r} "
            f"(kind = {base_header.get('kind')!r}); a variant keeps its base's kind"
        )
    missing = sorted({"name", "description"} - set(header))
    if missing:
        raise ProfileError(
            f"{source} [profile]: a variant of {name!r} needs its own {' and '.join(missing)}"
        )
    merged["profile"] = {"kind": base_header.get("kind")} | {
        k: v for k, v in header.items() if k != "base"
    }
    return merged


def _from_document(doc: dict, source: str) -> Profile:
    doc = _resolve_base(doc, source)
    unknown = sorted(set(doc) - {"profile", "fixed_point", "analog", *CHIP_KEYS})
    if unknown:
        raise ProfileError(
            f"{source}: unknown table(s) {unknown}; expected [profile] and [fixed_point] or "
            "[analog], and optionally [resources], [timing], [energy]"
        )
    header = doc.get("profile")
    if not isinstance(header, dict):
        raise ProfileError(f"{source}: no [profile] table (name, kind, description)")
    bad = sorted(set(header) - _HEADER_KEYS)
    if bad:
        raise ProfileError(
            f"{source} [profile]: unknown key(s) {bad}; known: {sorted(_HEADER_KEYS)}"
        )
    missing = sorted(_HEADER_KEYS - set(header))
    if missing:
        raise ProfileError(f"{source} [profile]: missing key(s) {missing}")
    kind = header["kind"]
    if kind not in _TABLES:
        raise ProfileError(
            f"{source} [profile]: kind = {kind!r} is not a profile kind; choose from "
            f"{sorted(_TABLES)}"
        )
    for key in ("name", "description"):
        if not isinstance(header[key], str) or not header[key].strip():
            raise ProfileError(f"{source} [profile]: {key} must be a non-empty string")
    table_name, cls = _TABLES[kind]
    other = [t for t, _ in _TABLES.values() if t != table_name and t in doc]
    if other:
        raise ProfileError(
            f"{source}: a {kind!r} profile cannot have a [{other[0]}] table (only [{table_name}])"
        )
    table = doc.get(table_name)
    if not isinstance(table, dict):
        raise ProfileError(f"{source}: a {kind!r} profile needs a [{table_name}] table")
    known = {f.name for f in fields(cls)} - _HEADER_KEYS - {"chip"}
    bad = sorted(set(table) - known)
    if bad:
        raise ProfileError(f"{source} [{table_name}]: unknown key(s) {bad}; known: {sorted(known)}")
    missing = sorted(known - _OPTIONAL_KEYS - set(table))
    if missing:
        raise ProfileError(f"{source} [{table_name}]: missing key(s) {missing}")
    chip = _parse_chip(doc, source)
    try:
        return cls(name=header["name"], description=header["description"], chip=chip, **table)
    except ProfileError as exc:
        raise ProfileError(f"{source}: {exc}") from None


def _bundled_dir():
    return resources.files("quantize") / "profiles"


def _read_text(path: Path) -> str:
    """A profile file's text; a file that is not UTF-8 text is a :class:`ProfileError` naming
    it."""
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ProfileError(
            f"{path}: not a text file (byte {exc.start} is not UTF-8): a profile is TOML text"
        ) from exc


def available_profiles() -> list[str]:
    """Names of the bundled profiles (``quantize/profiles/*.toml``), sorted."""
    return sorted(
        p.name[: -len(".toml")] for p in _bundled_dir().iterdir() if p.name.endswith(".toml")
    )


def parse_profile(text: str, source: str = "<string>") -> Profile:
    """A profile from TOML text; ``source`` names it in error messages."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProfileError(f"{source}: not valid TOML: {exc}") from exc
    return _from_document(doc, source)


def load_profile(source: str | Path | Profile) -> Profile:
    """A bundled profile by name (``"loihi2"``, ``"fixed16"``, ``"analog"``), a TOML file path,
    or an already loaded profile (returned as is)."""
    if isinstance(source, FixedPointProfile | AnalogProfile):
        return source
    text = str(source)
    if "@" in text and not Path(text).exists():
        return _stepped(text)
    if not text.endswith(".toml") and not Path(text).exists():
        if text not in available_profiles():
            raise ProfileError(
                f"unknown profile {text!r}; bundled profiles: {available_profiles()} "
                "(or give the path of a .toml file)"
            )
        resource = _bundled_dir() / f"{text}.toml"
        return parse_profile(resource.read_text(encoding="utf-8"), f"profiles/{text}.toml")
    path = Path(text)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such profile file")
    return parse_profile(_read_text(path), str(path))


def profile_toml(profile: Profile, comment: str = "") -> str:
    """``profile``'s whole definition as the text of a profile file (module docstring): every
    key of its kind's table and every chip figure with its source and range, no ``base``, so
    that :func:`parse_profile` reads back an equal profile wherever the file goes (units as the
    format's: SI, seconds, joules, watts). ``comment``: lines put atop it as ``#`` comments.
    The text is ASCII (any other character escaped, in the comment too), whatever the locale
    writes it in."""
    table = _TABLES[profile.kind][0]
    lines = [f"# {_ascii(line)}".rstrip() for line in comment.splitlines()]
    lines += [*([""] if lines else []), "[profile]", f"name = {_toml(profile.name)}",
              f"kind = {_toml(profile.kind)}", f"description = {_toml(profile.description)}",
              "", f"[{table}]"]  # fmt: skip
    lines += [
        f"{f.name} = {_toml(getattr(profile, f.name))}"
        for f in fields(profile)
        if f.name not in _HEADER_KEYS | {"chip"} and getattr(profile, f.name) is not None
    ]
    chip = profile.chip
    tables = [] if chip is None else [t for t in chip.tables() if t.figures] or [chip.resources]
    for t in tables:  # a chip of empty tables still reads back as a chip (not None)
        lines += ["", f"[{t.table}]"]
        lines += [f"{key} = {_figure_toml(f)}" for key, f in t.figures]
    return "\n".join(lines) + "\n"


def _figure_toml(figure) -> str:
    """A chip figure as the inline table a profile file gives it (``value``, ``source``, and
    ``low``, ``low_source``, ``high``, ``high_source`` where it carries a range)."""
    keys = ("value", "source", *(RANGE_KEYS if figure.ranged else ()))
    return "{ " + ", ".join(f"{k} = {_toml(getattr(figure, k))}" for k in keys) + " }"


def _toml(value) -> str:
    """``value`` (a string, boolean, integer, float or a list or tuple of them) as a TOML
    value that reads back equal: floats by ``repr`` (``inf``, ``nan`` as TOML spells them),
    strings in double quotes with every character outside printable ASCII escaped."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, str):
        return '"' + _ascii(value.replace("\\", "\\\\").replace('"', '\\"')) + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    raise TypeError(f"no TOML value for {value!r} ({type(value).__name__})")


def _ascii(text: str) -> str:
    """``text`` with every character outside printable ASCII as a TOML escape (``\\u00b5``)."""
    return "".join(
        c if " " <= c <= "~" else f"\\u{ord(c):04x}" if ord(c) <= 0xFFFF else f"\\U{ord(c):08x}"
        for c in text
    )


def at_step(profile: FixedPointProfile, dt: float) -> FixedPointProfile:
    """The clocked ``profile`` stepped every ``dt`` [s], named ``BASE@STEP`` (``loihi2@80us``;
    a name that has a step already keeps its base; :mod:`quantize.steps`)."""
    label = step_label(dt)
    said, n = re.subn(r"dt = [^,;]*", f"dt = {label}", profile.description)
    return replace(profile.with_dt(dt), name=stepped_name(profile.name, dt),
                   description=said if n else f"{profile.description}, dt = {label}")  # fmt: skip


def _stepped(text: str) -> FixedPointProfile:
    """``NAME@STEP`` (``loihi2@80us``, ``my_chip.toml@2e-5``): the clocked profile ``NAME``
    stepped every ``STEP`` (:mod:`quantize.steps`)."""
    base, _, step = text.rpartition("@")
    try:
        dt = parse_step(step)
    except ValueError as exc:
        raise ProfileError(f"profile {text!r}: {exc}") from None
    profile = load_profile(base)
    if not isinstance(profile, FixedPointProfile):
        raise ProfileError(
            f"profile {text!r}: {profile.name!r} is a {profile.kind!r} profile, which has no "
            "clock; only a clocked (fixed-point) profile takes @STEP"
        )
    return at_step(profile, dt)


def generic_fixed_point(bits: int, dt: float, name: str | None = None) -> FixedPointProfile:
    """The generic N-bit fixed-point chip: every word ``bits`` wide (decay constants at most
    30 bits), plain integer weights and biases (no exponents), threshold ``2^(bits-2)``,
    currents with up to ``bits // 2`` fractional bits, ``dt`` [s] time step.
    ``fixed16.toml`` is ``generic_fixed_point(16, 1e-4)``."""
    _check_int(bits, "generic fixed-point profile", "bits", 8, MAX_STATE_BITS)
    return FixedPointProfile(
        name=name or f"fixed{bits}",
        description=f"generic {bits}-bit fixed point, dt = {dt:g} s",
        dt=dt,
        state_bits=bits,
        decay_bits=min(bits, MAX_DECAY_BITS),
        refractory_bits=bits,
        weight_mantissa_bits=bits,
        weight_exponent_min=0,
        weight_exponent_max=0,
        trigger_shift_max=min(2 * bits, MAX_TRIGGER_SHIFT),
        current_shift_max=bits // 2,
        bias_mantissa_bits=bits,
        bias_exponent_min=0,
        bias_exponent_max=0,
        threshold_mantissa_bits=bits - 1,
        threshold_shift=0,
        headroom_bits=6,
    )
