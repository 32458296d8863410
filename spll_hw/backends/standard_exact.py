"""The standard-neuron sPLL as a backend, and what its clocked targets' backends share.

``standard-exact`` is its K-level gate in the golden engine, event by event: the cost of the
construction itself, with no time step, chip arithmetic or refractory stand-in (it takes the
golden backend's ``profile`` option, so its cost can be measured per chip profile).

The clocked targets' backends live beside their writers and build on :class:`Clocked` and the
construction's options here: ``nir-numpy``, ``nir-snntorch`` and ``nir-norse`` in
:mod:`mappings.nir.standard_backend`, ``standard-fixed-point`` and ``lava-standard`` in
:mod:`mappings.lava.standard_backend`.
"""

from __future__ import annotations

from spll_hw.backends.base import (
    Backend,
    Capabilities,
    Option,
    int_in_range,
    positive_float,
)
from spll_hw.backends.golden import GoldenBackend
from spll_hw.neuron_graph import NeuronGraph
from spll_hw.simulate import as_network

from ..construction.gate import (
    DEFAULT_INPUT_RATE,
    DEFAULT_LEVELS,
    DEFAULT_PLACEMENT,
    MAX_LEVELS,
    PLACEMENTS,
    GateOptions,
    gate_levels,
)


def choice(name: str, choices: tuple[str, ...]):
    """An option's converter that accepts one of ``choices`` (``ValueError`` naming ``name``)."""

    def convert(value: object) -> str:
        if value not in choices:
            raise ValueError(f"{name} must be one of {choices}, got {value!r}")
        return str(value)

    return convert


#: The construction's options, shared by its backends.
LEVELS_OPTION = Option(
    DEFAULT_LEVELS, f"gate levels K (1..{MAX_LEVELS})", int_in_range("levels", 1, MAX_LEVELS)
)
PLACEMENT_OPTION = Option(DEFAULT_PLACEMENT, "gate level placement",
                          choice("placement", PLACEMENTS))  # fmt: skip


#: Declared TDE-rate tolerance of the exact K-level gate against golden per placement, by the
#: fewest levels it holds for: about 1.5x the mean error measured on the conformance reference
#: set (``python -m spll_hw.backends.conformance --errors-only standard-exact:levels=K``;
#: uniform K = 2, 4, 8, 16: 0.36, 0.11, 0.027, 0.006; quantile: 0.37, 0.23, 0.10, 0.038). Few
#: levels fail on periodic input, whose facilitatory current sits where Poisson-placed levels
#: are coarse.
EXACT_GATE_TOLERANCE = {
    "uniform": ((16, 0.02), (8, 0.05), (4, 0.15), (2, 0.5), (1, 1.5)),
    "quantile": ((16, 0.06), (8, 0.15), (4, 0.35), (2, 0.55), (1, 1.5)),
}


class StandardExact(GoldenBackend):
    """The standard-neuron sPLL's K-level gate (:mod:`.construction`) in the golden engine:
    a CCO spike adds ``g_tde_trg * q(I_fac)`` at its exact time, ``q`` the staircase of the
    levels :func:`~.construction.gate_levels` places for the realised network (after the
    ``profile``'s rounding or mismatch) at ``input_rate``."""

    name = "standard-exact"
    description = "standard-neuron sPLL's K-level gate, exact event-driven (Rust core)"
    OPTIONS = {
        **GoldenBackend.OPTIONS,
        "levels": LEVELS_OPTION,
        "placement": PLACEMENT_OPTION,
        "input_rate": Option(DEFAULT_INPUT_RATE, "input rate [Hz] the levels are placed for",
                             positive_float("input_rate")),
    }  # fmt: skip

    @property
    def capabilities(self) -> Capabilities:
        k = int(self.options["levels"])
        table = EXACT_GATE_TOLERANCE[str(self.options["placement"])]
        tolerance = next(tol for fewest, tol in table if k >= fewest)
        return Capabilities(
            exact=True, dt=None, arithmetic="float", resume=True, probes=True, threads=True,
            rate_tolerance=tolerance,
        )  # fmt: skip

    def gate(self, network):
        return gate_levels(
            network, int(self.options["levels"]), str(self.options["placement"]),
            float(self.options["input_rate"]),
        )  # fmt: skip


def clocked_options(dt: float, dt_help: str) -> dict[str, Option]:
    """The options every clocked target of the construction takes: its step ``dt`` [s] by
    default (``dt_help`` says what it is), the gate's levels and their placement."""
    return {
        "dt": Option(dt, dt_help, positive_float("dt")),
        "levels": LEVELS_OPTION,
        "placement": PLACEMENT_OPTION,
    }


class Clocked(Backend):
    """A clocked target of the construction: its declared tolerance, ``rate_tolerance`` (a
    relative TDE-rate error) at the step ``measured_dt`` [s] it was measured at, grows in
    proportion beyond it; :meth:`graph` states what it prepared as a graph of standard
    neurons."""

    arithmetic: str
    measured_dt: float
    rate_tolerance: float

    def neuron_graph(self, network):
        """The construction this backend runs for ``network``, neuron for neuron
        (:meth:`graph` of what it prepares)."""
        return self.graph(self.prepared(as_network(network)))

    def graph(self, prepared) -> NeuronGraph:
        """What ``prepared`` (this backend's :meth:`prepare` of a network) holds as a graph of
        standard neurons, neuron for neuron."""
        raise NotImplementedError

    @property
    def gate_options(self) -> GateOptions:
        """The gate its options ask for (:func:`clocked_options`' ``levels`` and
        ``placement``, at the default input rate [Hz])."""
        return GateOptions(int(self.options["levels"]), str(self.options["placement"]))

    @property
    def capabilities(self) -> Capabilities:
        dt = float(self.options["dt"])
        return Capabilities(
            exact=False, dt=dt, arithmetic=self.arithmetic,
            rate_tolerance=self.rate_tolerance * max(1.0, dt / self.measured_dt),
        )  # fmt: skip
