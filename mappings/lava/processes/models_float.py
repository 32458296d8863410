"""Floating-point ProcessModels (tag ``floating_pt``) of the CCO and TDE processes.

The algorithm of :mod:`mappings.lava.parameters` with real numbers: the ideal chip.
"""

import numpy as np
from lava.magma.core.decorator import implements, requires, tag
from lava.magma.core.model.py.model import PyLoihiProcessModel
from lava.magma.core.model.py.ports import PyInPort, PyOutPort
from lava.magma.core.model.py.type import LavaPyType
from lava.magma.core.resources import CPU
from lava.magma.core.sync.protocols.loihi_protocol import LoihiProtocol

from mappings.lava.processes.process import CCO, TDE


def membrane(model, candidate: np.ndarray) -> np.ndarray:
    """One membrane step shared by all four models; returns the boolean spike vector ``(N,)``.

    Neurons outside their refractory period take ``v = candidate`` (decayed potential plus
    drive) and spike at ``v > vth`` (reset to 0, refractory counter set, time step logged);
    refractory neurons count down with ``v`` held at 0.
    """
    active = model.refr_left == 0
    model.refr_left[~active] -= 1
    model.v[active] = candidate[active]
    spiked = active & (model.v > model.vth)
    model.v[spiked] = 0
    model.refr_left[spiked] = model.refr[spiked]
    idx = np.flatnonzero(spiked)
    model.log[idx, model.count[idx]] = model.time_step
    model.count[idx] += 1
    return spiked


class _NeuronsFloat(PyLoihiProcessModel):
    s_out: PyOutPort = LavaPyType(PyOutPort.VEC_DENSE, float)
    u: np.ndarray = LavaPyType(np.ndarray, float)
    v: np.ndarray = LavaPyType(np.ndarray, float)
    du: np.ndarray = LavaPyType(np.ndarray, float)
    dv: np.ndarray = LavaPyType(np.ndarray, float)
    vth: np.ndarray = LavaPyType(np.ndarray, float)
    current_shift: np.ndarray = LavaPyType(np.ndarray, int)
    refr: np.ndarray = LavaPyType(np.ndarray, int)
    refr_left: np.ndarray = LavaPyType(np.ndarray, int)
    count: np.ndarray = LavaPyType(np.ndarray, int)
    log: np.ndarray = LavaPyType(np.ndarray, int)
    saturated: np.ndarray = LavaPyType(np.ndarray, int)


@implements(proc=CCO, protocol=LoihiProtocol)
@requires(CPU)
@tag("floating_pt")
class PyCcoModelFloat(_NeuronsFloat):
    """CCO step: send the previous step's spikes; ``u = u (1 - du) + feedback``; membrane with
    drive ``u + bias``."""

    fb_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, float)
    bias: np.ndarray = LavaPyType(np.ndarray, float)
    s_buff: np.ndarray = LavaPyType(np.ndarray, float)

    def run_spk(self) -> None:
        self.s_out.send(self.s_buff)
        self.u[:] = self.u * (1 - self.du) + self.fb_in.recv()
        self.s_buff[:] = membrane(self, self.v * (1 - self.dv) + self.u + self.bias)


@implements(proc=TDE, protocol=LoihiProtocol)
@requires(CPU)
@tag("floating_pt")
class PyTdeModelFloat(_NeuronsFloat):
    """TDE step: gate ``= gate * i_fac`` if the CCO fired (``i_fac`` before this step);
    ``i_fac = i_fac (1 - d_fac) + input``; ``u = u (1 - du) + gate``; membrane with drive
    ``u``; send."""

    fac_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, float)
    trg_in: PyInPort = LavaPyType(PyInPort.VEC_DENSE, float)
    i_fac: np.ndarray = LavaPyType(np.ndarray, float)
    d_fac: np.ndarray = LavaPyType(np.ndarray, float)
    gate: np.ndarray = LavaPyType(np.ndarray, float)
    gate_shift: np.ndarray = LavaPyType(np.ndarray, int)

    def run_spk(self) -> None:
        fac_in, trigger = self.fac_in.recv(), self.trg_in.recv() > 0
        jump = np.where(trigger, self.gate * self.i_fac, 0.0)
        self.i_fac[:] = self.i_fac * (1 - self.d_fac) + fac_in
        self.u[:] = self.u * (1 - self.du) + jump
        self.s_out.send(membrane(self, self.v * (1 - self.dv) + self.u).astype(float))
