"""Python API of the golden model: exact event-driven simulation in the Rust core.

All times are in seconds. Input spike trains are 1-D float arrays of sorted times in
``[0, duration]``. The simulation runs with the GIL released; batches run in parallel over
samples on all cores.
"""

from __future__ import annotations

import hashlib
import numbers
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import _engine
from .activity import warn_if_silent
from .limits import (
    MEMORY_SHARE,
    available_memory,
    check_memory,
    check_threads,
    cores,
    out_of_memory,
)
from .network import Network
from .params import PARAM_NAMES, SpllParams
from .result import SimulationResult

#: Default limit on events per sPLL and call (see ``max_events``).
DEFAULT_MAX_EVENTS = 200_000_000
#: Largest ``max_events`` (the engine counts events in 64 bits).
MAX_EVENTS_LIMIT = 2**64 - 1

#: Bytes per spike time (float64): recorded spikes, input trains.
SPIKE_BYTES = 8
#: Shortest interval [s] between two spikes of one neuron assumed by the recording estimate
#: when a neuron has no refractory period (as the engine's event-limit message).
MIN_INTERVAL = 1e-5
#: Bytes per probe time and sPLL: five float64 values, held twice while the engine hands the
#: traces over.
PROBE_BYTES = 2 * 5 * 8
#: Bytes the engine holds per input spike beyond the caller's array: its own copy of the train,
#: plus, for every sPLL it simulates at the same time, the facilitatory current at each input.
INPUT_COPY_BYTES = 8
INPUT_RUN_BYTES = 16

#: Names of the five probed state variables, in the order of :attr:`Trace.values`' last axis.
TRACE_VARIABLES = ("i_fac", "i_trg", "v_tde", "i_cco", "v_cco")


class UnverifiedStateWarning(UserWarning):
    """A saved :class:`EngineState` without a network fingerprint (saved by spll-hw before
    fingerprints, or built by hand) was resumed: it could not be checked to belong to the
    network it continues."""


@dataclass(frozen=True)
class EngineState:
    """Saved state of every sPLL after a run, shape ``(n_spll, 13)`` (columns
    ``_engine.STATE_NAMES``: time, facilitatory current and time, then time, potential, current,
    refractory end and next spike of the TDE and of the CCO); pass to ``simulate`` (with the
    input spikes that follow ``time``) to continue the run bit for bit. ``simulate`` checks it in
    full against the network and refuses any value the engine cannot have made, naming it.

    ``network`` is the fingerprint (:func:`network_fingerprint`) of the network and gate that
    made the state; ``simulate`` refuses to resume it on any other. A state without one (pickled
    before fingerprints existed, or built by hand from ``values``) is accepted with an
    :class:`UnverifiedStateWarning`: its values are still checked, its parameters cannot be."""

    values: np.ndarray
    network: str | None = None

    def __post_init__(self) -> None:
        try:
            values = np.asarray(self.values, dtype=np.float64)
        except (TypeError, ValueError):
            values = np.empty(0)
        if values.ndim != 2 or values.shape[1:] != (_engine.STATE_LEN,):
            got = f"shape {values.shape}" if np.ndim(self.values) else repr(self.values)
            raise ValueError(
                f"EngineState.values must be a float array of shape (n_spll, "
                f"{_engine.STATE_LEN}), a result's final_state.values; got {got}"
            )
        if not values.size:
            raise ValueError("EngineState.values holds no sPLL: shape (0, 13)")
        object.__setattr__(self, "values", values)

    @property
    def time(self) -> float:
        """Time [s] the saved run reached."""
        return float(self.values[0, 0])


@dataclass(frozen=True)
class Trace:
    """State variables sampled at ``times`` (right-continuous: after the events at that time).

    ``values`` has shape ``(n_spll, len(times), 5)`` with the variables of
    :data:`TRACE_VARIABLES`: facilitatory and trigger currents, TDE potential, CCO synapse current
    and CCO potential.
    """

    times: np.ndarray
    values: np.ndarray

    def __getitem__(self, name: str) -> np.ndarray:
        """One variable, shape ``(n_spll, len(times))``."""
        return self.values[:, :, TRACE_VARIABLES.index(name)]


