"""A board emulator speaking the spll-hw USB protocol, plugged into pyusb as a backend.

:class:`EmulatedBoard` is the device side of :mod:`.protocol` and :mod:`.wire`: a state machine
with a command channel, a bounded input FIFO (``input_credits`` packets, NAKed when full), a
bounded output FIFO (``output_buffer`` packets; a full one stops input consumption) and a
:class:`DeviceCore` that computes the network (:class:`~mappings.usb.image.FixedPointCore`:
the Rust fixed-point reference of ``quantize``). The board answers the input packets it has
consumed when the host reads output and none is queued (or at the run's last packet, STOP or
COUNTERS): one call of the core for all of them, then each packet's output packets, ack and
horizon in turn, the same stream as a core advanced packet by packet. :class:`EmulatorBackend`
implements pyusb's ``usb.backend.IBackend`` over a set of boards, so ::

    dev = usb.core.find(idVendor=0x1209, idProduct=0x0001, backend=EmulatorBackend(board))

returns a real ``usb.core.Device`` whose descriptors, string requests, claims and bulk transfers
go through pyusb's own code paths to the board. Transfers that a real device would leave pending
(nothing to read, a full FIFO, a stalled board) wait out the caller's timeout and raise
``usb.core.USBTimeoutError``, as libusb does; an unplugged board raises ``USBError`` with
``errno.ENODEV``; a board without access rights raises ``errno.EACCES`` on open.

:class:`Faults` makes the board misbehave on purpose: stall, unplug (and come back), drop,
corrupt, truncate or reorder output packets, corrupt input packets, deny access.
"""

from __future__ import annotations

import errno
import time
from array import array
from collections import deque
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from .link import (
    CONFIGURATION,
    DEFAULT_PID,
    DEFAULT_VID,
    EP_COMMAND,
    EP_EVENTS_IN,
    EP_EVENTS_OUT,
    EP_RESPONSE,
    INTERFACE,
    require_pyusb,
)
from .protocol import (
    START_ARGS,
    Counters,
    DeviceInfo,
    Opcode,
    Status,
    decode_command,
    encode_response,
)
from .wire import (
    EVENT_DTYPE,
    EVENT_PREFIX,
    MAX_TICK,
    Kind,
    Port,
    WireError,
    decode_events,
    decode_packet,
    encode_event_packets,
    encode_packet,
)

usb = require_pyusb()

#: libusb's error codes for the errors the emulator raises (as pyusb's libusb1 backend does).
_LIBUSB_ERROR_ACCESS, _LIBUSB_ERROR_NO_DEVICE, _LIBUSB_ERROR_BUSY = -3, -4, -6
_LIBUSB_ERROR_TIMEOUT, _LIBUSB_ERROR_PIPE, _LIBUSB_ERROR_OVERFLOW = -7, -9, -8


class DeviceCore(Protocol):
    """The network computation inside a board.

    ``load`` takes a fixed-point image (raises ``ValueError`` naming what is wrong) and sets
    ``n_spll``; ``start(duration)`` begins a run of time steps 1 .. ``duration``;
    ``advance(ticks, horizon, final)`` takes the input spikes [ticks] (int64, shape ``(k,)``,
    sorted, in previous horizon .. ``duration``) and returns the output events
    (:data:`~mappings.usb.wire.EVENT_DTYPE`, sorted by tick) with previous horizon <= tick <
    ``horizon`` (``horizon`` is ``duration + 1`` when ``final``).
    """

    n_spll: int

    def load(self, image: bytes) -> None: ...

    def start(self, duration: int) -> None: ...

    def advance(self, ticks: np.ndarray, horizon: int, final: bool) -> np.ndarray: ...


