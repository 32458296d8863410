"""The control protocol, version 1: commands on bulk EP 0x01, responses on bulk EP 0x81.

A command is a :data:`~mappings.usb.wire.Kind.COMMAND` packet whose payload is::

    0   1   opcode   :class:`Opcode`
    1   3   reserved 0
    4   n   arguments (opcode-specific, below)

and the device answers each with exactly one ``RESPONSE`` packet carrying the command's ``seq``::

    0   1   opcode   echo of the command's opcode
    1   1   status   :class:`Status`
    2   2   reserved 0
    4   n   data (opcode-specific; on an error status, a UTF-8 message)

Opcodes, arguments -> data:

=============  =====================================  ==========================================
opcode         arguments                              data
=============  =====================================  ==========================================
GET_INFO 0x01  none                                   :class:`DeviceInfo` (16 bytes)
RESET 0x02     none                                   none; drops image, run, counters, seqs
LOAD 0x03      a fixed-point image (:mod:`.image`)    none; device is then READY
START 0x04     u32 duration [ticks]                   none; the event streams start at seq 0
STOP 0x05      none                                   none; aborts a run, sends a FINAL packet
COUNTERS 0x06  none                                   :class:`Counters` (32 bytes)
=============  =====================================  ==========================================

A run of duration ``K`` ticks executes the network's time steps 1 .. K: an input event's tick
is the step it is delivered at, an output event's tick the step it was emitted at (both in
1 .. K), and the FINAL packets of a run carry the horizon ``K + 1``.

Device states: IDLE (no image) -> LOAD -> READY -> START -> RUNNING -> (FINAL input packet
processed, or STOP) -> DONE; START again from DONE or READY; RESET -> IDLE from anywhere.
A command not allowed in the current state answers ``BAD_STATE``.
"""

from __future__ import annotations

import struct
from dataclasses import astuple, dataclass, fields
from enum import IntEnum

from .wire import EVENT_DTYPE, EVENT_PREFIX, OVERHEAD, Kind, Packet, WireError, encode_packet

_PREFIX = struct.Struct("<BBH")


class Opcode(IntEnum):
    """Control commands."""

    GET_INFO = 0x01
    RESET = 0x02
    LOAD = 0x03
    START = 0x04
    STOP = 0x05
    COUNTERS = 0x06


class Status(IntEnum):
    """Response status codes."""

    OK = 0
    BAD_PACKET = 1  # the command packet failed to decode (CRC, truncated, ...)
    BAD_STATE = 2  # not allowed in the device's current state
    BAD_IMAGE = 3  # LOAD: the fixed-point image is malformed or too large for the device
    UNKNOWN_OPCODE = 4
    BAD_ARGUMENT = 5


#: START's argument: the run's duration [ticks].
START_ARGS = struct.Struct("<I")


@dataclass(frozen=True)
class DeviceInfo:
    """GET_INFO data (16 bytes, ``<IIHHHH`` in this order).

    Attributes:
        firmware: firmware version (opaque u32).
        max_image: largest fixed-point image LOAD accepts [bytes].
        max_spll: largest network (sPLLs) the device holds.
        max_events: most events one event packet may carry (either direction).
        input_credits: input packets the device buffers; the host may have this many
            unacknowledged input packets in flight (flow control).
        output_buffer: output packets the device buffers before it stops consuming input.
    """

    firmware: int
    max_image: int
    max_spll: int
    max_events: int
    input_credits: int
    output_buffer: int

    FORMAT = struct.Struct("<IIHHHH")

    def pack(self) -> bytes:
        return self.FORMAT.pack(*astuple(self))

    @classmethod
    def unpack(cls, data: bytes) -> DeviceInfo:
        if len(data) != cls.FORMAT.size:
            raise WireError(f"GET_INFO data must be {cls.FORMAT.size} bytes, got {len(data)}")
        return cls(*cls.FORMAT.unpack(data))

    @property
    def max_packet_bytes(self) -> int:
        """Largest event packet [bytes]: what a bulk read must have room for."""
        return OVERHEAD + EVENT_PREFIX.size + EVENT_DTYPE.itemsize * self.max_events


@dataclass(frozen=True)
class Counters:
    """COUNTERS data: eight u32 counts since the last START (32 bytes, ``<8I``).

    Attributes:
        input_events: input events accepted into the network.
        input_packets: input packets accepted.
        input_dropped_events: events in input packets the device rejected (bad CRC, seq gap,
            malformed); unknown-length corrupt packets count 0 here but 1 in ``crc_errors``.
        crc_errors: input or command packets that failed to decode.
        seq_errors: input packets whose seq was not the expected one (lost or repeated).
        output_events: output events put on the wire.
        output_packets: output packets put on the wire.
        horizon: the output stream's horizon: every step below it is simulated
            (``duration + 1`` once a run is complete).
    """

    input_events: int = 0
    input_packets: int = 0
    input_dropped_events: int = 0
    crc_errors: int = 0
    seq_errors: int = 0
    output_events: int = 0
    output_packets: int = 0
    horizon: int = 0

    FORMAT = struct.Struct("<8I")

    def pack(self) -> bytes:
        return self.FORMAT.pack(*(v & 0xFFFFFFFF for v in astuple(self)))

    @classmethod
    def unpack(cls, data: bytes) -> Counters:
        if len(data) != cls.FORMAT.size:
            raise WireError(f"COUNTERS data must be {cls.FORMAT.size} bytes, got {len(data)}")
        return cls(*cls.FORMAT.unpack(data))

    def as_dict(self) -> dict[str, int]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def encode_command(seq: int, opcode: Opcode, args: bytes = b"") -> bytes:
    """A COMMAND packet."""
    return encode_packet(Kind.COMMAND, seq, _PREFIX.pack(int(Opcode(opcode)), 0, 0) + bytes(args))


def decode_command(packet: Packet) -> tuple[int, bytes]:
    """``(opcode, args)`` of a COMMAND packet (the opcode may be unknown: the device answers
    ``UNKNOWN_OPCODE``)."""
    if packet.kind != Kind.COMMAND or len(packet.payload) < _PREFIX.size:
        raise WireError(f"not a command packet ({packet.kind.name}, {len(packet.payload)} bytes)")
    opcode, _, _ = _PREFIX.unpack_from(packet.payload)
    return opcode, packet.payload[_PREFIX.size :]


def encode_response(seq: int, opcode: int, status: Status, data: bytes = b"") -> bytes:
    """A RESPONSE packet answering command ``seq``."""
    return encode_packet(Kind.RESPONSE, seq, _PREFIX.pack(opcode, int(status), 0) + bytes(data))


def decode_response(packet: Packet) -> tuple[int, Status, bytes]:
    """``(opcode, status, data)`` of a RESPONSE packet."""
    if packet.kind != Kind.RESPONSE or len(packet.payload) < _PREFIX.size:
        raise WireError(f"not a response packet ({packet.kind.name}, {len(packet.payload)} bytes)")
    opcode, status, _ = _PREFIX.unpack_from(packet.payload)
    try:
        status = Status(status)
    except ValueError:
        raise WireError(f"response with unknown status {status}") from None
    return opcode, status, packet.payload[_PREFIX.size :]