def add_phase_noise(
    spikes: np.ndarray, sigma: float, rng: np.random.Generator, duration: float
) -> np.ndarray:
    """Shift every spike by ``N(0, sigma**2)`` seconds (thesis 2.9), re-sort, and keep those
    still inside ``[0, duration]`` (spikes jittered out of the window do not happen in it)."""
    if sigma == 0:
        return spikes
    jittered = np.sort(spikes + rng.normal(0.0, sigma, size=spikes.shape))
    return jittered[(jittered >= 0) & (jittered <= duration)]


def batch_trains(
    inputs: Sequence, noise_sigma: float, seed: int | None, duration: float
) -> list[np.ndarray]:
    """Validated input trains of a batch, each with its own phase-noise stream spawned from
    ``seed`` (``numpy.random.SeedSequence``) so results do not depend on the thread count."""
    check_noise_sigma(noise_sigma)
    check_seed(seed)
    trains = [as_spike_train(x, f"inputs[{i}]") for i, x in enumerate(inputs)]
    if noise_sigma > 0:
        rngs = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(len(trains))]
        trains = [
            add_phase_noise(x, noise_sigma, r, duration) for x, r in zip(trains, rngs, strict=True)
        ]
    return trains


def as_network(network: Network | SpllParams) -> Network:
    """``network`` itself, or a one-sPLL network of bare parameters; ``ValueError`` otherwise."""
    if isinstance(network, SpllParams):
        return Network.single(network)
    if not isinstance(network, Network):
        raise ValueError(f"expected a Network or SpllParams, got {type(network).__name__}")
    return network


def network_fingerprint(matrix: np.ndarray, gate=None) -> str:
    """Fingerprint of what a saved state depends on: the parameter matrix (``Network.matrix``,
    ``(n_spll, 15)`` float64, its bytes) and the gate (``engine_gate``'s arrays, or none); 16
    hex digits of SHA-256."""
    digest = hashlib.sha256(b"spll-hw engine state v1")
    for a in (matrix, *(engine_gate(gate) or ())):
        a = np.ascontiguousarray(a, dtype="<f8")
        digest.update(repr(a.shape).encode() + a.tobytes())
    return digest.hexdigest()[:16]


def _start_time(state: EngineState | None, net: Network, fingerprint: str) -> float:
    """Time [s] a run resumed from ``state`` on ``net`` (of ``fingerprint``) starts at: 0 from
    rest. A state of another network of the same size, or with a time that is not finite and
    >= 0, is refused; every other value the engine checks, naming it."""
    if state is None:
        return 0.0
    if not isinstance(state, EngineState):
        raise ValueError(
            f"state must be an EngineState (a result's final_state), got {type(state).__name__}"
        )
    values = state.values
    if state.network is None:
        warnings.warn(
            "the saved state carries no network fingerprint (saved by an older spll-hw or "
            "built by hand): it cannot be checked to belong to this network; resuming it on "
            "another network gives wrong spikes",
            UnverifiedStateWarning,
            stacklevel=3,
        )
    elif state.network != fingerprint and len(values) == net.n_spll:
        raise ValueError(
            f"the saved state belongs to another network (fingerprint {state.network}) than "
            f"this one ({fingerprint}): same size, but its parameters or gate differ; resume "
            "on the network and gate that made it"
        )
    bad = np.flatnonzero(~(np.isfinite(values[:, 0]) & (values[:, 0] >= 0)))
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"saved state of sPLL {i}: t = {float(values[i, 0])!r} must be a finite time >= 0 s"
        )
    return float(values[0, 0])


def check_seed(seed) -> None:
    """The phase-noise seed must be ``None`` or an integer >= 0 (``numpy.random``'s range)."""
    if seed is None:
        return
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise ValueError(
            f"seed must be None or an integer >= 0 (a numpy.random seed), got {seed!r}"
        )


