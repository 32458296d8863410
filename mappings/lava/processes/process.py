"""The CCO and TDE of N sPLLs as Lava Processes (one process per population, shape ``(N,)``).

Ports::

    spike generator (RingBuffer) ─> Dense (fan-out, weights g_tde_fac) ─> TDE.fac_in
    CCO.s_out ─────────────────────────────────────────────────────────> TDE.trg_in
    TDE.s_out ─> Dense (feedback, diagonal weights g_cco) ──────────────> CCO.fb_in

A spike at step ``k`` reaches its targets at step ``k + 1`` (:mod:`mappings.lava.parameters`):
the feedback ``Dense`` buffers one step, and the CCO sends the spikes of the previous step before
it updates. The fan-out ``Dense`` also delays by one step, so the spike generator plays the input
one step early (and the ``Dense`` buffer starts with the first step's input). In fixed point a
``Dense`` shares one weight exponent, so weights with different exponents get one ``Dense``
each, all feeding the same port.

Variables shared by both ProcessModels, with Lava's LIF conventions: ``du``, ``dv`` (and the
TDE's ``d_fac``) are the decays (float: fraction lost per step, ``1 - exp(-dt/tau)``; fixed:
``delta`` out of ``2**decay_bits``); ``bias`` per step; ``vth`` the threshold; ``gate`` and
``gate_shift`` the trigger gate (float: factor and 0); ``current_shift`` the fractional bits of
the currents (fixed only; 0 in float). Recording: ``count`` spikes per neuron,
``log[i, :count[i]]`` the Lava time steps they happened in, ``saturated`` clipped updates. The
fixed-point word widths ``decay_bits`` and ``state_bits`` are process parameters.

Lava's compiler finds ProcessModels by executing every module next to the Process as a
top-level file (not registered in ``sys.modules``). So the modules of this package import each
other by absolute name, and those defining dataclasses do without ``from __future__ import
annotations`` (string annotations make ``dataclasses`` look the module up and fail).
"""

from __future__ import annotations

from lava.magma.core.process.ports.ports import InPort, OutPort
from lava.magma.core.process.process import AbstractProcess
from lava.magma.core.process.variable import Var


class _Neurons(AbstractProcess):
    """State, refractory counter and spike recording common to both populations."""

    def __init__(self, *, name: str, log_capacity: int, formats: dict, **vars_) -> None:
        shape = (len(vars_["vth"]),)
        super().__init__(shape=shape, name=name, **formats)
        self.s_out = OutPort(shape=shape)
        self.u = Var(shape=shape, init=0)
        self.v = Var(shape=shape, init=0)
        self.refr_left = Var(shape=shape, init=0)
        self.count = Var(shape=shape, init=0)
        self.log = Var(shape=(shape[0], log_capacity), init=0)
        self.saturated = Var(shape=shape, init=0)
        for key, value in vars_.items():
            setattr(self, key, Var(shape=shape, init=value))


class CCO(_Neurons):
    """Current-controlled oscillators: a LIF neuron with bias (offset current) whose synapse
    ``u`` receives the TDE's feedback on ``fb_in`` (already weighted by the feedback ``Dense``).

    Args: arrays of shape ``(N,)``: ``du``, ``dv`` decays of synapse and membrane, ``bias``,
    ``vth`` threshold, ``refr`` refractory steps, ``current_shift``; ``log_capacity`` spikes
    recorded per neuron; ``decay_bits``, ``state_bits`` (fixed point only).
    """

    def __init__(self, *, du, dv, bias, vth, refr, current_shift, log_capacity: int, **formats):
        super().__init__(
            name="cco", log_capacity=log_capacity, formats=formats,
            du=du, dv=dv, bias=bias, vth=vth, refr=refr, current_shift=current_shift,
        )  # fmt: skip
        self.fb_in = InPort(shape=self.u.shape)
        self.s_buff = Var(shape=self.u.shape, init=0)


class TDE(_Neurons):
    """Temporal difference encoders: facilitatory current ``i_fac`` fed by ``fac_in`` (input
    spikes weighted by the fan-out ``Dense``); a CCO spike on ``trg_in`` adds the gate applied
    to ``i_fac`` to the trigger current ``u``; LIF membrane ``v``.

    Args: arrays of shape ``(N,)``: ``d_fac``, ``du``, ``dv`` decays of facilitatory current,
    trigger current and membrane; ``gate``, ``gate_shift`` the gate (float: factor, 0; fixed:
    ``(i_fac * gate) >> gate_shift``); ``vth``; ``refr``; ``current_shift``; ``log_capacity``;
    ``decay_bits``, ``state_bits`` (fixed point only).
    """

    def __init__(self, *, d_fac, du, dv, gate, gate_shift, vth, refr, current_shift,
                 log_capacity: int, **formats):  # fmt: skip
        super().__init__(
            name="tde", log_capacity=log_capacity, formats=formats, d_fac=d_fac, du=du, dv=dv,
            gate=gate, gate_shift=gate_shift, vth=vth, refr=refr, current_shift=current_shift,
        )  # fmt: skip
        self.fac_in = InPort(shape=self.u.shape)
        self.trg_in = InPort(shape=self.u.shape)
        self.i_fac = Var(shape=self.u.shape, init=0)
