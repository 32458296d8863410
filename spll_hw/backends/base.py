"""The backend protocol: what every simulator of an sPLL network does and declares.

A backend simulates a **batch** of input spike trains through one
:class:`~spll_hw.network.Network` and returns one :class:`~spll_hw.result.SimulationResult`
per train, or on the fast path just the ``(n_samples, n_spll)`` TDE rates the features need. It
is configured by options (``dt``, ``profile``, ...) given as keyword arguments or in a spec
string ``name:key=value:...`` (:mod:`spll_hw.backends`), and declares its
:class:`Capabilities`: exact or clocked, float or fixed point, resume, probes, threads, a board,
and its tolerance against the golden model.

Write a backend by subclassing :class:`Backend`: set ``name``, ``description``, ``extra``,
``requires`` and ``OPTIONS``, implement :attr:`Backend.capabilities` and :meth:`Backend._run`,
and register the class in the ``spll_hw.backends`` entry-point group of your package. The base
class validates every input the same way for every backend (spike trains, duration, phase
noise, threads, memory), draws the phase noise, and stamps results with the backend's spec;
:mod:`spll_hw.backends.conformance` then checks the contract.
"""

from __future__ import annotations

import abc
import importlib.util
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import chips
from ..limits import check_threads
from ..network import Network
from ..params import SpllParams
from ..result import SimulationResult
from ..simulate import as_network, batch_trains, check_recording


@dataclass(frozen=True)
class Option:
    """One option of a backend: its default, a help line and a converter that validates a
    value (raising ``ValueError``) and returns it in its proper type."""

    default: object
    help: str
    convert: Callable[[object], object] | None = None


@dataclass(frozen=True)
class Capabilities:
    """What a configured backend can do.

    Attributes:
        exact: event-driven with exact spike times (else clocked with time step ``dt``).
        dt: time step [s] of a clocked backend (``None`` when exact, or where each sPLL has
            its own step).
        arithmetic: ``"float"`` or ``"fixed"`` (integer state words of a chip profile).
        resume: continues a run from a result's ``final_state`` (``simulate(state=...)``).
        probes: samples state variables (``simulate(probe_times=...)``).
        threads: runs samples or sPLLs on several threads (``threads`` option of a call).
        hardware: drives a physical device.
        rate_tolerance: declared largest relative L1 error of the TDE-rate vector
            (``harness.metrics.rate_error``, mean over the conformance reference set of
            :mod:`spll_hw.backends.conformance`) against the golden model of the same network
            as the same chip profile realises it: the simulator's own error (time grid,
            arithmetic), not what the profile's rounding changes.
        tolerance_basis: why ``rate_tolerance`` is what it is, in words, where the backend's
            options decide it in a way a reader may not expect (a chip profile's own
            ``tolerance``, or another profile's measured arithmetic,
            :func:`mappings.fixed_point.backend.declared_tolerance`); ``""`` otherwise.
    """

    exact: bool
    dt: float | None
    arithmetic: str
    resume: bool = False
    probes: bool = False
    threads: bool = False
    hardware: bool = False
    rate_tolerance: float = 0.0
    tolerance_basis: str = ""

    def summary(self) -> str:
        """One line: ``exact, float, threads`` or ``dt = 1e-05 s, fixed point, board``."""
        step = "a step per sPLL" if self.dt is None else f"dt = {self.dt:g} s"
        parts = ["exact" if self.exact else step]
        parts.append("fixed point" if self.arithmetic == "fixed" else "float")
        parts += [name for name in ("resume", "probes", "threads") if getattr(self, name)]
        if self.hardware:
            parts.append("board")
        return ", ".join(parts)


def positive_float(name: str) -> Callable[[object], float]:
    """Converter of an option that must be a finite number > 0."""

    def convert(value: object) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float | str):
            raise ValueError(f"{name} must be a number > 0, got {value!r}")
        try:
            x = float(value)
        except ValueError:
            raise ValueError(f"{name} must be a number > 0, got {value!r}") from None
        if not (math.isfinite(x) and x > 0):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        return x

    return convert