def check_max_events(max_events) -> int:
    """``max_events`` as an int, refused unless an integer in 1 .. 2**64 - 1."""
    if isinstance(max_events, bool) or not isinstance(max_events, numbers.Integral):
        raise ValueError(
            f"max_events must be an integer in 1 .. 2**64 - 1 (events per sPLL and call), got "
            f"{max_events!r}"
        )
    if not 1 <= max_events <= MAX_EVENTS_LIMIT:
        raise ValueError(
            f"max_events must be in 1 .. 2**64 - 1 (events per sPLL and call), got {max_events}"
        )
    return int(max_events)


def as_spike_train(times, what: str) -> np.ndarray:
    """``times`` as a contiguous 1-D float64 array; ``what`` names it in the error."""
    arr = np.asarray(times, dtype=np.float64)
    if arr.ndim != 1:
        raise ValueError(f"{what} must be a 1-D array of spike times, got shape {arr.shape}")
    return np.ascontiguousarray(arr)


def recording_bytes(
    matrix: np.ndarray, duration: float, n_samples: int = 1, max_events: int = DEFAULT_MAX_EVENTS
) -> float:
    """Upper bound [bytes] on the spike times a recording of ``n_samples`` runs of ``duration``
    seconds of the network ``matrix`` (``Network.matrix``, ``(n_spll, 15)``) keeps: every neuron
    fires at most once per refractory period (or per :data:`MIN_INTERVAL` without one), and an
    sPLL has at most ``max_events`` spikes."""
    refr = matrix[:, [PARAM_NAMES.index("t_tde_refr"), PARAM_NAMES.index("t_cco_refr")]]
    per_spll = np.sum(duration / np.maximum(refr, MIN_INTERVAL) + 1, axis=1)
    return n_samples * float(np.sum(np.minimum(per_spll, max_events))) * SPIKE_BYTES


def check_recording(
    matrix: np.ndarray, duration: float, n_samples: int = 1, max_events: int = DEFAULT_MAX_EVENTS
) -> None:
    """Refuse a spike recording that could outgrow memory (:func:`recording_bytes`)."""
    check_memory(
        recording_bytes(matrix, duration, n_samples, max_events),
        f"recording the spikes of {len(matrix)} sPLLs for {duration:g} s"
        + (f" in {n_samples} samples" if n_samples > 1 else "")
        + " (up to one spike per refractory period per neuron)",
        "record counts only (record_spikes=False), or run shorter or fewer samples",
    )


