"""Brian2 as backends ``brian2-numpy``, ``brian2-cython`` and ``brian2-cpp_standalone``.

Options: ``dt`` [s] (default 10 µs), ``method`` (Brian2 integration method, default ``exact``),
``profile`` / ``chip_seed`` (simulate the network as a chip profile realises it). A batch runs as
one Brian2 network with a copy of the sPLLs per sample
(:func:`~mappings.brian2.run.simulate_brian2_batch`).
"""

from __future__ import annotations

from typing import ClassVar

from spll_hw.backends.base import PROFILE_OPTIONS, Backend, Capabilities, Option, positive_float
from spll_hw.result import SimulationResult

from .run import simulate_brian2_batch

#: Time step [s] when none is given.
DEFAULT_DT = 1e-5
#: The conformance suite's step: numpy's per-step overhead makes 10 us slow.
CONFORMANCE_DT = 5e-5


def _method(value: object) -> str:
    text = str(value)
    if not text.isidentifier():
        raise ValueError(f"method must be a Brian2 integration method name, got {value!r}")
    return text


class Brian2Backend(Backend):
    """The sPLL network as Brian2 NeuronGroups and Synapses, clock-driven (one target)."""

    target: ClassVar[str]
    extra = "brian2"
    requires = ("brian2",)
    OPTIONS = {
        "dt": Option(DEFAULT_DT, "time step [s]", positive_float("dt")),
        "method": Option("exact", "Brian2 integration method of the neurons", _method),
        **PROFILE_OPTIONS,
    }

    CONFORMANCE_OPTIONS = {"dt": CONFORMANCE_DT}

    @property
    def capabilities(self) -> Capabilities:
        dt = float(self.options["dt"])
        # Inputs and crossings act at the end of their step: errors grow faster than dt.
        # Measured mean rate error on the conformance reference set (every target alike):
        # 0.0083 at 10 us (largest sample 0.020), 0.0786 at 50 us (0.142), about
        # 0.0083 (dt / 10 us)**1.4; declared 1.5 times that, at least 0.0125.
        return Capabilities(
            exact=False, dt=dt, arithmetic="float",
            rate_tolerance=max(0.0125, 1.5 * 0.0083 * (dt / 1e-5) ** 1.4),
        )  # fmt: skip

    def _run(self, prepared, trains, duration, *, threads, record_spikes) -> list[SimulationResult]:
        # The whole batch is one Brian2 network (one build, one compilation).
        return simulate_brian2_batch(
            prepared, trains, duration, dt=float(self.options["dt"]), target=self.target,
            method=str(self.options["method"]), record_spikes=record_spikes,
        )  # fmt: skip


class Brian2Numpy(Brian2Backend):
    name = "brian2-numpy"
    target = "numpy"
    description = "Brian2, numpy code generation (clock-driven)"


class Brian2Cython(Brian2Backend):
    name = "brian2-cython"
    target = "cython"
    description = "Brian2, Cython code generation (clock-driven)"


class Brian2CppStandalone(Brian2Backend):
    name = "brian2-cpp_standalone"
    target = "cpp_standalone"
    description = "Brian2, C++ standalone (clock-driven; a build per batch, kept per shape)"
