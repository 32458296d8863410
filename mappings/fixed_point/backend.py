"""``golden-fixed-point``: the discrete-time fixed-point reference of a chip profile.

Options: ``profile`` (a fixed-point ``quantize`` profile, default ``loihi2``) and ``dt`` [s]
(overrides the profile's time step). A spike at time ``t`` arrives at step
``max(1, ceil(t/dt))`` (:mod:`spll_hw.model.grid`), the run has ``round(duration/dt)`` steps and
a spike at step ``k`` is reported at ``k · dt``.

Each result's ``info`` has ``profile``, ``dt``, ``n_steps``, ``saturations``
(``(n_spll, 5)`` counts, :data:`SATURATION_NAMES`), ``state`` (``(n_spll, 9)`` integers after the
last step, :data:`STATE_NAMES`), ``warnings`` and the ``quantized`` network.
"""

from __future__ import annotations

from functools import cache

import numpy as np

import quantize
from spll_hw import _engine
from spll_hw.backends.base import Backend, Capabilities, Option, positive_float
from spll_hw.network import Network
from spll_hw.result import SimulationResult

#: Variables whose saturations the reference counts, in the order of ``info["saturations"]``.
SATURATION_NAMES: tuple[str, ...] = ("fac", "trg", "v_tde", "u_cco", "v_cco")

#: Integer state per sPLL after the last step, in the order of ``info["state"]``.
STATE_NAMES: tuple[str, ...] = (
    "fac", "trg", "v_tde", "tde_refr_left", "u_cco", "v_cco", "cco_refr_left",
    "tde_fired", "cco_fired",
)  # fmt: skip

#: Limit on time steps per call (a dt far too small for the run is an error).
MAX_STEPS = 1_000_000_000

#: Profile used when none is named.
DEFAULT_PROFILE = "loihi2"

#: Mean rate error at dt = 10 µs that a bundled profile's integer arithmetic causes on the
#: conformance reference set (``python -m spll_hw.backends.conformance --errors-only
#: golden-fixed-point:profile=P:dt=1e-5``): loihi2 0.1025 (its currents have no fractional
#: bits; with 4 it is 0.022), fixed16 0.383. It shrinks with larger steps (fewer truncations
#: per time constant), about as ``dt**-0.75``. A profile of a listed one's integer formats
#: (whatever its name and step) has its error; any other is taken as the worst, unless it
#: declares its own ``tolerance`` (:func:`declared_tolerance`).
ARITHMETIC_ERROR_10US = {"loihi2": 0.10, "fixed16": 0.38}
#: Rate error per second of time step from the time grid alone: a 32-bit profile without
#: truncation (``quantize.generic_fixed_point(32, dt)``) measures 0.0063 at 10 µs and 0.026 at
#: 50 µs, about 500 dt; the bound takes 1000 dt.
GRID_ERROR_PER_SECOND = 1000.0
#: Margin of the declared tolerance over the model of the measured errors.
TOLERANCE_MARGIN = 1.5


def rate_tolerance(arithmetic_error: float, dt: float) -> float:
    """Declared rate tolerance [relative L1] of a profile whose integer arithmetic errs by
    ``arithmetic_error`` at 10 µs (:data:`ARITHMETIC_ERROR_10US`), stepped by ``dt`` [s],
    against the golden model of the network it realises: ``1.5 (a (10 µs / dt)**0.75 + 1000
    dt)``. Measured means on the reference set (loihi2 / fixed16) at 5, 10, 20, 50, 100, 200
    µs: 0.172 / 0.651, 0.1025 / 0.383, 0.062 / 0.186, 0.034 / 0.085, 0.089 / 0.089, 0.191 /
    0.200; the bound is 0.26 / 0.97, 0.165 / 0.585, 0.12 / 0.37, 0.12 / 0.245, 0.18 / 0.25,
    0.32 / 0.36."""
    return TOLERANCE_MARGIN * (arithmetic_error * (1e-5 / dt) ** 0.75 + GRID_ERROR_PER_SECOND * dt)


