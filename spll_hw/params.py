"""Parameters of one spiking phase-locked loop (sPLL) and its free-running frequency.

Units are SI throughout: seconds, amperes, farads, volts, hertz. With the thesis's normalisation
(C = V_thr = 1) currents are in "volts per second" and gains are dimensionless multipliers of them;
nothing in the engine depends on that choice.

The 15 parameters follow section 2.4.2 of the thesis; the names of the eight tuned ones follow the
columns of its Table 6 (``tau_cco_syn`` is tau_õ,syn, ``g_tde_fac`` is g_Δ,fac, ...).
"""

from __future__ import annotations

import math
import numbers
import tomllib
from dataclasses import MISSING, asdict, dataclass, fields, replace
from pathlib import Path

from . import _engine
from .model.frequency import free_frequency, offset_for_frequency

#: Column order of the (n_spll, 15) parameter matrix handed to every backend; defined by the
#: Rust core (``engine/src/params.rs``): tau_cco_syn, tau_cco, c_cco, g_cco, i_cco_offset,
#: t_cco_refr, v_cco_thr, tau_tde_fac, tau_tde_trg, tau_tde, c_tde, g_tde_fac, g_tde_trg,
#: t_tde_refr, v_tde_thr.
PARAM_NAMES: tuple[str, ...] = tuple(_engine.PARAM_NAMES)

_POSITIVE = (
    "tau_cco_syn",
    "tau_cco",
    "c_cco",
    "v_cco_thr",
    "tau_tde_fac",
    "tau_tde_trg",
    "tau_tde",
    "c_tde",
    "v_tde_thr",
)
_NON_NEGATIVE = ("g_cco", "g_tde_fac", "g_tde_trg", "t_cco_refr", "t_tde_refr", "i_cco_offset")


