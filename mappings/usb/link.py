"""``UsbLink``: the host side of the board protocol, on pyusb.

One USB configuration (value 1) with one vendor-class interface (number 0) and four bulk
endpoints:

========  =========  ================================================
endpoint  direction  carries
========  =========  ================================================
0x01      OUT        COMMAND packets (:mod:`.protocol`)
0x81      IN         RESPONSE packets, one per command
0x02      OUT        INPUT_EVENTS packets (:mod:`.wire`)
0x82      IN         OUTPUT_EVENTS packets
========  =========  ================================================

Flow control is credit-based: GET_INFO tells how many input packets the device buffers
(``input_credits``); the host never has more unacknowledged input packets in flight, and every
output packet acknowledges the input packets consumed so far (``ack``). A bulk transfer therefore
never blocks on a full device buffer in normal operation; every transfer still carries a bounded
timeout (``timeout`` [s], never 0, which libusb reads as "forever"), so a device that stops
answering is reported after at most ``timeout`` seconds of silence, never a hang.

Linux permissions: a user without access to the device node gets :class:`DevicePermissionError`,
whose message carries :data:`UDEV_RULE`.
"""

from __future__ import annotations

import errno
import time
from dataclasses import dataclass, field

import numpy as np

from .protocol import (
    START_ARGS,
    Counters,
    DeviceInfo,
    Opcode,
    Status,
    decode_response,
    encode_command,
)
from .wire import (
    EVENT_DTYPE,
    MAX_TICK,
    EventBlock,
    Kind,
    Port,
    WireError,
    check_stream_order,
    decode_events,
    decode_packet,
    encode_events,
    make_events,
)

#: pid.codes' test VID:PID (1209:0001); a board shipping this protocol needs its own PID.
DEFAULT_VID = 0x1209
DEFAULT_PID = 0x0001
#: bConfigurationValue and bInterfaceNumber the board exposes.
CONFIGURATION = 1
INTERFACE = 0
#: Bulk endpoint addresses (table in the module docstring).
EP_COMMAND = 0x01
EP_RESPONSE = 0x81
EP_EVENTS_OUT = 0x02
EP_EVENTS_IN = 0x82
#: Largest response (GET_INFO/COUNTERS data or an error message) a command read makes room for.
MAX_RESPONSE_BYTES = 4096

#: udev rule giving logged-in users (and the ``plugdev`` group) access to the board.
UDEV_RULE = (
    'SUBSYSTEM=="usb", ATTRS{{idVendor}}=="{vid:04x}", ATTRS{{idProduct}}=="{pid:04x}", '
    'MODE="0660", GROUP="plugdev", TAG+="uaccess"'
)
UDEV_HOWTO = (
    "put this line in /etc/udev/rules.d/70-spll-hw.rules:\n    {rule}\nthen run "
    "'sudo udevadm control --reload-rules && sudo udevadm trigger' and replug the board"
)


def require_pyusb():
    """Import and return the ``usb`` package, or raise ``ImportError`` naming the extra."""
    try:
        import usb.backend
        import usb.core
        import usb.util
    except ImportError as exc:
        raise ImportError(
            "mappings.usb needs pyusb: pip install -e '.[usb]' (or pip install pyusb)"
        ) from exc
    return usb


# ---------------------------------------------------------------------------------- errors
class UsbLinkError(RuntimeError):
    """Base class of every link failure; ``stats`` is the stream's progress when it has one."""

    def __init__(self, message: str, stats: LinkStats | None = None):
        super().__init__(message if stats is None else f"{message}; {stats.summary()}")
        self.stats = stats


class NoUsbBackendError(UsbLinkError):
    """pyusb found no libusb on this machine."""


class DeviceNotFoundError(UsbLinkError):
    """No board with the requested VID:PID (and serial) is attached."""


class DevicePermissionError(UsbLinkError):
    """The board is attached but this user may not open it (see :data:`UDEV_RULE`)."""


class DeviceBusyError(UsbLinkError):
    """Another program (or another open :class:`UsbLink`) has claimed the interface."""


class DeviceTimeoutError(UsbLinkError):
    """The board stopped answering: no transfer completed within the timeout."""


class DeviceDisconnectedError(UsbLinkError):
    """The board went away (unplugged, reset or powered off)."""


