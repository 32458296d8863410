"""Bit-accurate fixed-point ProcessModels (tag ``fixed_pt``) of the CCO and TDE processes.

The integer algorithm of ``engine/src/fixed_point.rs`` (see :mod:`mappings.lava.parameters`):
``decay(x) = (x (2^D - delta)) >> D`` with ``D = decay_bits``, every state non-negative and
clipped at ``2^(state_bits - 1) - 1`` (``saturated`` counts the clips), the gate
``(i_fac * gate) >> gate_shift``, currents with ``current_shift`` fractional bits (the membrane
adds ``current >> current_shift``), all arithmetic in ``int64``.
"""

import numpy as np
from lava.magma.core.decorator import implements, requires, tag
from lava.magma.core.model.py.model import PyLoihiProcessModel
from lava.magma.core.model.py.ports import PyInPort, PyOutPort
from lava.magma.core.model.py.type import LavaPyType
from lava.magma.core.resources import CPU
from lava.magma.core.sync.protocols.loihi_protocol import LoihiProtocol

from mappings.lava.processes.models_float import membrane
from mappings.lava.processes.process import CCO, TDE


class _NeuronsFixed(PyLoihiProcessModel):
    s_out: PyOutPort = LavaPyType(PyOutPort.VEC_DENSE, np.int32, precision=1)
    u: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=24)
    v: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=24)
    du: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=12)
    dv: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=12)
    vth: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=24)
    current_shift: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=5)
    refr: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=8)
    refr_left: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=8)
    count: np.ndarray = LavaPyType(np.ndarray, np.int64)
    log: np.ndarray = LavaPyType(np.ndarray, np.int64)
    saturated: np.ndarray = LavaPyType(np.ndarray, np.int64)

    def __init__(self, proc_params) -> None:
        super().__init__(proc_params)
        self.decay_bits = int(proc_params["decay_bits"])
        self.state_max = 2 ** (int(proc_params["state_bits"]) - 1) - 1

    def decay(self, x: np.ndarray, delta: np.ndarray) -> np.ndarray:
        """``(x (2^D - delta)) >> D`` (``x >= 0``: truncation towards zero)."""
        return (x * ((1 << self.decay_bits) - delta)) >> self.decay_bits

    def saturate(self, x: np.ndarray, where=slice(None)) -> np.ndarray:
        """Clip ``x`` (the values of neurons ``where``) at the largest state value, counting
        the clipped neurons."""
        over = x > self.state_max
        self.saturated[where] += over
        return np.where(over, self.state_max, x)

    def candidate(self, drive: np.ndarray) -> np.ndarray:
        """``sat(decay(v) + drive)`` for the neurons outside their refractory period."""
        active = self.refr_left == 0
        v = self.decay(self.v, self.dv) + drive
        v[active] = self.saturate(v[active], active)
        return v


@implements(proc=CCO, protocol=LoihiProtocol)
@requires(CPU)
@tag("fixed_pt")
class PyCcoModelFixed(_NeuronsFixed):
    """CCO step in integers: send the previous step's spikes; ``u = sat(decay(u) + feedback)``;
    membrane ``v = sat(decay(v) + (u + bias) >> current_shift)``."""

    fb_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, np.int32, precision=24)
    bias: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=24)
    s_buff: np.ndarray = LavaPyType(np.ndarray, np.int32, precision=1)

    def run_spk(self) -> None:
        self.s_out.send(self.s_buff)
        self.u[:] = self.saturate(self.decay(self.u, self.du) + self.fb_in.recv())
        self.s_buff[:] = membrane(self, self.candidate((self.u + self.bias) >> self.current_shift))


@implements(proc=TDE, protocol=LoihiProtocol)
@requires(CPU)
@tag("fixed_pt")
class PyTdeModelFixed(_NeuronsFixed):
    """TDE step in integers: gate ``(i_fac * gate) >> gate_shift`` if the CCO fired (``i_fac``
    before this step); ``i_fac = sat(decay(i_fac) + input)``; ``u = sat(decay(u) + gate)``;
    membrane ``v = sat(decay(v) + u >> current_shift)``; send."""

    fac_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, np.int32, precision=24)
    trg_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, np.int32, precision=1)
    i_fac: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=24)
    d_fac: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=12)
    gate: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=31)
    gate_shift: np.ndarray = LavaPyType(np.ndarray, np.int64, precision=6)

    def run_spk(self) -> None:
        fac_in, trigger = self.fac_in.recv().astype(np.int64), self.trg_in.recv() > 0
        jump = np.where(trigger, (self.i_fac * self.gate) >> self.gate_shift, 0)
        self.i_fac[:] = self.saturate(self.decay(self.i_fac, self.d_fac) + fac_in)
        self.u[:] = self.saturate(self.decay(self.u, self.du) + jump)
        self.s_out.send(
            membrane(self, self.candidate(self.u >> self.current_shift)).astype(np.int32)
        )