def declared_tolerance(profile: quantize.FixedPointProfile) -> tuple[float, str]:
    """The rate tolerance the integer reference of ``profile`` declares at its own step, and
    why, in words for the export check's verdict (``""`` for a measured bundled profile itself,
    by its name or at a step of it, ``loihi2@80us``): the profile's own ``tolerance`` key
    where it has one, at every step; else :func:`rate_tolerance` of the measured bundled
    profile (:data:`ARITHMETIC_ERROR_10US`) whose integer formats
    (:meth:`~quantize.FixedPointProfile.formats`) it has, whatever its name; else of the
    worst measured arithmetic."""
    if profile.tolerance is not None:
        return float(profile.tolerance), (
            f"profile {profile.name}'s own [fixed_point] tolerance = {profile.tolerance:g}"
        )
    same = next((name for name in ARITHMETIC_ERROR_10US
                 if _bundled_formats(name) == profile.formats()), None)  # fmt: skip
    if same is not None:
        tolerance = rate_tolerance(ARITHMETIC_ERROR_10US[same], profile.dt)
        if profile.name.split("@")[0] == same:
            return tolerance, ""
        return tolerance, (f"profile {profile.name} has the integer formats of bundled {same}, "
                           f"so {same}'s measured arithmetic at dt = {profile.dt:g} s")  # fmt: skip
    worst = max(ARITHMETIC_ERROR_10US, key=ARITHMETIC_ERROR_10US.__getitem__)
    return rate_tolerance(ARITHMETIC_ERROR_10US[worst], profile.dt), (
        f"profile {profile.name} has the integer formats of no measured bundled profile "
        f"({', '.join(ARITHMETIC_ERROR_10US)}) and no [fixed_point] tolerance, so the worst "
        f"measured arithmetic, {worst}'s, at dt = {profile.dt:g} s (declare tolerance in its "
        "[fixed_point] table, or give --max-error)"
    )


@cache
def _bundled_formats(name: str) -> tuple[int, ...]:
    """The integer formats of bundled profile ``name`` (read once)."""
    return quantize.load_profile(name).formats()


def fixed_point_profile(value: object) -> str | quantize.FixedPointProfile:
    """Converter of the ``profile`` option: a fixed-point profile (name or TOML file, or a
    loaded ``quantize.FixedPointProfile`` from Python, e.g. ``generic_fixed_point(20, 3e-5)``,
    which a spec names by its ``name``)."""
    source = value if isinstance(value, quantize.FixedPointProfile) else str(value)
    profile = quantize.load_profile(source)
    if not isinstance(profile, quantize.FixedPointProfile):
        raise ValueError(
            f"profile {profile.name!r} is {profile.kind}, not fixed point: it has no integer "
            f"arithmetic to run (simulate it with golden:profile={profile.name})"
        )
    return source


class FixedPointBackend(Backend):
    """What a digital chip computes: the network's integers, stepped by ``dt``."""

    name = "golden-fixed-point"
    description = "discrete-time fixed-point reference of a chip profile (Rust, bit-exact)"
    OPTIONS = {
        "profile": Option(DEFAULT_PROFILE, "fixed-point chip profile (name or TOML file)",
                          fixed_point_profile),
        "dt": Option(None, "time step [s] (default: the profile's)", positive_float("dt")),
    }  # fmt: skip

    def __init__(self, **options: object) -> None:
        super().__init__(**options)
        profile = quantize.load_profile(self.options["profile"])
        dt = self.options["dt"]
        self.profile = profile if dt is None else profile.with_dt(float(dt))

    @property
    def capabilities(self) -> Capabilities:
        # Against the golden model of the realised network: the time grid (spikes on steps,
        # a one-step synaptic delay) and integer truncation (rate_tolerance).
        tolerance, basis = declared_tolerance(self.profile)
        return Capabilities(
            exact=False, dt=self.profile.dt, arithmetic="fixed", threads=True,
            rate_tolerance=tolerance, tolerance_basis=basis,
        )  # fmt: skip

    def prepare(self, network: Network) -> quantize.QuantizedNetwork:
        """The network's integers on this profile (``ValueError`` when it does not fit)."""
        return quantize.quantize(network, self.profile)

    def _run(
        self, prepared: quantize.QuantizedNetwork, trains, duration, *, threads, record_spikes,
    ) -> list[SimulationResult]:  # fmt: skip
        fixed = prepared.fixed
        out = _engine.simulate_fixed_point(
            np.ascontiguousarray(fixed.matrix, dtype=np.int64), trains, fixed.dt, duration,
            fixed.state_bits, fixed.decay_bits, record_spikes, threads, MAX_STEPS,
        )  # fmt: skip
        return [
            SimulationResult(
                tde_counts=out["tde_counts"][k],
                cco_counts=out["cco_counts"][k],
                duration=duration,
                tde_spikes=out["tde_spikes"][k] if record_spikes else None,
                cco_spikes=out["cco_spikes"][k] if record_spikes else None,
                info={
                    "profile": prepared.profile.name,
                    "dt": fixed.dt,
                    "n_steps": int(out["n_steps"]),
                    "saturations": out["saturations"][k],
                    "state": out["state"][k],
                    "warnings": _warnings(prepared, out["saturations"][k]),
                    "quantized": prepared,
                },
            )
            for k in range(len(trains))
        ]


def _warnings(q: quantize.QuantizedNetwork, saturations: np.ndarray) -> list[str]:
    """The quantization warnings plus one line per state variable that saturated."""
    out = list(q.report.warnings)
    for v, name in enumerate(SATURATION_NAMES):
        hits = saturations[:, v]
        if hits.any():
            out.append(
                f"state {name} saturated {int(hits.sum())} times in "
                f"{int(np.count_nonzero(hits))} sPLL(s)"
            )
    return out