class DeviceError(UsbLinkError):
    """The board answered a command with an error status."""

    def __init__(self, opcode: Opcode, status: Status, detail: str):
        detail = f" ({detail})" if detail else ""
        super().__init__(f"device refused {opcode.name}: {status.name}{detail}")
        self.opcode, self.status = opcode, status


class ProtocolError(UsbLinkError):
    """The board's answer broke the protocol (wrong version, unexpected packet, ...)."""


class StreamError(UsbLinkError):
    """A run finished but events were lost or rejected; ``result`` holds what did arrive."""

    def __init__(self, message: str, result: StreamResult):
        super().__init__(message, result.stats)
        self.result = result


# ---------------------------------------------------------------------------------- results
@dataclass
class LinkStats:
    """Progress and losses of one streamed run; every count is in events unless named packets.

    Attributes:
        input_events: input events the host had to send.
        input_sent: input events written to the board.
        input_consumed: input events in packets the board has acknowledged.
        output_received: output events accepted by the host.
        horizon: ticks up to which the accepted output is complete.
        rejected_packets: output packets the host rejected, each with the reason.
        missing_packets: output packets never seen (gaps in ``seq``).
        misaddressed: output events addressed to an sPLL the network does not have (counted by
            :meth:`StreamResult.spikes`; lost, never silently dropped).
        counters: the board's own counters after the run (``None`` if it could not be asked).
    """

    input_events: int = 0
    input_sent: int = 0
    input_consumed: int = 0
    output_received: int = 0
    horizon: int = 0
    rejected_packets: list[str] = field(default_factory=list)
    missing_packets: int = 0
    misaddressed: int = 0
    counters: Counters | None = None

    @property
    def input_lost(self) -> int | None:
        """Input events sent but not accepted by the board (``None`` without counters)."""
        return None if self.counters is None else self.input_sent - self.counters.input_events

    @property
    def output_lost(self) -> int | None:
        """Output events the board sent that the host did not accept (``None`` w/o counters)."""
        return None if self.counters is None else self.counters.output_events - self.output_received

    @property
    def complete(self) -> bool:
        """Nothing rejected, missing or lost in either direction, and every input sent."""
        return (
            self.counters is not None
            and not self.rejected_packets
            and not self.missing_packets
            and not self.misaddressed
            and self.input_sent == self.input_events
            and self.input_lost == 0
            and self.output_lost == 0
        )

    def summary(self) -> str:
        """One line: what was sent, consumed, received and lost."""
        parts = [
            f"input: {self.input_sent} of {self.input_events} events sent, "
            f"{self.input_consumed} acknowledged",
            f"output: {self.output_received} events received up to tick {self.horizon}",
        ]
        if self.rejected_packets:
            parts.append(
                f"{len(self.rejected_packets)} output packet(s) rejected "
                f"({'; '.join(self.rejected_packets)})"
            )
        if self.missing_packets:
            parts.append(f"{self.missing_packets} output packet(s) missing (seq gap)")
        if self.misaddressed:
            parts.append(f"{self.misaddressed} output event(s) addressed beyond the network (lost)")
        if self.counters is None:
            parts.append("device counters unavailable")
        else:
            c = self.counters
            parts.append(
                f"device accepted {c.input_events} input events ({self.input_lost} lost: "
                f"{c.crc_errors} corrupt packet(s), {c.input_dropped_events} events dropped), "
                f"sent {c.output_events} output events ({self.output_lost} lost)"
            )
        return "; ".join(parts)


@dataclass
class StreamResult:
    """Output of one run on the board.

    Attributes:
        events: accepted output events, :data:`~mappings.usb.wire.EVENT_DTYPE`, shape ``(k,)``,
            in arrival order (ticks non-decreasing).
        duration: the run's length [ticks].
        stats: progress and losses.
        wall_time: seconds from START to the FINAL packet.
    """

    events: np.ndarray
    duration: int
    stats: LinkStats
    wall_time: float

    def spikes(self, port: Port, n_spll: int) -> list[np.ndarray]:
        """Per-sPLL spike ticks of ``port`` (TDE or CCO), a list of ``n_spll`` int64 arrays.

        Raises :class:`StreamError` when events of ``port`` are addressed to sPLL ``n_spll`` or
        beyond (a board whose image does not match the network): they are counted in
        ``stats.misaddressed`` as lost, never dropped in silence."""
        mine = np.flatnonzero(self.events["port"] == port)
        address = self.events["address"][mine]
        beyond = address >= n_spll
        if beyond.any():
            self.stats.misaddressed += int(beyond.sum())
            raise StreamError(
                f"{int(beyond.sum())} {Port(port).name} event(s) addressed to sPLL "
                f"{int(address[beyond].max())} of a {n_spll}-sPLL network (lost): the "
                "board runs another network than the one loaded",
                self,
            )
        order = np.argsort(address, kind="stable")  # each sPLL's ticks keep their order
        bounds = np.cumsum(np.bincount(address, minlength=n_spll))[:-1]
        ticks = self.events["tick"][mine]  # contiguous first: a gather from it is cheaper
        return np.split(ticks[order].astype(np.int64), bounds)