def optional_int(name: str) -> Callable[[object], int | None]:
    """Converter of an option that is ``None`` or an integer >= 0."""

    def convert(value: object) -> int | None:
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise ValueError(f"{name} must be an integer >= 0, got {value!r}")
        return value

    return convert


def int_in_range(name: str, low: int, high: int) -> Callable[[object], int]:
    """Converter of an option that must be an integer in ``low..high`` (checked where the spec
    is parsed, so a bad value fails before any work)."""

    def convert(value: object) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise ValueError(f"{name} must be an integer in {low}..{high}, got {value!r}")
        return value

    return convert


def positive_int(name: str) -> Callable[[object], int]:
    """Converter of an option that must be an integer >= 1."""

    def convert(value: object) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
        return value

    return convert


def chip_profile(value: object) -> str | None:
    """Converter of the ``profile`` option: ``None``/``"none"`` or a known chip profile."""
    if value is None or value == "none":
        return None
    if not str(value).strip():
        raise ValueError("profile is empty: give a profile name (spll-hw chips lists them) or a "
                         "TOML file")  # fmt: skip
    chips.describe(str(value))  # unknown or broken profiles fail here, before any work
    return str(value)


def exact_parameters(value: object) -> str | None:
    """Converter of the ``exact`` option: ``None`` or sPLL parameter names joined by ``+``
    (kept as that canonical text, so the spec recreates it)."""
    if value is None:
        return None
    return "+".join(chips.exact_names(str(value)))


#: Parameters a ``profile`` leaves at their requested values: which formats cost accuracy.
EXACT_OPTION = Option(
    None,
    "with profile: sPLL parameters kept at their requested values, joined by '+' (e.g. "
    "tau_tde_fac+tau_tde), to see which of the chip's formats or mismatches costs accuracy",
    exact_parameters,
)
#: The options of a float backend that simulates the network as a chip realises it
#: (:meth:`Backend.prepare`): ``profile``, and ``chip_seed``, the seed of an analog profile's
#: mismatch draw (default: the profile's own seed).
PROFILE_OPTIONS = {
    "profile": Option(
        None,
        "chip profile (name or TOML file): simulate the network as this chip realises it "
        "(quantized or mismatched parameters); default: the network as given",
        chip_profile,
    ),
    "chip_seed": Option(
        None,
        "seed of an analog profile's mismatch draw (default: the profile's)",
        optional_int("chip_seed"),
    ),
}


