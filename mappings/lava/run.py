"""Run an sPLL network's exact processes on Lava's CPU simulator.

:func:`build` wires Lava's spike generator (``RingBuffer``), the fan-out and feedback ``Dense``
processes and the custom :class:`~mappings.lava.processes.process.TDE` and
:class:`~mappings.lava.processes.process.CCO`; :func:`simulate_lava` runs them with
``Loihi2SimCfg``, which starts every process in its own OS process (Lava's multi-process runtime),
and returns the golden engine's result type. (The standard construction runs as its exported folder:
:func:`mappings.lava.standard_backend.simulate_lava_standard`.)
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

import quantize
from mappings.lava.compat import import_lava
from mappings.lava.parameters import FloatParameters, split_weights
from spll_hw.model.grid import arrival_counts, n_steps
from spll_hw.network import Network
from spll_hw.result import SimulationResult


def _lava() -> SimpleNamespace:
    """Lava's classes and spll-hw's processes, imported when a network is built or run, so the
    parameters (:func:`make_spec`, the export) need no lava-nc."""
    import_lava()
    from lava.magma.core.run_conditions import RunSteps
    from lava.magma.core.run_configs import Loihi2SimCfg
    from lava.proc.dense.process import Dense
    from lava.proc.io.source import RingBuffer

    # optional extra: lava (these modules import it); the models register on import
    from mappings.lava.processes import models_fixed, models_float  # noqa: F401
    from mappings.lava.processes.process import CCO, TDE

    return SimpleNamespace(
        RunSteps=RunSteps, Loihi2SimCfg=Loihi2SimCfg, Dense=Dense, RingBuffer=RingBuffer,
        CCO=CCO, TDE=TDE,
    )  # fmt: skip


#: Lava run-config tags of the two model families.
TAGS = ("floating_pt", "fixed_pt")
#: Fixed-point profile of ``fixed_pt`` when none is named (``quantize/profiles``).
DEFAULT_PROFILE = "loihi2"
#: Time step [s] of ``floating_pt`` when none is given (the Loihi-2-like profile's).
DEFAULT_DT = 1e-5
#: Graded-spike width of the input fan-out (spike counts per step).
MESSAGE_BITS = 24


@dataclass(frozen=True)
class LavaSpec:
    """Everything the Lava processes of a network need, for one tag (what
    :func:`~mappings.lava.export.export_lava` writes).

    ``tde``, ``cco``: the processes' variables (arrays of shape ``(N,)``, argument names of
    :class:`~mappings.lava.processes.process.TDE` / :class:`~mappings.lava.processes.process.CCO`);
    ``fan_out``, ``feedback``: ``Dense`` weights per weight exponent (``{exponent: (N,) weights}``,
    the fan-out's column and the feedback's diagonal); ``formats``: the fixed-point word widths
    (empty for ``floating_pt``); ``info``: profile name, dt and warnings for the result.
    """

    tag: str
    dt: float
    tde: dict
    cco: dict
    fan_out: dict
    feedback: dict
    formats: dict
    info: dict

    @property
    def n_spll(self) -> int:
        return len(self.tde["vth"])


def make_spec(network, tag: str = "floating_pt", dt=None, profile=None) -> LavaSpec:
    """The :class:`LavaSpec` of ``network``; arguments as :func:`simulate_lava`."""
    if tag not in TAGS:
        raise ValueError(f"unknown Lava tag {tag!r}; choose from {TAGS}")
    return (_fixed if tag == "fixed_pt" else _float)(network, dt, profile)


@dataclass
class LavaNetwork:
    """The processes of one built network (``tde`` and ``cco`` record the spikes)."""

    source: object  # lava.proc.io.source.RingBuffer
    fan_out: list
    tde: object  # mappings.lava.processes.process.TDE
    cco: object  # mappings.lava.processes.process.CCO
    feedback: list
    num_steps: int
    spec: LavaSpec


def build(spec: LavaSpec, inputs, duration: float) -> LavaNetwork:
    """The Lava processes running ``spec`` on ``inputs`` (sorted spike times [s]) for
    ``duration`` [s]."""
    return build_batch(spec, [inputs], duration)


def build_batch(spec: LavaSpec, trains, duration: float) -> LavaNetwork:
    """The Lava processes running ``spec`` on every train of ``trains`` (each sorted spike
    times [s]) for ``duration`` [s], side by side: sample ``s`` drives its own copy of the
    sPLLs, neurons ``s * n_spll .. (s + 1) * n_spll - 1`` of ``tde`` and ``cco``, through its
    own row of the spike generator. Lava's runtime cost is per step and process, not per
    neuron, so a batch costs about what one train does."""
    xs = [_check_inputs(x, duration) for x in trains]
    if not xs:
        raise ValueError("a batch needs at least one input train")
    dt, n, k = spec.dt, spec.n_spll, len(xs)
    num_steps = n_steps(duration, dt)
    counts = np.array([arrival_counts(x, num_steps, dt) for x in xs])  # (k, num_steps)
    lava = _lava()
    RingBuffer, Dense, TDE, CCO = lava.RingBuffer, lava.Dense, lava.TDE, lava.CCO  # noqa: N806
    # The fan-out Dense delays one step: play step k's input at step k - 1 and start its buffer
    # with step 1's.
    source = RingBuffer(data=np.hstack([counts[:, 1:], np.zeros((k, 1), dtype=counts.dtype)]))
    owner = np.repeat(np.arange(k), n)  # sample of each neuron
    fan_out = []
    for e, w in spec.fan_out.items():
        weights = np.zeros((k * n, k), dtype=np.asarray(w).dtype)
        weights[np.arange(k * n), owner] = np.tile(w, k)
        dense = Dense(weights=weights, weight_exp=e, num_message_bits=MESSAGE_BITS,
                      name=f"fan_out_{e}")  # fmt: skip
        dense.a_buff.init = np.tile(w, k) * counts[owner, 0] * 2**e
        fan_out.append(dense)
    tde_vars = {key: np.tile(v, k) for key, v in spec.tde.items()}
    cco_vars = {key: np.tile(v, k) for key, v in spec.cco.items()}
    tde = TDE(log_capacity=_capacity(num_steps, spec.tde["refr"]), **tde_vars, **spec.formats)
    cco = CCO(log_capacity=_capacity(num_steps, spec.cco["refr"]), **cco_vars, **spec.formats)
    feedback = [Dense(weights=np.diag(np.tile(w, k)), weight_exp=e, name=f"feedback_{e}")
                for e, w in spec.feedback.items()]  # fmt: skip
    for dense in fan_out:
        source.s_out.connect(dense.s_in)
        dense.a_out.connect(tde.fac_in)
    cco.s_out.connect(tde.trg_in)
    for dense in feedback:
        tde.s_out.connect(dense.s_in)
        dense.a_out.connect(cco.fb_in)
    return LavaNetwork(source, fan_out, tde, cco, feedback, num_steps, spec)


def _capacity(num_steps: int, refr: np.ndarray) -> int:
    """Spikes a neuron can fire in ``num_steps`` (at most one per ``refr + 1`` steps)."""
    return num_steps // (int(np.min(refr)) + 1) + 1


def _float(network, dt, profile):
    if isinstance(network, quantize.QuantizedNetwork):
        network = network.network  # the realised values, with real arithmetic
    if dt is None:
        dt = DEFAULT_DT if profile is None else quantize.load_profile(profile).dt
    p = FloatParameters.from_network(network, float(dt))
    zero = np.zeros(network.n_spll, dtype=int)
    tde = dict(d_fac=p.d_fac, du=p.d_trg, dv=p.d_tde, gate=p.gate,
               gate_shift=zero, vth=p.tde_threshold, refr=p.tde_refr,
               current_shift=zero)  # fmt: skip
    cco = dict(du=p.d_cco_syn, dv=p.d_cco, bias=p.bias, vth=p.cco_threshold, refr=p.cco_refr,
               current_shift=zero)  # fmt: skip
    return LavaSpec("floating_pt", p.dt, tde, cco, {0: p.fac_weight}, {0: p.cco_weight}, {},
                    {"dt": p.dt})  # fmt: skip


def _fixed(network, dt, profile):
    if isinstance(network, quantize.QuantizedNetwork):
        if dt is not None or profile is not None:
            raise ValueError("the network is already quantized; pass the Network to choose "
                             "another profile or dt")  # fmt: skip
        q = network
    elif isinstance(network, Network):
        chosen = quantize.load_profile(DEFAULT_PROFILE if profile is None else profile)
        if not isinstance(chosen, quantize.FixedPointProfile):
            raise ValueError(
                f"profile {chosen.name!r} is not a fixed-point profile; lava-fixed needs one "
                f"such as {DEFAULT_PROFILE!r} (see quantize/profiles)"
            )
        q = quantize.quantize(network, chosen if dt is None else chosen.with_dt(float(dt)))
    else:
        raise ValueError(f"expected a spll_hw Network, got {type(network).__name__}")
    f = q.fixed
    tde = dict(d_fac=f["fac_decay"], du=f["trg_decay"], dv=f["tde_decay"],
               gate=f["trg_mantissa"], gate_shift=f["trg_shift"], vth=f["tde_threshold"],
               refr=f["tde_refr"], current_shift=f["tde_current_shift"])  # fmt: skip
    cco = dict(du=f["cco_syn_decay"], dv=f["cco_decay"], bias=f["cco_bias"],
               vth=f["cco_threshold"], refr=f["cco_refr"],
               current_shift=f["cco_current_shift"])  # fmt: skip
    formats = {"decay_bits": f.decay_bits, "state_bits": f.state_bits}
    info = {"dt": f.dt, "profile": f.profile, "warnings": list(q.report.warnings)}
    return LavaSpec("fixed_pt", f.dt, tde, cco, split_weights(f["fac_weight"]),
                    split_weights(f["cco_weight"]), formats, info)  # fmt: skip


def simulate_lava(
    network,
    input_spike_times,
    duration: float,
    tag: str = "floating_pt",
    dt: float | None = None,
    profile: str | None = None,
) -> SimulationResult:
    """Simulate one input spike train through an sPLL network as Lava processes on the CPU.

    Args:
        network: a :class:`~spll_hw.network.Network`, a ``quantize.QuantizedNetwork``
            (``fixed_pt``: its integers; ``floating_pt``: its realised values) or a
            :class:`LavaSpec` (e.g. from :func:`~mappings.lava.export.load_export`).
        input_spike_times: sorted input spike times [s] in ``[0, duration]``, shape ``(n,)``.
        duration: simulated time [s]; ``round(duration / dt)`` Lava time steps.
        tag: ``"floating_pt"`` (the algorithm in real numbers) or ``"fixed_pt"`` (bit-accurate
            integers of the ``quantize`` profile, equal to the ``golden-fixed-point`` backend).
        dt: time step [s] (default: the profile's, or :data:`DEFAULT_DT`).
        profile: ``quantize`` fixed-point profile name or file (default ``"loihi2"``).

    Returns:
        A :class:`SimulationResult` with ``backend`` ``"lava-float"`` or ``"lava-fixed"``;
        spike times ``k dt`` for a spike at step ``k``. ``wall_time`` is the run after
        compilation and process start-up; ``info`` has ``setup_time``, ``dt``, ``num_steps``,
        ``saturated`` (clipped updates per population) and ``warnings``.

    Raises:
        ValueError: bad inputs, an unknown tag or profile, a network the fixed-point profile
            cannot represent (the message names the sPLL and parameter), or lava-nc missing.
    """
    return simulate_lava_batch(network, [input_spike_times], duration, tag, dt, profile)[0]


def simulate_lava_batch(
    network,
    trains,
    duration: float,
    tag: str = "floating_pt",
    dt: float | None = None,
    profile: str | None = None,
) -> list[SimulationResult]:
    """:func:`simulate_lava` of several input trains in one Lava network
    (:func:`build_batch`: each train drives its own copy of the sPLLs), one result per train,
    each equal to the train's run alone. ``wall_time`` and ``info["setup_time"]`` are the
    batch's divided by its size; ``info["batch"]`` is the size."""
    start = time.perf_counter()
    if isinstance(network, LavaSpec):
        if (dt, profile) != (None, None) or tag != network.tag:
            raise ValueError(f"a LavaSpec fixes tag ({network.tag!r}), dt and profile")
        spec = network
    else:
        spec = make_spec(network, tag, dt, profile)
    net = build_batch(spec, trains, duration)
    k, n = len(trains), spec.n_spll
    lava = _lava()
    RunSteps, Loihi2SimCfg = lava.RunSteps, lava.Loihi2SimCfg  # noqa: N806
    run_cfg = Loihi2SimCfg(select_tag=tag)
    net.tde.run(condition=RunSteps(num_steps=1), run_cfg=run_cfg)
    try:
        ready = time.perf_counter()
        if net.num_steps > 1:
            net.tde.run(condition=RunSteps(num_steps=net.num_steps - 1), run_cfg=run_cfg)
        wall = time.perf_counter() - ready
        recorded = {
            pop: (getattr(net, pop).count.get().astype(np.int64),
                  getattr(net, pop).log.get().astype(np.int64),
                  getattr(net, pop).saturated.get().astype(np.int64))
            for pop in ("tde", "cco")
        }  # fmt: skip
    finally:
        net.tde.stop()
    results = []
    for s in range(k):
        own = slice(s * n, (s + 1) * n)
        spikes = {pop: [log[i, : count[i]] * spec.dt for i in range(own.start, own.stop)]
                  for pop, (count, log, _) in recorded.items()}  # fmt: skip
        saturated = {pop: int(sat[own].sum()) for pop, (_, _, sat) in recorded.items()}
        warnings = list(spec.info.get("warnings", ())) + [
            f"{pop.upper()} states clipped {c} times at the largest state value"
            for pop, c in saturated.items()
            if c
        ]
        results.append(
            SimulationResult(
                tde_counts=recorded["tde"][0][own],
                cco_counts=recorded["cco"][0][own],
                duration=float(duration),
                backend="lava-float" if tag == "floating_pt" else "lava-fixed",
                tde_spikes=spikes["tde"],
                cco_spikes=spikes["cco"],
                wall_time=wall / k,
                info={
                    **spec.info,
                    "tag": tag,
                    "num_steps": net.num_steps,
                    "setup_time": (ready - start) / k,
                    "saturated": saturated,
                    "warnings": warnings,
                    "batch": k,
                },
            )  # fmt: skip
        )
    return results


def _check_inputs(inputs, duration: float) -> np.ndarray:
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0 s, got {duration!r}")
    x = np.asarray(inputs, dtype=float)
    if x.ndim != 1:
        raise ValueError(f"input spike times must be a 1-D array, got shape {x.shape}")
    if x.size and (not np.all(np.isfinite(x)) or x.min() < 0 or x.max() > duration):
        raise ValueError(f"input spike times must be finite and within [0, {duration}] s")
    if np.any(np.diff(x) < 0):
        raise ValueError("input spike times must be sorted")
    return x