# ---------------------------------------------------------------------------------- the link
class UsbLink:
    """A board speaking the spll-hw AER protocol, found by USB vendor and product id.

    Args:
        vid, pid: USB vendor and product id.
        serial: pick the board with this serial number when several are attached.
        backend: a pyusb backend (``None``: libusb via pyusb's default search; the emulator:
            :class:`mappings.usb.emulator.EmulatorBackend`).
        timeout: bound on every USB transfer and on silence during a run [s], > 0.

    Use as a context manager or call :meth:`open` / :meth:`close`.
    """

    def __init__(
        self,
        vid: int = DEFAULT_VID,
        pid: int = DEFAULT_PID,
        *,
        serial: str | None = None,
        backend=None,
        timeout: float = 1.0,
    ):
        if not (timeout > 0 and np.isfinite(timeout)):
            raise ValueError(f"timeout must be a finite number of seconds > 0, got {timeout!r}")
        self.vid, self.pid, self.serial = int(vid), int(pid), serial
        self.backend = backend
        self.timeout = float(timeout)
        self.device = None
        self.info: DeviceInfo | None = None
        self._cmd_seq = 0
        self._image: bytes | None = None

    # ------------------------------------------------------------------ open / close
    @property
    def _ms(self) -> int:
        return max(1, round(self.timeout * 1000))

    @property
    def name(self) -> str:
        return f"{self.vid:04x}:{self.pid:04x}" + (f" serial {self.serial}" if self.serial else "")

    def open(self) -> UsbLink:
        """Find, configure and claim the board, then check its protocol version (GET_INFO)."""
        usb = require_pyusb()
        match = None if self.serial is None else (lambda d: _serial(d) == self.serial)
        try:
            device = usb.core.find(
                idVendor=self.vid, idProduct=self.pid, backend=self.backend, custom_match=match
            )
        except usb.core.NoBackendError:
            raise NoUsbBackendError(
                "pyusb found no libusb on this machine: install it (Debian/Ubuntu: "
                "'apt-get install libusb-1.0-0') or use the usb-emulator backend"
            ) from None
        except usb.core.USBError as exc:  # reading a serial number opens the device
            raise self._open_error(exc) from exc
        if device is None:
            raise DeviceNotFoundError(
                f"no USB board {self.name} attached (check 'lsusb'; without a board use the "
                "emulator: the usb-emulator backend)"
            )
        try:
            device.set_configuration(CONFIGURATION)
            usb.util.claim_interface(device, INTERFACE)
        except usb.core.USBError as exc:
            usb.util.dispose_resources(device)
            raise self._open_error(exc) from exc
        self.device = device
        self._cmd_seq = 0
        try:
            self.info = DeviceInfo.unpack(self._command(Opcode.GET_INFO))
        except Exception:
            self.close()
            raise
        return self

    def _open_error(self, exc) -> UsbLinkError:
        if exc.errno == errno.EACCES:
            rule = UDEV_RULE.format(vid=self.vid, pid=self.pid)
            return DevicePermissionError(
                f"no permission to open USB board {self.name} ({exc}); "
                + UDEV_HOWTO.format(rule=rule)
            )
        if exc.errno == errno.EBUSY:
            return DeviceBusyError(
                f"USB board {self.name} is claimed by another program or link ({exc})"
            )
        if exc.errno == errno.ENODEV:
            return DeviceDisconnectedError(f"USB board {self.name} went away while opening")
        return UsbLinkError(f"cannot open USB board {self.name}: {exc}")

    def close(self) -> None:
        """Release the interface and the handle (errors of a vanished board are ignored)."""
        if self.device is None:
            return
        usb = require_pyusb()
        try:
            usb.util.release_interface(self.device, INTERFACE)
        except usb.core.USBError:
            pass  # the board may be gone; its handle is closed below all the same
        usb.util.dispose_resources(self.device)
        self.device = None

    def __enter__(self) -> UsbLink:
        return self.open() if self.device is None else self

    def __exit__(self, *exc) -> None:
        self.close()

    def reconnect(self, wait: float = 5.0, poll: float = 0.05) -> UsbLink:
        """Close, wait up to ``wait`` [s] for the board to enumerate again (polling every
        ``poll`` s), reopen it and load the last image again (a replugged board has lost it).

        A board that reappears without access rights is retried too (udev applies its rule a
        moment after enumeration). Raises :class:`DeviceNotFoundError`, or the last
        :class:`DevicePermissionError`, if it is not usable in time."""
        self.close()
        deadline = time.monotonic() + wait
        while True:
            try:
                self.open()
                break
            except DevicePermissionError:
                if time.monotonic() >= deadline:
                    raise
            except (DeviceNotFoundError, DeviceDisconnectedError):
                if time.monotonic() >= deadline:
                    raise DeviceNotFoundError(
                        f"USB board {self.name} did not come back within {wait:g} s"
                    ) from None
            time.sleep(poll)
        if self._image is not None:
            self.reset()
            self.load(self._image)
        return self

    # ------------------------------------------------------------------ transfers
    def _usb_error(self, exc, what: str, stats: LinkStats | None = None) -> UsbLinkError:
        usb = require_pyusb()
        if isinstance(exc, usb.core.USBTimeoutError) or exc.errno == errno.ETIMEDOUT:
            return DeviceTimeoutError(
                f"USB board {self.name} stopped answering: {what} timed out after "
                f"{self.timeout:g} s",
                stats,
            )
        if exc.errno in (errno.ENODEV, errno.ENOENT, errno.ESHUTDOWN):
            return DeviceDisconnectedError(
                f"USB board {self.name} disconnected during {what} ({exc})", stats
            )
        return UsbLinkError(f"USB transfer failed during {what}: {exc}", stats)

    def _write(self, endpoint: int, data: bytes, what: str, stats: LinkStats | None = None):
        usb = require_pyusb()
        if self.device is None:
            raise UsbLinkError(f"link to {self.name} is not open")
        try:
            written = self.device.write(endpoint, data, self._ms)
        except usb.core.USBError as exc:
            raise self._usb_error(exc, what, stats) from exc
        if written != len(data):
            raise UsbLinkError(f"short write during {what}: {written} of {len(data)} bytes", stats)

    def _read(self, endpoint: int, size: int, what: str, stats: LinkStats | None = None) -> bytes:
        usb = require_pyusb()
        if self.device is None:
            raise UsbLinkError(f"link to {self.name} is not open")
        try:
            return bytes(self.device.read(endpoint, size, self._ms))
        except usb.core.USBError as exc:
            raise self._usb_error(exc, what, stats) from exc

    def _command(self, opcode: Opcode, args: bytes = b"", stats: LinkStats | None = None) -> bytes:
        seq = self._cmd_seq
        self._cmd_seq = (seq + 1) & 0xFFFF
        self._write(EP_COMMAND, encode_command(seq, opcode, args), opcode.name, stats)
        raw = self._read(EP_RESPONSE, MAX_RESPONSE_BYTES, f"{opcode.name} response", stats)
        try:
            packet = decode_packet(raw)
            echo, status, data = decode_response(packet)
        except WireError as exc:
            raise ProtocolError(f"bad response to {opcode.name}: {exc}", stats) from exc
        if packet.seq != seq or echo != opcode:
            raise ProtocolError(
                f"response to {opcode.name} (seq {seq}) answers opcode 0x{echo:02x} seq "
                f"{packet.seq}",
                stats,
            )
        if status != Status.OK:
            raise DeviceError(opcode, status, data.decode("utf-8", "replace"))
        return data

    # ------------------------------------------------------------------ control commands
    def reset(self) -> None:
        """RESET: the board drops its image, run and counters."""
        self._command(Opcode.RESET)

    def load(self, image: bytes) -> None:
        """LOAD a fixed-point image (:mod:`mappings.usb.image`); kept for :meth:`reconnect`."""
        image = bytes(image)
        if self.info is not None and len(image) > self.info.max_image:
            raise ValueError(
                f"image of {len(image)} bytes exceeds the board's {self.info.max_image}-byte limit"
            )
        self._command(Opcode.LOAD, image)
        self._image = image

    def start(self, duration: int) -> None:
        """START a run of ``duration`` ticks."""
        self._command(Opcode.START, START_ARGS.pack(duration))

    def stop(self) -> None:
        """STOP (abort) the current run."""
        self._command(Opcode.STOP)

    def counters(self, stats: LinkStats | None = None) -> Counters:
        """Read the board's :class:`~mappings.usb.protocol.Counters`."""
        return Counters.unpack(self._command(Opcode.COUNTERS, stats=stats))

    # ------------------------------------------------------------------ streaming
    def run(self, ticks, duration: int, *, strict: bool = True) -> StreamResult:
        """Stream one input spike train through the loaded network and collect its output.

        Args:
            ticks: input spikes [ticks: the time step each is delivered at], int, shape
                ``(k,)``, non-decreasing, each in ``1 .. duration``; a repeated tick is several
                spikes in one time step.
            duration: run length [ticks = time steps], 1 .. 2**32 - 2.
            strict: raise :class:`StreamError` (carrying the partial result) when any event was
                lost or rejected; otherwise return the result and let ``stats`` tell.

        Raises :class:`DeviceTimeoutError` or :class:`DeviceDisconnectedError` (with the
        progress so far) when the board goes silent or away.
        """
        if self.device is None or self.info is None:
            raise UsbLinkError(f"link to {self.name} is not open")
        ticks = _check_ticks(ticks, duration)
        packets = _split(ticks, duration, self.info.max_events)
        stats = LinkStats(input_events=int(ticks.size))
        self.start(duration)
        started = time.perf_counter()
        received: list[np.ndarray] = []
        sent: list[int] = [0]  # input events in packets 0 .. i-1, for ack (packets) -> events
        acked = 0  # input packets acknowledged
        expected_seq = 0
        rejected = 0  # output packets rejected since the last accepted one
        last_tick = 0
        while True:
            n_sent = len(sent) - 1
            if n_sent < len(packets) and n_sent - acked < self.info.input_credits:
                chunk, horizon, final = packets[n_sent]
                data = encode_events(
                    Kind.INPUT_EVENTS, n_sent & 0xFFFF, chunk, horizon, final=final
                )
                self._write(EP_EVENTS_OUT, data, f"input packet {n_sent}", stats)
                sent.append(sent[-1] + int(chunk.size))
                stats.input_sent += int(chunk.size)
                continue
            try:
                raw = self._read(EP_EVENTS_IN, self.info.max_packet_bytes, "output read", stats)
            except DeviceTimeoutError:
                if self._finished_without_final(stats, duration):
                    break
                raise
            try:
                packet = decode_packet(raw)
                if packet.kind != Kind.OUTPUT_EVENTS:
                    raise WireError(f"expected an OUTPUT_EVENTS packet, got {packet.kind.name}")
                if (packet.seq - expected_seq) & 0xFFFF >= 0x8000:  # behind: repeated or late
                    last = (expected_seq - 1) & 0xFFFF
                    stats.rejected_packets.append(
                        f"output packet seq {packet.seq} arrived after seq {last} (a repeated or "
                        "reordered packet; its events were not counted twice)"
                    )
                    continue  # no gap to explain: not counted in `rejected`
                block = decode_events(packet)
                _check_within_run(block, duration, f"output packet {packet.seq}")
                last_tick = check_stream_order(block, last_tick, f"output packet {packet.seq}")
            except WireError as exc:
                stats.rejected_packets.append(str(exc))
                rejected += 1
                continue
            # a seq gap not explained by the packets rejected since the last good one
            gap = (packet.seq - expected_seq) & 0xFFFF
            stats.missing_packets += max(0, gap - rejected)
            rejected = 0
            expected_seq = (packet.seq + 1) & 0xFFFF
            acked += (block.ack - acked) & 0xFFFF
            acked = min(acked, len(sent) - 1)
            stats.input_consumed = sent[acked]
            received.append(block.events)
            stats.output_received += int(block.events.size)
            stats.horizon = block.horizon
            if packet.final:
                stats.counters = self.counters(stats)
                break
        # joined as bytes (np.concatenate promotes structured dtypes pair by pair, in Python),
        # into a bytearray: one copy, and the array over it is writable
        events = np.frombuffer(bytearray().join(received), EVENT_DTYPE)
        result = StreamResult(events, int(duration), stats, time.perf_counter() - started)
        if strict and not stats.complete:
            raise StreamError(f"run on USB board {self.name} lost events", result)
        return result

    def _finished_without_final(self, stats: LinkStats, duration: int) -> bool:
        """After a silent read: ask the board whether it finished and only its FINAL packet
        was lost (then record its counters and return True); False otherwise."""
        try:
            counters = self.counters(stats)
        except DeviceTimeoutError:
            return False
        if counters.horizon > duration:
            stats.counters = counters
            stats.rejected_packets.append("FINAL packet never arrived")
            return True
        return False


