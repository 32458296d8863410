"""The USB board as a backend of ``spll_hw.backends`` / ``spll-hw compare`` (``usb``).

``simulate_usb(network, inputs, duration, profile=..., device=...)`` quantizes the network to a
fixed-point chip profile (``quantize``), loads its image on the board, streams the input spikes
as ticks and returns the board's TDE and CCO spikes as a
:class:`~spll_hw.result.SimulationResult`, in seconds (tick ``k`` is time ``k * dt``).

``device``: ``"board"`` uses an attached board (an error if none), ``"emulator"`` the board
emulator on the Rust fixed-point reference, ``"auto"`` (default) the board when pyusb finds
one, else the emulator. A board that is attached but cannot be used (permissions, busy) is an
error in every mode, never a silent fallback.

Spike times follow the model's grid (:mod:`spll_hw.model.grid`), as the fixed-point reference
does: an input spike at time ``t`` is delivered at step ``max(1, ceil(t / dt))`` (one on a
step's end in that step), inputs after the last step are dropped, the run has
``round(duration / dt)`` steps and a spike emitted at step ``k`` is reported at ``k * dt``.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from mappings.fixed_point.backend import FixedPointBackend, fixed_point_profile
from quantize import quantize
from spll_hw.backends.base import Backend, Capabilities, Option, positive_float
from spll_hw.model.grid import n_steps, spike_steps
from spll_hw.network import Network
from spll_hw.result import SimulationResult

from .image import FixedPointCore, FixedPointImage
from .link import (
    DEFAULT_PID,
    DEFAULT_VID,
    DeviceNotFoundError,
    NoUsbBackendError,
    UsbLink,
    UsbLinkError,
)
from .wire import MAX_TICK, Port

DEVICES = ("auto", "board", "emulator")


def run_steps(duration: float, dt: float) -> int:
    """Time steps of a run (the model's :func:`~spll_hw.model.grid.n_steps`), within a tick."""
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be finite and > 0 s, got {duration!r}")
    steps = n_steps(duration, dt)
    if not steps < MAX_TICK:
        raise ValueError(
            f"duration {duration} s at dt = {dt} s is {steps} steps; a run has 1 .. {MAX_TICK - 1}"
        )
    return steps


def input_ticks(times, dt: float, steps: int) -> np.ndarray:
    """Input spike times [s] (sorted, finite, >= 0; shape ``(k,)``) as delivery ticks
    (:func:`spll_hw.model.grid.spike_steps`), int64, keeping those up to ``steps``."""
    t = np.asarray(times, dtype=np.float64).reshape(-1)
    if t.size:
        if not np.all(np.isfinite(t)) or t.min() < 0:
            raise ValueError("input spike times must be finite and >= 0 s")
        back = np.flatnonzero(np.diff(t) < 0)
        if back.size:
            i = int(back[0])
            raise ValueError(f"input spike times must be sorted: {t[i + 1]} after {t[i]} s")
    ticks = spike_steps(t, dt)
    return ticks[ticks <= steps]


def emulator_link(core=None, *, timeout: float = 1.0, **board_options) -> UsbLink:
    """An unopened :class:`UsbLink` to a fresh emulated board (``core``: default
    :class:`FixedPointCore`; ``board_options``: :class:`~mappings.usb.emulator.EmulatedBoard`)."""
    from .emulator import EmulatedBoard, EmulatorBackend  # optional extra: usb (pyusb)

    board = EmulatedBoard(core or FixedPointCore(), **board_options)
    return UsbLink(board.vid, board.pid, backend=EmulatorBackend(board), timeout=timeout)


def open_device(
    device: str = "auto",
    *,
    vid: int = DEFAULT_VID,
    pid: int = DEFAULT_PID,
    serial: str | None = None,
    timeout: float = 1.0,
) -> tuple[UsbLink, str]:
    """An open link and what it is: ``"board"`` or ``"emulator"`` (see the module docstring)."""
    if device not in DEVICES:
        raise ValueError(f"device must be one of {DEVICES}, got {device!r}")
    if device != "emulator":
        link = UsbLink(vid, pid, serial=serial, timeout=timeout)
        try:
            return link.open(), "board"
        except (NoUsbBackendError, DeviceNotFoundError):
            if device == "board":
                raise
    return emulator_link(timeout=timeout).open(), "emulator"


def simulate_usb(
    network: Network,
    inputs,
    duration: float,
    *,
    profile: str = "loihi2",
    device: str = "auto",
    vid: int | str = DEFAULT_VID,
    pid: int | str = DEFAULT_PID,
    serial: str | None = None,
    timeout: float = 1.0,
    strict: bool = True,
) -> SimulationResult:
    """Run one input spike train [s] through ``network`` on the USB board (module docstring).

    Args:
        network: the network; quantized to ``profile`` (a fixed-point ``quantize`` profile).
        inputs: input spike times [s], sorted, shape ``(k,)``.
        duration: run length [s].
        device: ``"auto"``, ``"board"`` or ``"emulator"``.
        vid, pid: the board's USB ids (ints or strings such as ``"0x1209"``).
        serial: pick one of several boards.
        timeout: bound on every USB transfer [s].
        strict: raise :class:`~mappings.usb.link.StreamError` when events were lost.

    Returns:
        ``backend`` ``"usb"`` (a board) or ``"usb-emulator"``; ``info`` holds the profile, the
        time step, the step count, the device and the link statistics.
    """
    q = quantize(network, profile)
    if q.fixed is None:
        raise ValueError(f"profile {q.profile.name!r} is not fixed point: a board needs integers")
    image = FixedPointImage.from_fixed(q.fixed)
    steps = run_steps(duration, image.dt)
    ticks = input_ticks(inputs, image.dt, steps)
    link, kind = open_device(
        device, vid=int(str(vid), 0), pid=int(str(pid), 0), serial=serial, timeout=timeout
    )
    with link:
        link.reset()
        link.load(image.pack())
        run = link.run(ticks, steps, strict=strict)
        name = link.name
    tde = [t * image.dt for t in run.spikes(Port.TDE, image.n_spll)]
    cco = [t * image.dt for t in run.spikes(Port.CCO, image.n_spll)]
    return SimulationResult(
        tde_counts=np.array([len(t) for t in tde], dtype=np.int64),
        cco_counts=np.array([len(t) for t in cco], dtype=np.int64),
        duration=float(duration),
        backend="usb" if kind == "board" else "usb-emulator",
        tde_spikes=tde,
        cco_spikes=cco,
        wall_time=run.wall_time,
        info={
            "profile": q.profile.name,
            "dt": image.dt,
            "n_steps": steps,
            "device": f"{kind} {name}",
            "link": run.stats.summary(),
            "complete": run.stats.complete,
        },
    )


def _usb_id(value: object) -> int:
    """A USB vendor or product id: an integer or a string such as ``"0x1209"``."""
    try:
        number = int(str(value), 0)
    except ValueError:
        raise ValueError(f"a USB id must be an integer such as 0x1209, got {value!r}") from None
    if not 0 <= number <= 0xFFFF:
        raise ValueError(f"a USB id is 16 bits, got {value!r}")
    return number


class _Usb(Backend):
    """A board (or its emulator) behind the USB link, on a fixed-point profile's integers;
    samples run one after the other."""

    extra = "usb"
    requires = ("usb",)
    device: ClassVar[str]
    OPTIONS = {
        "profile": Option("loihi2", "fixed-point chip profile (name or TOML file)",
                          fixed_point_profile),
        "timeout": Option(1.0, "bound on every USB transfer [s]", positive_float("timeout")),
    }  # fmt: skip

    @property
    def capabilities(self) -> Capabilities:
        reference = FixedPointBackend(profile=self.options["profile"]).capabilities
        return Capabilities(
            exact=False, dt=reference.dt, arithmetic="fixed", hardware=self.device == "board",
            rate_tolerance=reference.rate_tolerance,
        )  # fmt: skip

    def realised(self, network: Network) -> Network:
        """The network as the profile's integers realise it (``simulate_usb`` quantizes it)."""
        return FixedPointBackend(profile=self.options["profile"]).realised(network)

    def _link_options(self) -> dict:
        return {}

    def _run(self, prepared, trains, duration, *, threads, record_spikes) -> list[SimulationResult]:
        return [
            simulate_usb(
                prepared, x, duration, profile=str(self.options["profile"]), device=self.device,
                timeout=float(self.options["timeout"]), **self._link_options(),
            )
            for x in trains
        ]  # fmt: skip


class UsbBoard(_Usb):
    name = "usb"
    description = "an sPLL board on USB (pyusb)"
    device = "board"
    OPTIONS = _Usb.OPTIONS | {
        "vid": Option(DEFAULT_VID, "USB vendor id (e.g. 0x1209)", _usb_id),
        "pid": Option(DEFAULT_PID, "USB product id", _usb_id),
        "serial": Option(None, "serial number, to pick one of several boards", str),
    }

    @classmethod
    def unavailable(cls) -> str | None:
        reason = super().unavailable()
        if reason is not None:
            return reason
        try:
            link, _ = open_device("board")
        except UsbLinkError as exc:
            return f"no board: {exc}"
        link.close()
        return None

    def _link_options(self) -> dict:
        return {k: self.options[k] for k in ("vid", "pid", "serial")}


class UsbEmulator(_Usb):
    name = "usb-emulator"
    description = "the sPLL board's emulator behind the USB link (fixed-point reference)"
    device = "emulator"