@dataclass(frozen=True)
class Faults:
    """Misbehaviour to inject; output-packet numbers are the ``seq`` of the current run.

    Attributes:
        stall_after: deliver this many output packets, then answer nothing at all.
        disconnect_after: deliver this many output packets, then unplug.
        reappear_after: seconds after an unplug until the board enumerates again, fresh from
            power-up (no image); ``None``: it stays away.
        drop: output packets lost on the wire (the host sees a seq gap).
        corrupt: output packets with one payload byte flipped (CRC mismatch).
        truncate: output packets cut 5 bytes short.
        reorder: output packets whose events the firmware sends in reverse order (valid CRC,
            out-of-order timestamps).
        repeat: output packets the wire delivers twice (the copy arrives right after it).
        corrupt_input: input packets (by seq) that arrive with one byte flipped.
        deny_access: opening the board fails with EACCES, as without a udev rule.
    """

    stall_after: int | None = None
    disconnect_after: int | None = None
    reappear_after: float | None = None
    drop: frozenset[int] = frozenset()
    corrupt: frozenset[int] = frozenset()
    truncate: frozenset[int] = frozenset()
    reorder: frozenset[int] = frozenset()
    repeat: frozenset[int] = frozenset()
    corrupt_input: frozenset[int] = frozenset()
    deny_access: bool = False


class _Silent(Exception):
    """The board leaves this transfer pending (NAK): the host's timeout decides."""


class _Gone(Exception):
    """The board is not on the bus."""


