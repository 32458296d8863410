"""The standard-neuron sPLL as NIR (:mod:`mappings.nir.standard`) in NIR consumers, as backends:
``nir-numpy`` (spll-hw's executor, :mod:`mappings.nir.executor`), ``nir-snntorch`` and
``nir-norse``.

Each builds the graph of the network (:func:`~mappings.nir.standard.to_standard_nir`: options
``dt``, ``levels``, ``placement``, ``refractory``), writes it to a NIR file, loads the file in
the consumer and steps it (:func:`~mappings.nir.consumers.run_consumer`), all samples of a batch
at once. What they compute is the same graph by the same rules: the three agree spike for spike
(``tests/test_standard_nir.py``).
"""

from __future__ import annotations

import importlib.util
import tempfile
from pathlib import Path

from spll_hw.backends.base import Option
from spll_hw.backends.standard_exact import Clocked, choice, clocked_options

from .consumers import run_consumer
from .neuron_graph import nir_graph
from .standard import DEFAULT_DT, REFRACTORY, to_standard_nir

#: Declared TDE-rate tolerance against golden at 100 µs, K = 8, refractory unit, from the error
#: per preset (benchmarks/bench_standard_presets.py; docs/backends.md, "Refractory periods and
#: the error per preset"): the largest error of the vary-offset presets the graph represents,
#: on 1 s of 300 Hz Poisson and on a BioTac sample: 10.4 % (biotac-vary-offset-lif's BioTac
#: sample; 12.0 % since the exact charge, kept: the export's own check decides what is written,
#: and picks a finer dt without --dt). Presets above it fail their export's check, which
#: refuses them (exit 2) with the sPLLs and what would help.
NIR_RATE_TOLERANCE = 0.11


class _NirConsumer(Clocked):
    consumer: str
    extra = "nir"
    arithmetic = "float"
    measured_dt = DEFAULT_DT
    rate_tolerance = NIR_RATE_TOLERANCE
    OPTIONS = {
        **clocked_options(DEFAULT_DT, "time step [s] written into the graph"),
        "refractory": Option("refractory-unit", "refractory periods (or their stand-in)",
                             choice("refractory", REFRACTORY)),
    }  # fmt: skip

    def prepare(self, network):
        return to_standard_nir(network, self.gate_options, dt=float(self.options["dt"]),
                               refractory=str(self.options["refractory"]))  # fmt: skip

    def graph(self, prepared):
        return nir_graph(prepared.graph)

    def _run(self, prepared, trains, duration, *, threads, record_spikes):
        import nir

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "network.nir"
            nir.write(path, prepared.graph)
            return run_consumer(self.consumer, path, trains, duration, record_spikes=record_spikes)


class NirNumpy(_NirConsumer):
    name = "nir-numpy"
    description = "standard-neuron sPLL as NIR, spll-hw's executor of the consumers' rules"
    consumer = "numpy"
    requires = ("nir",)


class _TorchConsumer(_NirConsumer):
    """A consumer on torch: it needs ``nir``, the consumer's package, torch and nirtorch."""

    extra = None
    #: How to install the consumer (not an extra: torch from PyPI is 4 GB).
    install: str

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        cls.requires = ("nir", cls.consumer, "torch", "nirtorch")

    @classmethod
    def unavailable(cls) -> str | None:
        missing = [m for m in cls.requires if importlib.util.find_spec(m) is None]
        return f"needs {', '.join(missing)} ({cls.install})" if missing else None


class NirSnntorch(_TorchConsumer):
    name = "nir-snntorch"
    description = "standard-neuron sPLL as NIR, run by snnTorch's NIR import (dt = 100 µs)"
    consumer = "snntorch"
    install = "pip install torch snntorch nirtorch"

    def __init__(self, **options: object) -> None:
        super().__init__(**options)
        if float(self.options["dt"]) != DEFAULT_DT:
            raise ValueError(
                f"backend 'nir-snntorch', option dt: snnTorch's NIR import steps by "
                f"{DEFAULT_DT:g} s, got {self.options['dt']!r}"
            )


class NirNorse(_TorchConsumer):
    name = "nir-norse"
    description = "standard-neuron sPLL as NIR, run by Norse's NIR import"
    consumer = "norse"
    install = "pip install torch nirtorch && pip install --no-deps norse"
