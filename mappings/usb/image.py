"""The fixed-point image LOAD carries, and the board core that runs it.

Image version 1 (little-endian, ``20 + 4 * P * N`` bytes, ``P = len(FIXED_PARAM_NAMES)``,
16 today)::

    offset  size    field
    0       4       magic       b"SPIM"
    4       2       version     1 (:data:`IMAGE_VERSION`)
    6       2       n_spll      u16, N
    8       1       n_params    P, the columns below
    9       1       state_bits  width of a state word, sign included (2 .. 32)
    10      1       decay_bits  width of a decay constant (1 .. 30)
    11      1       reserved    0
    12      8       dt          float64 [s]: the time step, i.e. the length of one tick
    20      4 P N   params      u32, sPLL-major (N rows of P), ``FIXED_PARAM_NAMES`` order

The P integers per sPLL are the discrete-time fixed-point parameters of ``quantize`` (decay
constants, weights, current shifts, bias, refractory periods [steps], thresholds, trigger
mantissa and shift; ``quantize.FIXED_PARAM_NAMES``, ``engine/src/fixed_point.rs``), every one
of them non-negative and below 2**32. A board refuses an image whose P is not its own. The board
interprets the time step only as the length of a tick; the integer dynamics do not depend on it.

:class:`FixedPointCore` is the emulator's :class:`~mappings.usb.emulator.DeviceCore`: it runs an
image on the Rust fixed-point reference, bit for bit what the ``golden-fixed-point`` backend
computes for the same network.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from quantize import FIXED_PARAM_NAMES, FixedPointNetwork
from spll_hw import _engine

from .wire import EVENT_DTYPE, Port

IMAGE_MAGIC = b"SPIM"
IMAGE_VERSION = 1
IMAGE_HEADER = struct.Struct("<4sHHBBBBd")


@dataclass(frozen=True)
class FixedPointImage:
    """A quantized network as the board stores it.

    Attributes:
        params: integer parameters, shape ``(N, P)``, int64, ``quantize.FIXED_PARAM_NAMES``
            columns.
        state_bits: state word width [bits], sign included.
        decay_bits: decay constant width [bits].
        dt: time step = one tick [s].
    """

    params: np.ndarray
    state_bits: int
    decay_bits: int
    dt: float

    def __post_init__(self) -> None:
        params = np.asarray(self.params)
        if params.ndim != 2 or params.shape[1] != len(FIXED_PARAM_NAMES):
            raise ValueError(
                f"fixed-point parameters must have shape (N, {len(FIXED_PARAM_NAMES)}), "
                f"got {params.shape}"
            )
        if not 1 <= params.shape[0] <= 0xFFFF:
            raise ValueError(f"an image holds 1 .. 65535 sPLLs, got {params.shape[0]}")
        if not np.issubdtype(params.dtype, np.integer):
            raise ValueError(f"fixed-point parameters must be integers, got {params.dtype}")
        bad = np.argwhere((params < 0) | (params > 0xFFFFFFFF))
        if bad.size:
            i, j = bad[0]
            raise ValueError(
                f"sPLL {i}: {FIXED_PARAM_NAMES[j]} = {params[i, j]} does not fit the image's "
                "unsigned 32-bit field"
            )
        if not (2 <= self.state_bits <= 32 and 1 <= self.decay_bits <= 30):
            raise ValueError(
                f"state_bits must be 2..32 and decay_bits 1..30, got {self.state_bits}, "
                f"{self.decay_bits}"
            )
        if not (np.isfinite(self.dt) and self.dt > 0):
            raise ValueError(f"time step dt must be finite and > 0 s, got {self.dt!r}")
        params = params.astype(np.int64)
        params.setflags(write=False)
        object.__setattr__(self, "params", params)

    @classmethod
    def from_fixed(cls, fixed: FixedPointNetwork) -> FixedPointImage:
        """The image of ``quantize(network, profile).fixed``."""
        return cls(fixed.matrix, fixed.state_bits, fixed.decay_bits, fixed.dt)

    @property
    def n_spll(self) -> int:
        return int(self.params.shape[0])

    def pack(self) -> bytes:
        """The image bytes (module docstring)."""
        head = IMAGE_HEADER.pack(
            IMAGE_MAGIC,
            IMAGE_VERSION,
            self.n_spll,
            len(FIXED_PARAM_NAMES),
            self.state_bits,
            self.decay_bits,
            0,
            float(self.dt),
        )
        return head + self.params.astype("<u4").tobytes()

    @classmethod
    def unpack(cls, data: bytes) -> FixedPointImage:
        """Parse image bytes; ``ValueError`` names what is wrong."""
        data = bytes(data)
        if len(data) < IMAGE_HEADER.size:
            raise ValueError(f"image of {len(data)} bytes is shorter than its header")
        magic, version, n, n_params, state_bits, decay_bits, reserved, dt = (
            IMAGE_HEADER.unpack_from(data)
        )
        if magic != IMAGE_MAGIC:
            raise ValueError(f"not a fixed-point image (magic {magic!r})")
        if version != IMAGE_VERSION:
            raise ValueError(f"unsupported image version {version} (this reads {IMAGE_VERSION})")
        if n_params != len(FIXED_PARAM_NAMES) or reserved:
            raise ValueError(
                f"image declares {n_params} parameters per sPLL, this board runs "
                f"{len(FIXED_PARAM_NAMES)}"
            )
        expected = IMAGE_HEADER.size + 4 * n_params * n
        if len(data) != expected:
            raise ValueError(f"image of {len(data)} bytes, its header declares {expected}")
        params = np.frombuffer(data, "<u4", offset=IMAGE_HEADER.size).reshape(n, n_params)
        return cls(params.astype(np.int64), state_bits, decay_bits, dt)


class FixedPointCore:
    """The emulator's network computation: an image on the Rust fixed-point reference.

    The reference takes input times [s]; the core feeds it ticks as times with a unit time step
    (``max(1, ceil(k / 1)) = k`` exactly, spikes come back at ``k * 1``), so no rounding
    enters. Each :meth:`advance` runs only the steps from the previous horizon to the new one,
    resumed from the integer state the previous call ended in (the reference's ``state`` /
    ``start_step``), with the inputs that arrive in them; inputs at or past the new horizon
    wait for a later call. Joined, the pieces are the whole run bit for bit, so a run costs
    what one call of the reference over the whole train costs, plus the overhead of one call
    per batch of input packets the emulator answers together.

    Attributes:
        n_spll: sPLLs of the loaded image (0 before LOAD).
    """

    n_spll = 0

    def load(self, image: bytes) -> None:
        """Parse and keep ``image`` (``ValueError`` for a malformed one)."""
        self.image = FixedPointImage.unpack(image)
        self.n_spll = self.image.n_spll

    def start(self, duration: int) -> None:
        """Begin a run of steps 1 .. ``duration``."""
        self.duration = duration
        self.step = 0  # steps run so far
        self.state: np.ndarray | None = None  # (1, n_spll, 9) int64 after step `self.step`
        self.pending = np.zeros(0, np.int64)  # input ticks after `self.step`, not yet run

    def advance(self, ticks: np.ndarray, horizon: int, final: bool) -> np.ndarray:
        """Output events with previous horizon <= tick < ``horizon`` (class docstring)."""
        self.pending = np.concatenate([self.pending, np.asarray(ticks, dtype=np.int64)])
        steps = horizon - 1
        if steps <= self.step:
            return np.zeros(0, EVENT_DTYPE)
        now = np.searchsorted(self.pending, steps, side="right")
        inputs, self.pending = self.pending[:now], self.pending[now:]
        out = _engine.simulate_fixed_point(
            np.ascontiguousarray(self.image.params),
            [inputs.astype(np.float64)],
            1.0,
            float(steps),
            self.image.state_bits,
            self.image.decay_bits,
            True,
            state=self.state,
            start_step=self.step,
        )
        first, self.step, self.state = self.step + 1, steps, out["state"]
        return spike_events(out["tde_spikes"][0], out["cco_spikes"][0], first)


def spike_events(tde: list[np.ndarray], cco: list[np.ndarray], start: int) -> np.ndarray:
    """Output events from per-sPLL spike ticks (float or int), keeping ticks >= ``start``,
    sorted by tick, then port (TDE before CCO), then sPLL: shape ``(k,)`` of
    :data:`~mappings.usb.wire.EVENT_DTYPE`."""
    trains = [*tde, *cco]
    lengths = [len(t) for t in trains]
    ticks = np.rint(np.concatenate([np.zeros(0), *trains])).astype(np.int64)
    address = np.repeat([*range(len(tde)), *range(len(cco))], lengths)
    port = np.repeat([int(Port.TDE)] * len(tde) + [int(Port.CCO)] * len(cco), lengths)
    keep = ticks >= start
    ticks, address, port = ticks[keep], address[keep], port[keep]
    # one int64 sort key, tick | port | address (a tick is below 2**32): a lexsort's order
    order = np.argsort((ticks << 24) | (port << 16) | address)
    events = np.zeros(ticks.size, EVENT_DTYPE)
    events["tick"], events["address"], events["port"] = ticks[order], address[order], port[order]
    return events