def recordable_samples(
    matrix: np.ndarray, duration: float, max_events: int = DEFAULT_MAX_EVENTS
) -> int:
    """How many runs of ``duration`` s of the network ``matrix`` one spike recording can hold
    within :data:`~spll_hw.limits.MEMORY_SHARE` of the available memory (at least 1: a run
    that does not fit alone is refused by :func:`check_recording`)."""
    per_sample = recording_bytes(matrix, duration, 1, max_events)
    return max(1, int(MEMORY_SHARE * available_memory() // per_sample))


def check_probes(n_spll: int, n_probes: int, fix: str = "probe fewer times or sPLLs") -> None:
    """Refuse state traces of ``n_spll`` sPLLs at ``n_probes`` times that could outgrow memory
    (:data:`PROBE_BYTES` each); ``fix`` says what to do instead."""
    check_memory(
        float(n_spll) * n_probes * PROBE_BYTES,
        f"probing the state of {n_spll} sPLLs at {n_probes} times",
        fix,
    )


#: Bytes a Python-side parameter matrix costs per sPLL while it is built (15 Python floats in a
#: list per row, then the float64 row).
MATRIX_BUILD_BYTES = 600


def network_matrix(net: Network) -> np.ndarray:
    """``net.matrix()``, refused up front when it could not be built in the available memory
    (:data:`MATRIX_BUILD_BYTES` per sPLL), and with a message if it runs out all the same."""
    what = f"building the parameter matrix of {net.n_spll} sPLLs"
    needed = float(net.n_spll) * MATRIX_BUILD_BYTES
    check_memory(needed, what, "use fewer sPLLs")
    with out_of_memory(what, needed, "use fewer sPLLs"):
        return net.matrix()


def check_train_size(n_spikes: float, what: str) -> None:
    """Refuse an input train of ``n_spikes`` spikes too big to hold (:data:`SPIKE_BYTES` each)
    before it is made; ``what`` describes it."""
    check_memory(
        n_spikes * SPIKE_BYTES,
        f"{what} ({n_spikes:.3g} spikes)",
        "lower its rate or shorten the duration",
    )


def check_engine_inputs(trains: Sequence[np.ndarray], concurrent: int) -> None:
    """Refuse input trains whose copies in the engine could outgrow memory: one copy of each
    train, and :data:`INPUT_RUN_BYTES` per spike of the longest for each of ``concurrent`` sPLLs
    simulated at the same time."""
    total = sum(x.size for x in trains)
    longest = max((x.size for x in trains), default=0)
    check_memory(
        total * INPUT_COPY_BYTES + longest * INPUT_RUN_BYTES * concurrent,
        f"simulating {total} input spikes ({len(trains)} trains, up to {longest} each, "
        f"{concurrent} at a time)",
        "use fewer input spikes (a lower rate or a shorter duration) or fewer threads",
    )


def check_noise_sigma(noise_sigma: float) -> None:
    """Phase noise must be a finite standard deviation >= 0 [s]."""
    if not (np.isfinite(noise_sigma) and noise_sigma >= 0):
        raise ValueError(f"noise_sigma must be finite and >= 0 s, got {noise_sigma!r}")


def engine_gate(gate) -> tuple[np.ndarray, np.ndarray] | None:
    """``gate`` as the engine takes it: ``None``, or C-contiguous float64 ``(thresholds,
    increments)`` of shape ``(n_spll, K)`` [A] (a pair of arrays, or an object with those two
    attributes such as :class:`spll_hw.construction.Gate`)."""
    if gate is None:
        return None
    if hasattr(gate, "thresholds") and hasattr(gate, "increments"):
        gate = (gate.thresholds, gate.increments)
    try:
        thresholds, increments = gate
    except (TypeError, ValueError):
        raise ValueError(
            f"gate must be None or a pair (thresholds, increments) of (n_spll, K) arrays, got "
            f"{type(gate).__name__}"
        ) from None
    arrays = []
    for name, a in (("thresholds", thresholds), ("increments", increments)):
        a = np.ascontiguousarray(a, dtype=np.float64)
        if a.ndim != 2:
            raise ValueError(f"gate {name} must have shape (n_spll, K), got shape {a.shape}")
        arrays.append(a)
    return arrays[0], arrays[1]


def simulate(
    network: Network | SpllParams,
    input_spike_times: Sequence[float] | np.ndarray,
    duration: float,
    noise_sigma: float = 0.0,
    seed: int | None = None,
    *,
    record_spikes: bool = True,
    state: EngineState | None = None,
    probe_times: Sequence[float] | np.ndarray | None = None,
    max_events: int = DEFAULT_MAX_EVENTS,
    gate=None,
) -> SimulationResult:
    """Simulate one input spike train through every sPLL of ``network``, exactly.

    Args:
        network: the sPLL network (a bare :class:`SpllParams` is a one-sPLL network).
        input_spike_times: sorted input spike times [s], shape ``(n_spikes,)``.
        duration: end of the run [s]; events at exactly ``duration`` are included. When resuming
            from ``state`` this is the absolute end time, not the length of the continuation.
        noise_sigma: phase noise [s] added to every input spike (thesis 2.9), seeded by ``seed``.
        seed: seed of the phase noise (``numpy.random.default_rng``).
        record_spikes: keep TDE and CCO spike times (counts are always kept).
        state: continue a previous run from its ``final_state``; inputs must then all be later
            than ``state.time``.
        probe_times: sorted times [s] at which to sample currents and potentials; the result's
            ``info["trace"]`` is then a :class:`Trace`.
        max_events: more events than this in one sPLL is an error (guards against parameters
            that make a neuron fire absurdly fast instead of hanging).
        gate: ``None`` (the golden model), or the standard-neuron sPLL's K-level gate as
            ``(thresholds, increments)`` [A], each of shape ``(n_spll, K)`` (or a
            :class:`spll_hw.construction.Gate`): a CCO spike then adds ``g_tde_trg *
            sum(increments[i, k] for levels with I_fac > thresholds[i, k])`` to the trigger
            current instead of ``g_tde_trg * I_fac``, at the exact spike time.

    Returns:
        A :class:`SimulationResult` with ``backend="golden"`` and ``final_state``.

    Raises:
        ValueError: on any invalid parameter, spike time, duration or state, naming it, and on
            a recording, probe trace or input bigger than the machine's memory allows.
        KeyboardInterrupt: on Ctrl-C, within about 0.1 s (the engine stops).
    """
    net = as_network(network)
    spikes = as_spike_train(input_spike_times, "input_spike_times")
    check_noise_sigma(noise_sigma)
    check_seed(seed)
    max_events = check_max_events(max_events)
    duration = float(duration)
    if noise_sigma > 0:
        spikes = add_phase_noise(spikes, noise_sigma, np.random.default_rng(seed), duration)
    probes = None if probe_times is None else as_spike_train(probe_times, "probe_times")
    matrix = network_matrix(net)
    fingerprint = network_fingerprint(matrix, gate)
    begin = _start_time(state, net, fingerprint)
    if record_spikes and np.isfinite(duration - begin):
        check_recording(matrix, duration - begin, max_events=max_events)
    if probes is not None:
        check_probes(net.n_spll, probes.size)
    check_engine_inputs([spikes], min(cores(), net.n_spll))
    start = time.perf_counter()
    planned = spikes.size * INPUT_COPY_BYTES + (0 if probes is None else probes.size) * PROBE_BYTES
    if record_spikes:
        planned += recording_bytes(matrix, duration - begin, 1, max_events)
    with out_of_memory(
        f"simulating {net.n_spll} sPLLs for {duration - begin:g} s",
        planned,
        "record counts only (record_spikes=False), or run shorter pieces (each resumed from "
        "the last one's final_state)",
    ):
        out = _engine.simulate(
            matrix,
            spikes,
            duration,
            record_spikes,
            None if state is None else np.ascontiguousarray(state.values),
            probes,
            max_events,
            engine_gate(gate),
        )
    wall = time.perf_counter() - start
    # Spikes after the end are not delivered (nor counted as inputs).
    info: dict = {"n_input_spikes": int(np.count_nonzero(spikes <= duration))}
    if probes is not None:
        info["trace"] = Trace(probes, out["trace"])
    result = SimulationResult(
        tde_counts=out["tde_counts"],
        cco_counts=out["cco_counts"],
        duration=duration - begin,
        backend="golden",
        tde_spikes=out["tde_spikes"],
        cco_spikes=out["cco_spikes"],
        wall_time=wall,
        final_state=EngineState(out["state"], network=fingerprint),
        info=info,
    )
    warn_if_silent(net, matrix, result, info["n_input_spikes"])
    return result


def simulate_batch(
    network: Network | SpllParams,
    inputs: Sequence[Sequence[float] | np.ndarray],
    duration: float,
    noise_sigma: float = 0.0,
    seed: int | None = None,
    *,
    record_spikes: bool = False,
    threads: int | None = None,
    max_events: int = DEFAULT_MAX_EVENTS,
    gate=None,
) -> list[SimulationResult]:
    """Simulate many input spike trains (samples) through the same network, in parallel.

    Samples run on ``threads`` threads (all cores by default, at most
    :func:`spll_hw.limits.max_threads`) with the GIL released. With ``noise_sigma > 0`` each
    sample gets its own noise stream spawned from ``seed`` (``numpy.random.SeedSequence``), so
    results do not depend on the thread count. ``gate`` is :func:`simulate`'s.

    Returns:
        One :class:`SimulationResult` per sample, in input order (``wall_time`` is the batch's
        wall time divided by the number of samples).

    Raises:
        ValueError: as :func:`simulate`, and for a thread count beyond the limit.
        KeyboardInterrupt: on Ctrl-C, within about 0.1 s (the engine stops).
    """
    net = as_network(network)
    threads = check_threads(threads)
    max_events = check_max_events(max_events)
    duration = float(duration)
    trains = batch_trains(inputs, noise_sigma, seed, duration)
    if not trains:
        return []
    matrix = network_matrix(net)
    if record_spikes and np.isfinite(duration):
        check_recording(matrix, duration, len(trains), max_events)
    check_engine_inputs(trains, min(threads or cores(), len(trains)))
    start = time.perf_counter()
    planned = sum(x.size for x in trains) * INPUT_COPY_BYTES
    if record_spikes:
        planned += recording_bytes(matrix, duration, len(trains), max_events)
    with out_of_memory(
        f"simulating {len(trains)} samples of {net.n_spll} sPLLs for {duration:g} s",
        planned,
        "record counts only (record_spikes=False), or run fewer samples or threads at a time",
    ):
        out = _engine.simulate_batch(
            matrix, trains, duration, record_spikes, threads, max_events, engine_gate(gate)
        )
    per_sample = (time.perf_counter() - start) / len(trains)
    return [
        SimulationResult(
            tde_counts=out["tde_counts"][i],
            cco_counts=out["cco_counts"][i],
            duration=duration,
            backend="golden",
            tde_spikes=out["tde_spikes"][i] if record_spikes else None,
            cco_spikes=out["cco_spikes"][i] if record_spikes else None,
            wall_time=per_sample,
            info={"n_input_spikes": int(np.count_nonzero(trains[i] <= duration))},
        )
        for i in range(len(trains))
    ]


def poisson_spikes(rate: float, duration: float, seed: int) -> np.ndarray:
    """Sorted Poisson spike times [s] at ``rate`` [Hz] on ``[0, duration)``, drawn from
    ``numpy.random.default_rng(seed)``. A train too big for the memory is refused before it is
    made."""
    if not (np.isfinite(rate) and rate >= 0):
        raise ValueError(f"Poisson rate must be finite and >= 0 Hz, got {rate!r}")
    check_train_size(rate * duration, f"a Poisson input of {rate:g} Hz for {duration:g} s")
    rng = np.random.default_rng(seed)
    return np.sort(rng.uniform(0.0, duration, rng.poisson(rate * duration)))


def poisson_trains(rate: float, duration: float, count: int, seed: int) -> list[np.ndarray]:
    """``count`` Poisson spike trains of ``rate`` [Hz] over ``duration`` [s]
    (:func:`poisson_spikes`); train ``k`` drawn from seed ``seed + k``."""
    return [poisson_spikes(rate, duration, seed + k) for k in range(count)]


def periodic_spikes(frequency: float, duration: float, phase: float = 0.0) -> np.ndarray:
    """Spike times ``phase + k / frequency`` inside ``[0, duration]``; empty for frequency 0.
    A train too big for the memory is refused before it is made."""
    if not (np.isfinite(frequency) and frequency >= 0):
        raise ValueError(f"input frequency must be finite and >= 0 Hz, got {frequency!r}")
    if frequency == 0:
        return np.empty(0)
    count = np.floor((duration - phase) * frequency) + 1
    check_train_size(count, f"a periodic input of {frequency:g} Hz for {duration:g} s")
    return phase + np.arange(int(count)) / frequency


def frequency_response(
    params: SpllParams,
    free_freq: float,
    input_freqs: Sequence[float] | np.ndarray,
    duration: float,
    *,
    threads: int | None = None,
) -> np.ndarray:
    """TDE firing rate [Hz] of one sPLL against the frequency of a periodic input (thesis
    Figures 8-9), shape ``(len(input_freqs),)``.

    The sPLL's offset current is set so that it free-runs at ``free_freq`` [Hz]; each input is a
    periodic train starting at t = 0 lasting ``duration`` seconds.
    """
    net = Network.single(params, free_frequency=free_freq)
    freqs = np.asarray(input_freqs, dtype=float).reshape(-1)
    trains = [periodic_spikes(f, duration) for f in freqs]
    results = simulate_batch(net, trains, duration, threads=threads)
    return np.array([r.tde_rates[0] for r in results])