@dataclass(frozen=True)
class SpllParams:
    """The 15 parameters of one sPLL (thesis section 2.4.2, Tables 6-7 names).

    CCO (current-controlled oscillator): synapse time constant ``tau_cco_syn`` [s], membrane time
    constant ``tau_cco`` [s], capacitance ``c_cco`` [F], synapse gain ``g_cco`` (current added per
    TDE spike), constant offset current ``i_cco_offset`` [A], refractory period ``t_cco_refr`` [s]
    and threshold ``v_cco_thr`` [V].

    TDE (temporal difference encoder): facilitatory and trigger synapse time constants
    ``tau_tde_fac``, ``tau_tde_trg`` [s], membrane time constant ``tau_tde`` [s], capacitance
    ``c_tde`` [F], facilitatory gain ``g_tde_fac`` (current added per input spike), trigger gain
    ``g_tde_trg`` (a CCO spike adds ``g_tde_trg * I_fac``), refractory period ``t_tde_refr`` [s]
    and threshold ``v_tde_thr`` [V].

    ``i_cco_offset`` defaults to 0 (a CCO that never fires); use :meth:`with_free_frequency` or a
    :class:`~spll_hw.network.Network` layout to set it from a target free-running frequency.
    """

    tau_cco_syn: float
    tau_cco: float
    tau_tde_trg: float
    tau_tde_fac: float
    tau_tde: float
    g_cco: float
    g_tde_trg: float
    g_tde_fac: float
    i_cco_offset: float = 0.0
    c_cco: float = 1.0
    c_tde: float = 1.0
    v_cco_thr: float = 1.0
    v_tde_thr: float = 1.0
    t_cco_refr: float = 1e-3
    t_tde_refr: float = 1e-3

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise ValueError(
                    f"SpllParams.{f.name} must be a real number, got {value!r} "
                    f"({type(value).__name__})"
                )
            try:
                number = float(value)
            except OverflowError:  # an int beyond the float range
                number = math.inf
            if not math.isfinite(number):
                raise ValueError(f"SpllParams.{f.name} must be finite, got {value!r}")
            object.__setattr__(self, f.name, number)
        for name in _POSITIVE:
            if getattr(self, name) <= 0:
                raise ValueError(
                    f"SpllParams.{name} must be > 0, got {getattr(self, name)!r} "
                    "(time constants, capacitances and thresholds are positive)"
                )
        for name in _NON_NEGATIVE:
            if getattr(self, name) < 0:
                raise ValueError(f"SpllParams.{name} must be >= 0, got {getattr(self, name)!r}")

    # ----------------------------------------------------------------------------- conversions
    def as_row(self) -> list[float]:
        """The parameters in :data:`PARAM_NAMES` order (one row of the network matrix)."""
        return [getattr(self, name) for name in PARAM_NAMES]

    @classmethod
    def from_row(cls, row) -> SpllParams:
        """Inverse of :meth:`as_row`."""
        return cls(**{name: float(v) for name, v in zip(PARAM_NAMES, row, strict=True)})

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: dict, *, source: str = "parameters") -> SpllParams:
        """Build from a mapping; unknown keys raise ``ValueError`` naming them and ``source``."""
        if not isinstance(values, dict):
            raise ValueError(
                f"{source}: must be a table of sPLL parameters ([spll] with name = value "
                f"lines), got {type(values).__name__} {values!r}"
            )
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ValueError(
                f"{source}: unknown sPLL parameter(s) {unknown}; known names: {sorted(known)}"
            )
        missing = sorted(
            f.name for f in fields(cls) if f.name not in values and f.default is MISSING
        )
        if missing:
            raise ValueError(f"{source}: missing sPLL parameter(s) {missing}")
        return cls(**values)

    @classmethod
    def from_toml(cls, path: str | Path) -> SpllParams:
        """Read the ``[spll]`` table of a TOML file (the format :meth:`to_toml` writes)."""
        path = Path(path)
        doc = read_toml(path, "parameter file")
        if "spll" not in doc:
            raise ValueError(f"{path}: no [spll] table (expected the sPLL parameters there)")
        return cls.from_dict(doc["spll"], source=f"{path} [spll]")

    def to_toml(self) -> str:
        """The parameters as a ``[spll]`` TOML table."""
        lines = ["[spll]"] + [f"{k} = {v!r}" for k, v in self.to_dict().items()]
        return "\n".join(lines) + "\n"

    # ----------------------------------------------------------------------------- frequencies
    def free_frequency(self) -> float:
        """Free-running CCO frequency [Hz] (eq. 6); 0 if the offset never reaches threshold."""
        return free_frequency(
            self.i_cco_offset, self.tau_cco, self.c_cco, self.v_cco_thr, self.t_cco_refr
        )

    def with_free_frequency(self, frequency: float) -> SpllParams:
        """A copy whose offset current makes the CCO free-run at ``frequency`` [Hz]."""
        return replace(
            self,
            i_cco_offset=offset_for_frequency(
                frequency, self.tau_cco, self.c_cco, self.v_cco_thr, self.t_cco_refr
            ),
        )

    def time_scaled(self, scale: float) -> SpllParams:
        """The same sPLL running ``scale`` times faster (thesis 2.4.3).

        Time constants, capacitances and refractory periods are divided by ``scale``; gains,
        offset current and thresholds stay. Every spike time of the scaled sPLL driven by input
        times ``t / scale`` is the original spike time divided by ``scale``.
        """
        if not (math.isfinite(scale) and scale > 0):
            raise ValueError(f"time scale must be finite and > 0, got {scale!r}")
        names = (
            "tau_cco_syn", "tau_cco", "tau_tde_trg", "tau_tde_fac", "tau_tde",
            "c_cco", "c_tde", "t_cco_refr", "t_tde_refr",
        )  # fmt: skip
        return replace(self, **{n: getattr(self, n) / scale for n in names})


def read_toml(path: Path, what: str) -> dict:
    """The TOML document at ``path``; a missing file or bad TOML is an error naming the file
    (``what`` says what kind of file was expected)."""
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such {what}")
    with path.open("rb") as fh:
        try:
            return tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"{path}: not valid TOML: {exc}") from exc
        except UnicodeDecodeError as exc:
            raise ValueError(
                f"{path}: not a text file (byte {exc.start} is not UTF-8): a {what} is TOML text"
            ) from exc