class Backend(abc.ABC):
    """A simulator of sPLL networks (module docstring). Instances are immutable
    configurations; create them with options or through :func:`spll_hw.backends.get`."""

    #: Registered name (the first part of a spec).
    name: ClassVar[str]
    #: One line for listings.
    description: ClassVar[str]
    #: The pip extra that installs what it needs (``None``: the core).
    extra: ClassVar[str | None] = None
    #: Modules it needs; a missing one makes it unavailable, naming :attr:`extra`.
    requires: ClassVar[tuple[str, ...]] = ()
    #: Accepted options.
    OPTIONS: ClassVar[dict[str, Option]] = {}
    #: Options the conformance suite runs it with (e.g. a coarser ``dt`` for a slow runtime).
    CONFORMANCE_OPTIONS: ClassVar[dict[str, object]] = {}
    #: Samples per call that callers chunking a long list of trains should use (a slow start,
    #: e.g. a compilation, wants large batches; memory on a device small ones).
    batch_size: ClassVar[int] = 64
    #: Prepared networks kept per configured backend (:meth:`prepare` runs once per network).
    PREPARED_CACHE: ClassVar[int] = 4

    def __init__(self, **options: object) -> None:
        unknown = sorted(set(options) - set(self.OPTIONS))
        if unknown:
            known = ", ".join(self.OPTIONS) or "none"
            raise ValueError(
                f"backend {self.name!r} has no option(s) {unknown}; its options: {known}"
            )
        values = {}
        for key, option in self.OPTIONS.items():
            value = options.get(key, option.default)
            if value is not option.default and option.convert is not None:
                try:
                    value = option.convert(value)
                except ValueError as exc:
                    raise ValueError(f"backend {self.name!r}, option {key}: {exc}") from None
            values[key] = value
        if values.get("exact") is not None and values.get("profile") is None:
            raise ValueError(
                f"backend {self.name!r}: exact={values['exact']} keeps parameters exact on a "
                "chip; name the chip too (profile=NAME)"
            )
        self.options: dict[str, object] = values
        self._prepared: list[tuple[Network, object]] = []

    # ---------------------------------------------------------------------------- description
    @property
    def spec(self) -> str:
        """The spec that recreates this backend: its name and every non-default option."""
        parts = [self.name]
        parts += [
            f"{k}={_spec_value(v)}" for k, v in self.options.items() if v != self.OPTIONS[k].default
        ]
        return ":".join(parts)

    @property
    def label(self) -> str:
        """:attr:`spec` as reports and summaries show it: also naming the chip ``profile``
        where it is this backend's default, which the spec leaves out
        (``golden-fixed-point:profile=loihi2``, whose spec is ``golden-fixed-point``), so a
        reader sees which chip ran. It recreates the same backend."""
        parts = [self.name]
        parts += [
            f"{k}={_spec_value(v)}"
            for k, v in self.options.items()
            if v != self.OPTIONS[k].default or (k == "profile" and v is not None)
        ]
        return ":".join(parts)

    def __repr__(self) -> str:
        return f"<backend {self.spec}>"

    @classmethod
    def unavailable(cls) -> str | None:
        """Why this backend cannot run here (``None``: it can). The default checks
        :attr:`requires`; backends needing a device also look for it."""
        missing = [m for m in cls.requires if importlib.util.find_spec(m) is None]
        if missing:
            hint = f"pip install -e '.[{cls.extra}]'" if cls.extra else "install it"
            return f"needs {', '.join(missing)} ({hint})"
        return None

    @property
    @abc.abstractmethod
    def capabilities(self) -> Capabilities:
        """What this configuration can do."""

    # ---------------------------------------------------------------------------- running
    def simulate_batch(
        self,
        network: Network | SpllParams,
        inputs: Sequence[Sequence[float] | np.ndarray],
        duration: float,
        *,
        noise_sigma: float = 0.0,
        seed: int | None = None,
        threads: int | None = None,
        record_spikes: bool = False,
    ) -> list[SimulationResult]:
        """Simulate every input train (sample) of ``inputs`` through ``network``.

        Args:
            network: the network (a bare :class:`SpllParams` is a one-sPLL network).
            inputs: sorted input spike times [s] per sample, each 1-D, finite and >= 0; spikes
                after ``duration`` are not delivered (``info["inputs_after_end"]`` counts them).
            duration: run length [s], finite and > 0.
            noise_sigma: phase noise [s] added to every input spike (thesis 2.9); sample ``i``
                draws from stream ``i`` spawned from ``seed`` (``numpy.random.SeedSequence``),
                so results depend neither on the batch split nor on the thread count.
            seed: seed of the phase noise.
            threads: threads (``None``: all cores) for backends that use them.
            record_spikes: keep spike times (counts are always kept).

        Returns:
            One :class:`SimulationResult` per sample, in input order, whose ``backend`` is
            this backend's :attr:`spec`.

        Raises:
            ValueError: invalid input (naming it), a network this backend or its chip profile
                cannot represent, or a request beyond the machine's memory.
        """
        return self._checked_run(
            network, inputs, duration, noise_sigma, seed, threads, record_spikes, "inputs[{}]"
        )

    def simulate(
        self,
        network: Network | SpllParams,
        input_spike_times: Sequence[float] | np.ndarray,
        duration: float,
        *,
        noise_sigma: float = 0.0,
        seed: int | None = None,
        threads: int | None = None,
        record_spikes: bool = True,
        state: object | None = None,
        probe_times: Sequence[float] | np.ndarray | None = None,
    ) -> SimulationResult:
        """One input train (a batch of one; :meth:`simulate_batch` for the arguments), with
        spikes recorded by default. ``state`` continues a previous run of a backend that
        supports resuming; ``probe_times`` [s] samples the state variables of one that
        supports probes (``info["trace"]``)."""
        extras = {}
        if state is not None:
            if not self.capabilities.resume:
                raise ValueError(f"backend {self.spec!r} cannot resume a saved state")
            extras["state"] = state
        if probe_times is not None:
            if not self.capabilities.probes:
                raise ValueError(f"backend {self.spec!r} has no probes")
            extras["probe_times"] = probe_times
        if not extras:
            return self.simulate_batch(
                network, [input_spike_times], duration, noise_sigma=noise_sigma, seed=seed,
                threads=threads, record_spikes=record_spikes,
            )[0]  # fmt: skip
        return self._checked_run(
            network, [input_spike_times], duration, noise_sigma, seed, threads, record_spikes,
            "input_spike_times", **extras,
        )[0]  # fmt: skip

    def rates(
        self,
        network: Network | SpllParams,
        inputs: Sequence[Sequence[float] | np.ndarray],
        duration: float,
        *,
        noise_sigma: float = 0.0,
        seed: int | None = None,
        threads: int | None = None,
    ) -> np.ndarray:
        """TDE rates [Hz] of every sample, shape ``(n_samples, n_spll)``: the features of the
        texture pipeline (arguments as :meth:`simulate_batch`)."""
        results = self.simulate_batch(
            network, inputs, duration, noise_sigma=noise_sigma, seed=seed, threads=threads
        )
        n = as_network(network).n_spll
        return np.array([r.tde_rates for r in results]).reshape(len(results), n)

    def _checked_run(
        self, network, inputs, duration, noise_sigma, seed, threads, record_spikes, label, **extras
    ) -> list[SimulationResult]:
        """:meth:`simulate_batch` (its arguments; ``inputs`` [s], ``duration`` [s]): the checks,
        the run and the stamp, with ``extras`` (a saved ``state``, ``probe_times``) passed on to
        :meth:`_run`; a bad train ``i`` is named in the error as ``label.format(i)``."""
        net, duration = as_network(network), _checked_duration(duration)
        threads = check_threads(threads)
        trains = batch_trains(inputs, noise_sigma, seed, duration)
        for i, x in enumerate(trains):
            _check_train(x, label.format(i))
        if not trains:
            return []
        if record_spikes:
            check_recording(net.matrix(), duration, len(trains))
        prepared = self.prepared(net)
        start = time.perf_counter()
        results = self._run(
            prepared, trains, duration, threads=threads, record_spikes=record_spikes, **extras
        )
        return self._stamp(results, trains, duration, time.perf_counter() - start)

    # ---------------------------------------------------------------------------- hooks
    def prepared(self, network: Network) -> object:
        """:meth:`prepare` of ``network``, computed once per network object and kept (the last
        :data:`PREPARED_CACHE` networks): the chunks of one workload pay for realising a chip
        profile, building integers or compiling once."""
        for known, prepared in self._prepared:
            if known is network:
                return prepared
        prepared = self.prepare(network)
        self._prepared = [(network, prepared), *self._prepared[: self.PREPARED_CACHE - 1]]
        return prepared

    def neuron_graph(self, network: Network):
        """The graph of standard neurons this backend runs for ``network``
        (:class:`spll_hw.neuron_graph.NeuronGraph`: a construction's neurons, synapses and
        step), which ``chips`` and ``fit`` place and cost in place of the two-compartment sPLL;
        its results then carry every neuron's spikes (``info["neuron_counts"]``). ``None`` (the
        default): it runs the sPLL itself."""
        return None

    def prepare(self, network: Network) -> object:
        """What :meth:`_run` simulates for ``network``: by default the network itself, or, for
        a float backend with a ``profile`` option, the network as that chip realises it
        (``chip_seed`` choosing an analog profile's mismatch draw, ``exact`` parameters kept
        at their requested values; a fixed-point backend's profile is its arithmetic
        instead). A network that does not fit raises ``ValueError``."""
        profile = self.options.get("profile")
        if profile is None or self.capabilities.arithmetic != "float":
            return network
        realised = chips.realise(network, profile, seed=self.options.get("chip_seed")).network
        exact = self.options.get("exact")
        if exact is None:
            return realised
        return chips.keep_exact(realised, network, chips.exact_names(exact))

    def realised(self, network: Network | SpllParams) -> Network:
        """The network, in SI units, that this configuration simulates: ``network`` itself, or
        as its chip profile realises it (quantized or mismatched parameters; what
        ``golden:profile=P`` simulates). The golden model of it is this backend's reference
        (``capabilities.rate_tolerance``, :mod:`spll_hw.backends.conformance`).

        The default takes it from :meth:`prepare`: a float backend's prepared network, or the
        ``network`` attribute of what a fixed-point backend prepares (a
        ``quantize.QuantizedNetwork``). A fixed-point backend whose :meth:`prepare` returns the
        requested network (it realises the network inside :meth:`_run`) overrides this.
        """
        prepared = self.prepared(as_network(network))
        if self.capabilities.arithmetic == "float" and isinstance(prepared, Network):
            return prepared
        inner = getattr(prepared, "network", None)
        if isinstance(inner, Network):
            return inner
        raise NotImplementedError(
            f"backend {self.spec!r} does not say which network it realises: its prepare() "
            f"returns {type(prepared).__name__}; override realised()"
        )

    @abc.abstractmethod
    def _run(
        self,
        prepared: object,
        trains: list[np.ndarray],
        duration: float,
        *,
        threads: int | None,
        record_spikes: bool,
        **extras: object,
    ) -> list[SimulationResult]:
        """Simulate the validated, noise-jittered ``trains`` through what :meth:`prepare`
        returned; one result per train. ``extras`` are ``state`` / ``probe_times`` when the
        capabilities allow them."""

    def _stamp(
        self, results: list[SimulationResult], trains: list[np.ndarray], duration: float,
        wall: float,
    ) -> list[SimulationResult]:  # fmt: skip
        if len(results) != len(trains):
            raise RuntimeError(
                f"backend {self.spec!r} returned {len(results)} results for {len(trains)} inputs"
            )
        for result, train in zip(results, trains, strict=True):
            result.backend = self.spec
            if not math.isfinite(result.wall_time):
                result.wall_time = wall / len(trains)
            after = int(np.count_nonzero(train > duration))
            result.info["n_input_spikes"] = int(train.size) - after  # delivered spikes
            if after:
                result.info["inputs_after_end"] = after
        return results


def _spec_value(value: object) -> str:
    """An option value as a spec writes it (a loaded profile object by its ``name``)."""
    if isinstance(value, float):
        return f"{value:g}"
    return str(getattr(value, "name", value))


def _checked_duration(duration: float) -> float:
    if isinstance(duration, bool) or not isinstance(duration, int | float | np.floating):
        raise ValueError(f"duration must be a number of seconds, got {duration!r}")
    duration = float(duration)
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0 s, got {duration!r}")
    return duration


def _check_train(x: np.ndarray, what: str) -> None:
    """A train must be finite, >= 0 and sorted (``batch_trains`` already made it 1-D)."""
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ValueError(f"{what}: input spike {bad[0]} is not a finite time ({x[bad[0]]})")
    if x.size and x.min() < 0:
        i = int(np.argmin(x))
        raise ValueError(f"{what}: input spike {i} has negative time {x[i]} s")
    back = np.flatnonzero(np.diff(x) < 0)
    if back.size:
        i = int(back[0]) + 1
        raise ValueError(
            f"{what}: input spike times must be sorted; spike {i} ({x[i]} s) comes after "
            f"{x[i - 1]} s"
        )