def _serial(device) -> str | None:
    """The board's serial number, ``None`` if it cannot be read; a board this user may not
    open raises the ``USBError`` (EACCES), which pyusb's ``serial_number`` would hide."""
    usb = require_pyusb()
    try:
        return device.serial_number
    except ValueError:  # pyusb: "no langid", after swallowing the USBError that caused it
        try:
            usb.util.get_langids(device)
        except usb.core.USBError as exc:
            if exc.errno == errno.EACCES:
                raise
        return None


def _check_ticks(ticks, duration: int) -> np.ndarray:
    if not (isinstance(duration, int | np.integer) and 1 <= duration < MAX_TICK):
        raise ValueError(f"duration must be an integer number of ticks in 1..{MAX_TICK - 1}")
    t = np.asarray(ticks)
    if t.ndim != 1 or (t.size and not np.issubdtype(t.dtype, np.integer)):
        raise ValueError(f"input ticks must be a 1-D integer array, got {t.dtype} {t.shape}")
    t = t.astype(np.int64)
    if t.size:
        back = np.flatnonzero(np.diff(t) < 0)
        if back.size:
            i = int(back[0])
            raise ValueError(f"input ticks out of order: tick {t[i + 1]} after {t[i]} (index {i})")
        if t[0] < 1 or t[-1] > duration:
            raise ValueError(f"input ticks must lie in 1..{duration}; got {t[0]}..{t[-1]}")
    return t