class EmulatedBoard:
    """One emulated board: USB identity, protocol state machine, FIFOs, core and faults.

    Args:
        core: the network computation (:class:`DeviceCore`).
        vid, pid, serial: USB identity.
        max_events: events per packet (either direction).
        input_credits: input packets the board buffers.
        output_buffer: output packets the board buffers before it stops consuming input.
        max_spll: largest network it accepts.
        max_image: largest image [bytes].
        faults: misbehaviour to inject.
    """

    FIRMWARE = 0x0001_0000

    def __init__(
        self,
        core: DeviceCore,
        *,
        vid: int = DEFAULT_VID,
        pid: int = DEFAULT_PID,
        serial: str = "SPLLEMU0001",
        max_events: int = 1024,
        input_credits: int = 4,
        output_buffer: int = 8,
        max_spll: int = 1024,
        max_image: int = 1 << 20,
        faults: Faults | None = None,
    ):
        self.core = core
        self.vid, self.pid, self.serial = vid, pid, serial
        self.info = DeviceInfo(
            self.FIRMWARE, max_image, max_spll, max_events, input_credits, output_buffer
        )
        self.faults = faults or Faults()
        self.attached = True
        self.generation = 0  # bumps on every replug: older handles are dead
        self.claimed_by: object | None = None
        self._unplugged_at = 0.0
        self._stalled = False
        self._disconnect_fired = False
        self._power_up()

    # ------------------------------------------------------------------ bus presence
    def _power_up(self) -> None:
        self.state = "IDLE"
        self.loaded = False
        self.responses: deque[bytes] = deque()
        self._clear_run()

    def _clear_run(self) -> None:
        self.counters = Counters()
        self.input_fifo: deque[bytes] = deque()
        self.output_fifo: deque[bytes] = deque()
        self.duration = 0
        self.horizon = 0
        self.in_seq = 0
        self.out_seq = 0
        self.received = 0
        self.consumed = 0
        self.delivered = 0
        # consumed input packets whose output is not yet computed: (ticks, horizon, ack, final)
        self.unemitted: list[tuple[np.ndarray, int, int, bool]] = []
        self.repeated: set[int] = set()  # packets of Faults.repeat already sent twice

    def unplug(self) -> None:
        """Take the board off the bus (every open handle fails with ENODEV)."""
        self.attached = False
        self.claimed_by = None
        self._unplugged_at = time.monotonic()

    def present(self) -> bool:
        """On the bus now? (An unplugged board with ``reappear_after`` comes back in time.)"""
        if not self.attached and self.faults.reappear_after is not None:
            if time.monotonic() - self._unplugged_at >= self.faults.reappear_after:
                self.attached = True
                self.generation += 1
                self._power_up()
        return self.attached

    # ------------------------------------------------------------------ endpoints
    def write(self, endpoint: int, data: bytes) -> int:
        """A bulk OUT transfer; returns bytes taken, raises :class:`_Silent` (NAK)."""
        if self._stalled:
            raise _Silent
        if endpoint == EP_COMMAND:
            response = self._command(data)  # (RESET replaces the response queue)
            self.responses.append(response)
        elif endpoint == EP_EVENTS_OUT:
            if len(self.input_fifo) >= self.info.input_credits:
                raise _Silent  # FIFO full: NAK until the host times out
            if self.received in self.faults.corrupt_input:
                data = _flip(data)
            self.received += 1
            self.input_fifo.append(data)
            self._pump()
        else:
            raise ValueError(f"no OUT endpoint 0x{endpoint:02x}")
        return len(data)

    def read(self, endpoint: int) -> bytes:
        """A bulk IN transfer: the next packet, or :class:`_Silent` when there is none."""
        if self._stalled:
            raise _Silent
        if endpoint == EP_RESPONSE:
            if not self.responses:
                raise _Silent
            return self.responses.popleft()
        if endpoint != EP_EVENTS_IN:
            raise ValueError(f"no IN endpoint 0x{endpoint:02x}")
        while True:
            self._pump()
            f = self.faults
            if f.stall_after is not None and self.delivered >= f.stall_after:
                self._stalled = True
                raise _Silent
            if (
                f.disconnect_after is not None
                and self.delivered >= f.disconnect_after
                and not self._disconnect_fired
            ):
                self._disconnect_fired = True
                self.unplug()
                raise _Gone
            if not self.output_fifo:
                self._flush()
            if not self.output_fifo:
                raise _Silent
            data = self.output_fifo.popleft()
            self._pump()  # room in the output FIFO: the board goes on consuming input
            seq = self.delivered
            self.delivered += 1
            if seq in f.drop:
                continue
            if seq in f.corrupt:
                return _flip(data)
            if seq in f.truncate:
                return data[:-5]
            if seq in f.reorder:
                return _reversed_events(data)
            if seq in f.repeat and seq not in self.repeated:
                self.repeated.add(seq)
                self.output_fifo.appendleft(data)  # the copy comes next
                self.delivered -= 1  # and is not a new packet of the run
            return data

    # ------------------------------------------------------------------ commands
    def _command(self, data: bytes) -> bytes:
        try:
            packet = decode_packet(data)
            opcode, args = decode_command(packet)
        except WireError as exc:
            self.counters = _bump(self.counters, crc_errors=1)
            return encode_response(_seq_of(data), 0, Status.BAD_PACKET, str(exc).encode())
        try:
            status, reply = self._execute(opcode, args)
        except ValueError as exc:
            status, reply = Status.BAD_ARGUMENT, str(exc).encode()
        return encode_response(packet.seq, opcode, status, reply)

    def _execute(self, opcode: int, args: bytes) -> tuple[Status, bytes]:
        if opcode == Opcode.GET_INFO:
            return Status.OK, self.info.pack()
        if opcode == Opcode.COUNTERS:
            self._flush()
            return Status.OK, self.counters.pack()
        if opcode == Opcode.RESET:
            self._power_up()
            return Status.OK, b""
        handler = {Opcode.LOAD: self._load, Opcode.START: self._start, Opcode.STOP: self._stop}
        if opcode in handler:
            return handler[opcode](args)
        return Status.UNKNOWN_OPCODE, f"opcode 0x{opcode:02x}".encode()

    def _load(self, args: bytes) -> tuple[Status, bytes]:
        if self.state == "RUNNING":
            return Status.BAD_STATE, b"LOAD during a run: STOP or RESET first"
        if len(args) > self.info.max_image:
            return Status.BAD_IMAGE, f"image exceeds {self.info.max_image} bytes".encode()
        try:
            self.core.load(args)
        except ValueError as exc:
            self.state, self.loaded = "IDLE", False
            return Status.BAD_IMAGE, str(exc).encode()
        if self.core.n_spll > self.info.max_spll:
            self.state, self.loaded = "IDLE", False
            return Status.BAD_IMAGE, f"{self.core.n_spll} sPLLs > {self.info.max_spll}".encode()
        self.state, self.loaded = "READY", True
        return Status.OK, b""

    def _start(self, args: bytes) -> tuple[Status, bytes]:
        if not self.loaded:
            return Status.BAD_STATE, b"START before LOAD"
        if self.state == "RUNNING":
            return Status.BAD_STATE, b"START during a run"
        if len(args) != START_ARGS.size:
            return Status.BAD_ARGUMENT, b"START takes a u32 duration"
        (duration,) = START_ARGS.unpack(args)
        if not 1 <= duration < MAX_TICK:
            return Status.BAD_ARGUMENT, b"duration must be 1 .. 2**32 - 2 ticks"
        self._clear_run()
        self.duration = duration
        self.core.start(duration)
        self.state = "RUNNING"
        return Status.OK, b""

    def _stop(self, args: bytes) -> tuple[Status, bytes]:
        if self.state != "RUNNING":
            return Status.BAD_STATE, b"STOP without a run"
        self._flush()
        self.input_fifo.clear()
        self._emit(np.zeros(0, EVENT_DTYPE), self.horizon, self.consumed, final=True)
        return Status.OK, b""

    # ------------------------------------------------------------------ streaming
    def _pump(self) -> None:
        """Consume input packets while running and the output FIFO has room (each consumed
        packet whose output is not computed yet holds one place: it makes at least one)."""
        while (
            self.state == "RUNNING"
            and self.input_fifo
            and len(self.output_fifo) + len(self.unemitted) < self.info.output_buffer
        ):
            self._consume(self.input_fifo.popleft())

    def _consume(self, data: bytes) -> None:
        self.consumed += 1
        c = self.counters
        try:
            packet = decode_packet(data)
        except WireError:
            self.counters = _bump(c, crc_errors=1)
            self._defer(np.zeros(0, np.int64), self.horizon, final=False)
            return
        if packet.seq != self.in_seq:
            c = _bump(c, seq_errors=1)
        self.in_seq = (packet.seq + 1) & 0xFFFF
        try:
            if packet.kind != Kind.INPUT_EVENTS:
                raise WireError(f"{packet.kind.name} packet on the input endpoint")
            block = decode_events(packet)
            events = block.events
            if events.size > self.info.max_events:
                raise WireError(f"{events.size} events > {self.info.max_events} per packet")
            if np.any(events["port"] != Port.INPUT) or np.any(events["address"] != 0):
                raise WireError("input events must be port INPUT, address 0")
            if events.size and int(events["tick"][0]) < max(self.horizon, 1):
                raise WireError(f"input tick {int(events['tick'][0])} before the horizon")
            if events.size and int(events["tick"][-1]) > self.duration:
                raise WireError(f"input tick {int(events['tick'][-1])} after the run")
        except WireError:
            n = max(0, (len(packet.payload) - EVENT_PREFIX.size) // EVENT_DTYPE.itemsize)
            self.counters = _bump(c, input_dropped_events=n)
            self._defer(np.zeros(0, np.int64), self.horizon, final=False)
            return
        self.counters = _bump(c, input_events=int(events.size), input_packets=1)
        end = self.duration + 1
        horizon = end if packet.final else min(max(block.horizon, self.horizon), end)
        self.horizon = horizon
        self._defer(events["tick"].astype(np.int64), horizon, packet.final)

    def _defer(self, ticks: np.ndarray, horizon: int, final: bool) -> None:
        """Note a consumed packet's input ticks and the output horizon [ticks] it moves the
        stream to; :meth:`_flush` computes and sends its output later, together with the
        packets consumed after it, in one call of the core (the last packet of a run at once)."""
        self.unemitted.append((ticks, horizon, self.consumed, final))
        if final:
            self._flush()  # the run is over: nothing more to wait for

    def _flush(self) -> None:
        """Advance the core once over every consumed packet not yet answered and queue, for
        each of them in turn, its output packets: the events below its horizon (the last one:
        every event the core returned), its ack and its horizon, as if the core had been
        advanced packet by packet."""
        if not self.unemitted:
            return
        pending, self.unemitted = self.unemitted, []
        ticks = np.concatenate([t for t, _, _, _ in pending])
        _, horizon, _, final = pending[-1]
        outputs = self.core.advance(ticks, horizon, final)
        # each packet's events end at its horizon; the last one sends what remains
        ends = np.r_[
            np.searchsorted(outputs["tick"], [h for _, h, _, _ in pending[:-1]]), outputs.size
        ]
        for (_, horizon, consumed, final), start, end in zip(
            pending, np.r_[0, ends[:-1]], ends, strict=True
        ):
            self._emit(outputs[start:end], horizon, consumed, final)

    def _emit(self, outputs: np.ndarray, horizon: int, consumed: int, final: bool) -> None:
        """Packetize ``outputs`` (at least one packet: it carries the ack and the horizon)
        with the stream's horizon [ticks] and the input packets consumed so far."""
        packets = encode_event_packets(
            Kind.OUTPUT_EVENTS,
            self.out_seq,
            outputs,
            min(horizon, MAX_TICK),
            self.info.max_events,
            ack=consumed & 0xFFFF,
            final=final,
        )
        self.output_fifo.extend(packets)
        self.out_seq = (self.out_seq + len(packets)) & 0xFFFF
        self.counters = _bump(
            self.counters, output_events=int(outputs.size), output_packets=len(packets)
        )
        self.counters = replace(self.counters, horizon=horizon)
        if final:
            self.state = "DONE"


def _bump(c: Counters, **deltas: int) -> Counters:
    values = c.as_dict()
    for key, delta in deltas.items():
        values[key] += delta
    return Counters(**values)


def _flip(data: bytes) -> bytes:
    """One byte of the payload (or of the header when there is none) inverted."""
    b = bytearray(data)
    b[min(len(b) - 5, 12)] ^= 0xFF
    return bytes(b)


def _seq_of(data: bytes) -> int:
    return int.from_bytes(data[4:6], "little") if len(data) >= 6 else 0


def _reversed_events(data: bytes) -> bytes:
    """The packet re-framed (valid CRC) with its events in reverse order: a firmware bug."""
    packet = decode_packet(data)
    prefix = packet.payload[: EVENT_PREFIX.size]
    events = np.frombuffer(packet.payload, EVENT_DTYPE, offset=EVENT_PREFIX.size)[::-1]
    return encode_packet(packet.kind, packet.seq, prefix + events.tobytes(), packet.flags)


# ---------------------------------------------------------------------------------- pyusb
class _Descriptor:
    """A USB descriptor: attributes as pyusb reads them."""

    def __init__(self, **fields):
        self.__dict__.update(fields)


@dataclass
class _Handle:
    board: EmulatedBoard
    generation: int


_ENDPOINTS = (EP_COMMAND, EP_RESPONSE, EP_EVENTS_OUT, EP_EVENTS_IN)


class EmulatorBackend(usb.backend.IBackend):
    """pyusb backend whose bus holds the given :class:`EmulatedBoard` objects.

    Pass it as ``backend=`` to ``usb.core.find`` or to :class:`~mappings.usb.link.UsbLink`.
    Timeouts are honoured in real time (a pending transfer sleeps ``timeout`` ms, then raises
    ``USBTimeoutError``); a timeout of 0, libusb's "forever", is refused on a transfer that
    would never complete.
    """

    def __init__(self, *boards: EmulatedBoard):
        super().__init__()
        self.boards = list(boards)

    # ------------------------------------------------------------------ enumeration
    def enumerate_devices(self):
        return [b for b in self.boards if b.present()]

    def get_device_descriptor(self, dev: EmulatedBoard):
        address = self.boards.index(dev) + 1 + 16 * dev.generation
        return _Descriptor(
            bLength=18, bDescriptorType=1, bcdUSB=0x0200, bDeviceClass=0, bDeviceSubClass=0,
            bDeviceProtocol=0, bMaxPacketSize0=64, idVendor=dev.vid, idProduct=dev.pid,
            bcdDevice=0x0100, iManufacturer=1, iProduct=2, iSerialNumber=3,
            bNumConfigurations=1, address=address, bus=1, port_number=address,
            port_numbers=(address,), speed=3,
        )  # fmt: skip

    def get_configuration_descriptor(self, dev, config):
        if config != 0:
            raise IndexError(f"configuration index {config}")
        return _Descriptor(
            bLength=9, bDescriptorType=2, wTotalLength=9 + 9 + 7 * len(_ENDPOINTS),
            bNumInterfaces=1, bConfigurationValue=CONFIGURATION, iConfiguration=0,
            bmAttributes=0x80, bMaxPower=50, extra_descriptors=[],
        )  # fmt: skip

    def get_interface_descriptor(self, dev, intf, alt, config):
        if (intf, alt, config) != (0, 0, 0):
            raise IndexError(f"interface {intf} alternate setting {alt}")
        return _Descriptor(
            bLength=9, bDescriptorType=4, bInterfaceNumber=INTERFACE, bAlternateSetting=0,
            bNumEndpoints=len(_ENDPOINTS), bInterfaceClass=0xFF, bInterfaceSubClass=0,
            bInterfaceProtocol=0, iInterface=0, extra_descriptors=[],
        )  # fmt: skip

    def get_endpoint_descriptor(self, dev, ep, intf, alt, config):
        self.get_interface_descriptor(dev, intf, alt, config)
        return _Descriptor(
            bLength=7, bDescriptorType=5, bEndpointAddress=_ENDPOINTS[ep], bmAttributes=0x02,
            wMaxPacketSize=512, bInterval=0, bRefresh=0, bSynchAddress=0, extra_descriptors=[],
        )  # fmt: skip

    # ------------------------------------------------------------------ handles
    def open_device(self, dev: EmulatedBoard) -> _Handle:
        if not dev.present():
            raise _usb_error(_LIBUSB_ERROR_NO_DEVICE)
        if dev.faults.deny_access:
            raise _usb_error(_LIBUSB_ERROR_ACCESS)
        return _Handle(dev, dev.generation)

    def close_device(self, dev_handle: _Handle) -> None:
        if dev_handle.board.claimed_by is dev_handle:
            dev_handle.board.claimed_by = None

    def set_configuration(self, dev_handle, config_value):
        self._board(dev_handle)
        if config_value not in (0, CONFIGURATION):
            raise _usb_error(_LIBUSB_ERROR_PIPE)

    def get_configuration(self, dev_handle):
        self._board(dev_handle)
        return CONFIGURATION

    def set_interface_altsetting(self, dev_handle, intf, altsetting):
        self._board(dev_handle)
        if (intf, altsetting) != (INTERFACE, 0):
            raise _usb_error(_LIBUSB_ERROR_PIPE)

    def claim_interface(self, dev_handle, intf):
        board = self._board(dev_handle)
        if board.claimed_by is not None and board.claimed_by is not dev_handle:
            raise _usb_error(_LIBUSB_ERROR_BUSY)
        board.claimed_by = dev_handle

    def release_interface(self, dev_handle, intf):
        board = self._board(dev_handle)
        if board.claimed_by is dev_handle:
            board.claimed_by = None

    def clear_halt(self, dev_handle, ep):
        self._board(dev_handle)

    def reset_device(self, dev_handle):
        self._board(dev_handle)._power_up()

    def is_kernel_driver_active(self, dev_handle, intf):
        self._board(dev_handle)
        return False

    # ------------------------------------------------------------------ transfers
    def bulk_write(self, dev_handle, ep, intf, data, timeout):
        board = self._claimed(dev_handle)
        return self._pending(lambda: board.write(ep, bytes(data)), dev_handle, timeout)

    def bulk_read(self, dev_handle, ep, intf, buff, timeout):
        board = self._claimed(dev_handle)
        packet = self._pending(lambda: board.read(ep), dev_handle, timeout)
        if len(packet) > len(buff):
            raise _usb_error(_LIBUSB_ERROR_OVERFLOW)
        memoryview(buff)[: len(packet)] = packet
        return len(packet)

    def ctrl_transfer(self, dev_handle, bmRequestType, bRequest, wValue, wIndex, data, timeout):
        """Standard GET_DESCRIPTOR(string) only, so ``Device.serial_number`` etc. work;
        any other request stalls the control pipe, as on a board with no such request."""
        board = self._board(dev_handle)
        if (bmRequestType, bRequest, wValue >> 8) != (0x80, 6, 3):
            raise _usb_error(_LIBUSB_ERROR_PIPE)
        index = wValue & 0xFF
        if index == 0:
            body = (0x0409).to_bytes(2, "little")  # LANGID: English (US)
        else:
            strings = {1: "spll-hw", 2: "sPLL board emulator", 3: board.serial}
            if index not in strings:
                raise _usb_error(_LIBUSB_ERROR_PIPE)
            body = strings[index].encode("utf-16-le")
        descriptor = (bytes([2 + len(body), 3]) + body)[: len(data)]
        data[: len(descriptor)] = array("B", descriptor)
        return len(descriptor)

    # ------------------------------------------------------------------ helpers
    def _board(self, dev_handle: _Handle) -> EmulatedBoard:
        board = dev_handle.board
        if not board.present() or board.generation != dev_handle.generation:
            raise _usb_error(_LIBUSB_ERROR_NO_DEVICE)
        return board

    def _claimed(self, dev_handle: _Handle) -> EmulatedBoard:
        board = self._board(dev_handle)
        if board.claimed_by is not dev_handle:
            raise _usb_error(_LIBUSB_ERROR_BUSY)
        return board

    def _pending(self, transfer, dev_handle: _Handle, timeout: int):
        try:
            return transfer()
        except _Gone:
            raise _usb_error(_LIBUSB_ERROR_NO_DEVICE) from None
        except _Silent:
            if timeout <= 0:
                raise RuntimeError(
                    "emulator: a transfer with timeout 0 (libusb: wait forever) on a board "
                    "that will never answer would hang"
                ) from None
            time.sleep(timeout / 1000)
            self._board(dev_handle)
            raise _usb_error(_LIBUSB_ERROR_TIMEOUT) from None


_ERRORS = {
    _LIBUSB_ERROR_ACCESS: (errno.EACCES, "Access denied (insufficient permissions)"),
    _LIBUSB_ERROR_NO_DEVICE: (errno.ENODEV, "No such device (it may have been disconnected)"),
    _LIBUSB_ERROR_BUSY: (errno.EBUSY, "Resource busy"),
    _LIBUSB_ERROR_TIMEOUT: (errno.ETIMEDOUT, "Operation timed out"),
    _LIBUSB_ERROR_PIPE: (errno.EPIPE, "Pipe error"),
    _LIBUSB_ERROR_OVERFLOW: (errno.EOVERFLOW, "Overflow"),
}


def _usb_error(code: int):
    """The exception pyusb's libusb1 backend raises for libusb error ``code``."""
    err, text = _ERRORS[code]
    cls = usb.core.USBTimeoutError if code == _LIBUSB_ERROR_TIMEOUT else usb.core.USBError
    return cls(text, code, err)
