"""The standard-neuron sPLL on Lava's own LIF and Dense (:mod:`mappings.lava.standard`) as
backends: ``standard-fixed-point`` runs Loihi's arithmetic in the Rust core
(:mod:`mappings.lava.loihi`), ``lava-standard`` the exported folder's ``run.py`` on lava-nc
(:func:`simulate_lava_standard`); they agree spike for spike
(``tests/test_standard_lava.py``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from spll_hw.backends.base import Capabilities, Option, int_in_range
from spll_hw.backends.standard_exact import Clocked, choice, clocked_options
from spll_hw.network import Network
from spll_hw.result import SimulationResult
from spll_hw.simulate import as_network

from .clocks import CLOCKS, clocked_standard, run_integers
from .clocks import DEFAULT_HOLDS as CLOCK_HOLDS
from .export import write_standard
from .loihi import results_from
from .neuron_graph import lava_graph
from .standard import CURRENTS, DEFAULT_DT, HOLDS, lava_standard

#: Declared TDE-rate tolerance against golden at 50 µs, K = 8, refractory unit, from the error
#: per preset (benchmarks/bench_standard_presets.py; docs/backends.md, "Refractory periods and
#: the error per preset"): the largest error of the vary-offset presets the integers represent,
#: on 1 s of 300 Hz Poisson and on a BioTac sample, 3.8 % (vibtac-vary-offset-lif's BioTac
#: sample), 5.6 % on its exports' own checks (16 levels, 6
#: inputs across each network's frequencies; up to 6.9 % on the vary-offset presets since kicks
#: carry their exact charge, 2026-11-27) and 4.8 % mean on the backend conformance set (worst
#: sample 7.2 %). Presets above it fail their export's check, which refuses them (exit 2) with
#: the sPLLs and what would help.
LAVA_RATE_TOLERANCE = 0.07


class _LavaStandardBase(Clocked):
    arithmetic = "fixed"
    measured_dt = DEFAULT_DT
    rate_tolerance = LAVA_RATE_TOLERANCE
    OPTIONS = {
        **clocked_options(DEFAULT_DT, "time step [s]"),
        "hold": Option(HOLDS[0], "refractory hold (dithered: a counter's, mean-correct)",
                       choice("hold", HOLDS)),
        "clock": Option(CLOCKS[0], "one: every sPLL at step dt; per-spll: each at the step "
                        "that holds its shorter refractory period in `holds` steps and a half "
                        "(dt unused; mappings/lava/clocks.py)", choice("clock", CLOCKS)),
        "holds": Option(CLOCK_HOLDS, "refractory steps of every sPLL with clock=per-spll",
                        int_in_range("holds", 2, 64)),
        "current": Option(CURRENTS[0], "lif: each CCO's current is its LIF's u; graded: a "
                          "GradedVec keeps it at 2^-s a_in units, passed to the CCO every step "
                          "(mappings/lava/graded_current.py)", choice("current", CURRENTS)),
    }  # fmt: skip
    CONFORMANCE_OPTIONS = {"dt": measured_dt}

    @property
    def capabilities(self) -> Capabilities:
        """:class:`~spll_hw.backends.standard_exact.Clocked`'s at ``dt``; with a clock per sPLL no
        one step (``dt`` ``None``) and the tolerance measured at the 50 µs step."""
        if self.options["clock"] == CLOCKS[0]:
            return super().capabilities
        return Capabilities(exact=False, dt=None, arithmetic=self.arithmetic,
                            rate_tolerance=self.rate_tolerance)  # fmt: skip

    def realised(self, network) -> Network:
        """The requested network itself: the standard-neuron construction approximates the
        exact sPLL (its gate levels and Loihi's integers are inside the declared tolerance),
        so golden of that network is the reference."""
        return as_network(network)

    def prepare(self, network):
        """Loihi's integers of ``network``: a :class:`~mappings.lava.standard.LavaStandard`
        at ``dt``, or with ``clock=per-spll`` a :class:`~mappings.lava.clocks.ClockedStandard`."""
        gate = self.gate_options
        choices = {"hold": str(self.options["hold"]), "current": str(self.options["current"])}
        if self.options["clock"] == CLOCKS[0]:
            return lava_standard(network, gate, dt=float(self.options["dt"]), **choices)
        return clocked_standard(network, int(self.options["holds"]), gate, **choices)

    def graph(self, prepared):
        return lava_graph(prepared)


class StandardFixedPoint(_LavaStandardBase):
    """The project's bit-accurate reference of what ``lava-standard`` computes (numpy)."""

    name = "standard-fixed-point"
    description = "standard-neuron sPLL in Loihi's LIF/Dense integers (numpy, = lava-standard)"

    def _run(self, prepared, trains, duration, *, threads, record_spikes):
        return run_integers(prepared, trains, duration, self.spec, record_spikes)


class LavaStandard(_LavaStandardBase):
    """The exported folder's ``run.py`` on lava-nc, one subprocess per sample."""

    name = "lava-standard"
    description = "standard-neuron sPLL on Lava's own LIF/Dense, bit-accurate (exported run.py)"
    extra = "lava"
    requires = ("lava",)

    def _run(self, prepared, trains, duration, *, threads, record_spikes):
        return simulate_lava_standard(prepared, trains, duration, self.spec)


def simulate_lava_standard(
    params, trains, duration: float, backend: str = "lava-standard"
) -> list[SimulationResult]:
    """Simulate every train (sorted input spike times [s]) through the standard construction's
    integers ``params`` (:func:`~mappings.lava.standard.lava_standard`) on Lava's own LIF and
    Dense for ``duration`` [s].

    Writes the export folder (:func:`~mappings.lava.export.write_standard`; ``params`` may be
    a :class:`~mappings.lava.clocks.ClockedStandard`) and runs its ``run.py`` once per train in
    a subprocess without ``PYTHONPATH``, so it runs on lava-nc and numpy alone. Returns one
    result per train (counts only, ``info["dt"]``: the step, or each sPLL's), named
    ``backend``; ``RuntimeError`` with the end of ``run.py``'s error output when it fails.
    """
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        write_standard(params, folder)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        for x in trains:
            np.save(folder / "spikes.npy", np.asarray(x, dtype=float))
            done = subprocess.run(
                [sys.executable, "run.py", "spikes.npy", repr(float(duration))],
                cwd=folder, env=env, capture_output=True, text=True, check=False,
            )  # fmt: skip
            if done.returncode != 0:
                raise RuntimeError(f"lava-standard run.py failed:\n{done.stderr[-3000:]}")
            out = json.loads(done.stdout.strip().splitlines()[-1])
            counts = {k: np.array([out[k]]) for k in ("tde_counts", "cco_counts")}
            results += results_from(counts, duration, out["dt"], backend, False)
    return results