def _check_within_run(block: EventBlock, duration: int, where: str) -> None:
    """:class:`WireError` for an output packet with a tick after the run's last step
    (``duration``) or a horizon past its end (``duration + 1``): a board fault that would
    otherwise be kept as a spike and make every later (good) packet look out of order."""
    if block.events.size and int(block.events["tick"][-1]) > duration:
        raise WireError(
            f"{where}: tick {int(block.events['tick'][-1])} is beyond the run of {duration} "
            "ticks (packet rejected)"
        )
    if block.horizon > duration + 1:
        raise WireError(
            f"{where}: horizon {block.horizon} is beyond the end of the run of {duration} ticks "
            "(packet rejected)"
        )


def _split(ticks: np.ndarray, duration: int, max_events: int) -> list[tuple[np.ndarray, int, bool]]:
    """Input packets ``(events, horizon, final)`` of at most ``max_events`` events; a packet's
    horizon is the next packet's first tick (the last one's is ``duration + 1``)."""
    starts = range(0, max(ticks.size, 1), max_events)
    events = make_events(ticks, 0, Port.INPUT)
    out = []
    for n, start in enumerate(starts):
        final = n == len(starts) - 1
        horizon = duration + 1 if final else int(ticks[start + max_events])
        out.append((events[start : start + max_events], horizon, final))
    return out


__all__ = [
    "DEFAULT_PID",
    "DEFAULT_VID",
    "UDEV_RULE",
    "DeviceBusyError",
    "DeviceDisconnectedError",
    "DeviceError",
    "DeviceNotFoundError",
    "DevicePermissionError",
    "DeviceTimeoutError",
    "LinkStats",
    "NoUsbBackendError",
    "ProtocolError",
    "StreamError",
    "StreamResult",
    "UsbLink",
    "UsbLinkError",
]
