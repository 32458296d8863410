"""The AER wire format, version 1: framed, checksummed bulk-transfer packets of timestamped events.

Every bulk transfer carries exactly one packet. All integers are little-endian.

Packet (16 + ``length`` bytes)::

    offset  size  field
    0       2     magic    b"SP" (0x53 0x50)
    2       1     version  1 (:data:`VERSION`)
    3       1     kind     :class:`Kind` (input events, output events, command, response)
    4       2     seq      u16 packet counter of this stream, 0 after START (events) or after
                           open/RESET (commands), wrapping at 65536
    6       2     flags    u16 bit field, bit 0 FINAL (last packet of a run); other bits 0
    8       4     length   u32 payload length [bytes]
    12      n     payload
    12 + n  4     crc      CRC-32 (IEEE 802.3, as :func:`zlib.crc32`) of bytes [0, 12 + n)

Event-packet payload (kinds ``INPUT_EVENTS`` and ``OUTPUT_EVENTS``; ``8 + 8k`` bytes)::

    0       4     horizon  u32 ticks: every event of this stream with tick < horizon is in
                           this or an earlier packet (device -> host: and the device has
                           simulated every tick below horizon); non-decreasing along a stream
    4       2     ack      u16: device -> host, input packets consumed since START (mod 65536),
                           which returns flow-control credits; host -> device 0
    6       2     reserved 0
    8       8k    events   k events of :data:`EVENT_DTYPE`, ticks non-decreasing

Event (8 bytes)::

    0       4     tick     u32 time in device ticks (the loaded network's time step) since START
    4       2     address  u16 input channel (port INPUT, always 0 in v1) or sPLL index
    6       1     port     :class:`Port`: 0 input (facilitatory synapse of every sPLL),
                           1 TDE spike, 2 CCO spike
    7       1     reserved 0

Decoding checks, in this order, and raises :class:`WireError` naming the first failure: at least
16 bytes, magic, version, declared length against the bytes received (truncated or overlong),
CRC, known kind; for event packets also the payload size, reserved bytes, ports and
non-decreasing ticks. Across packets, a receiver checks that ticks never go below the previous
packet's horizon or last tick (:func:`check_stream_order`). Nothing here needs pyusb.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from enum import IntEnum, IntFlag

import numpy as np

#: First two bytes of every packet.
MAGIC = b"SP"
#: Wire-format version this module reads and writes.
VERSION = 1
#: Header layout: magic, version, kind, seq, flags, payload length.
HEADER = struct.Struct("<2sBBHHI")
#: CRC-32 trailer.
TRAILER = struct.Struct("<I")
#: Bytes of framing around a payload (header + CRC).
OVERHEAD = HEADER.size + TRAILER.size
#: Event-payload prefix: horizon, ack, reserved.
EVENT_PREFIX = struct.Struct("<IHH")
#: One address event on the wire (8 bytes).
EVENT_DTYPE = np.dtype([("tick", "<u4"), ("address", "<u2"), ("port", "u1"), ("reserved", "u1")])
#: Largest tick a u32 timestamp holds.
MAX_TICK = 2**32 - 1


class Kind(IntEnum):
    """Packet kinds (header byte 3)."""

    INPUT_EVENTS = 0x01
    OUTPUT_EVENTS = 0x02
    COMMAND = 0x10
    RESPONSE = 0x11


class Flags(IntFlag):
    """Header flag bits."""

    NONE = 0
    FINAL = 0x0001


class Port(IntEnum):
    """Event ports (event byte 6)."""

    INPUT = 0
    TDE = 1
    CCO = 2


#: Kinds and the common header flags by value: a dict look-up per packet, not an enum call.
_KINDS = {int(k): k for k in Kind}
_FLAGS = {int(f): f for f in (Flags.NONE, Flags.FINAL)}
_FINAL = int(Flags.FINAL)


class WireError(ValueError):
    """A packet that cannot be decoded: truncated, corrupt (CRC), wrong version or malformed."""


@dataclass(frozen=True)
class Packet:
    """One framed packet.

    Attributes:
        kind: what the payload holds.
        seq: u16 stream counter.
        flags: header flags.
        payload: the payload bytes.
    """

    kind: Kind
    seq: int
    flags: Flags
    payload: bytes

    @property
    def final(self) -> bool:
        return bool(int(self.flags) & _FINAL)  # (an int test: IntFlag's & is slow)


@dataclass(frozen=True)
class EventBlock:
    """Decoded event-packet payload.

    Attributes:
        horizon: ticks; every event of the stream with tick < horizon has been sent.
        ack: input packets the device has consumed since START (mod 65536); 0 from the host.
        events: structured array of :data:`EVENT_DTYPE`, shape ``(k,)``.
    """

    horizon: int
    ack: int
    events: np.ndarray


def encode_packet(kind: Kind, seq: int, payload: bytes = b"", flags: Flags = Flags.NONE) -> bytes:
    """Frame ``payload`` as one packet: header, payload, CRC-32 (see the module docstring)."""
    if not 0 <= seq <= 0xFFFF:
        raise ValueError(f"packet seq must be a u16 (0..65535), got {seq}")
    code = int(kind) if kind in _KINDS else int(Kind(kind))  # (Kind names a bad one)
    head = HEADER.pack(MAGIC, VERSION, code, seq, int(flags), len(payload))
    body = head + bytes(payload)
    return body + TRAILER.pack(zlib.crc32(body))


def decode_packet(data: bytes) -> Packet:
    """Parse one packet; :class:`WireError` says what is wrong (truncated, CRC, version, ...)."""
    data = bytes(data)
    if len(data) < OVERHEAD:
        raise WireError(f"truncated packet: {len(data)} bytes, a packet has at least {OVERHEAD}")
    magic, version, kind, seq, flags, length = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise WireError(f"bad magic {magic!r} (expected {MAGIC!r}): not an spll-hw AER packet")
    if version != VERSION:
        raise WireError(f"unsupported wire-format version {version} (this host speaks {VERSION})")
    if len(data) != OVERHEAD + length:
        what = "truncated" if len(data) < OVERHEAD + length else "overlong"
        raise WireError(
            f"{what} packet: header declares a {length}-byte payload ({OVERHEAD + length} bytes "
            f"in all), received {len(data)} bytes"
        )
    (crc,) = TRAILER.unpack_from(data, HEADER.size + length)
    actual = zlib.crc32(data[: HEADER.size + length])
    if crc != actual:
        raise WireError(f"corrupt packet seq {seq}: CRC 0x{actual:08x} != trailer 0x{crc:08x}")
    if kind not in _KINDS:
        raise WireError(f"unknown packet kind 0x{kind:02x} (seq {seq})")
    flags = _FLAGS[flags] if flags in _FLAGS else Flags(flags)
    return Packet(_KINDS[kind], seq, flags, data[HEADER.size : HEADER.size + length])


def make_events(ticks, addresses, ports) -> np.ndarray:
    """Events ``(k,)`` of :data:`EVENT_DTYPE` from broadcastable ticks, addresses and ports."""
    ticks, addresses, ports = np.broadcast_arrays(
        np.atleast_1d(np.asarray(ticks, dtype=np.int64)),
        np.asarray(addresses, dtype=np.int64),
        np.asarray(ports, dtype=np.int64),
    )
    for name, values, top in (
        ("tick", ticks, MAX_TICK),
        ("address", addresses, 0xFFFF),
        ("port", ports, 0xFF),
    ):
        if values.size and (values.min() < 0 or values.max() > top):
            raise ValueError(f"event {name} out of range 0..{top}: {values.min()}..{values.max()}")
    events = np.zeros(ticks.shape, dtype=EVENT_DTYPE)
    events["tick"], events["address"], events["port"] = ticks, addresses, ports
    return events


def encode_events(
    kind: Kind,
    seq: int,
    events: np.ndarray,
    horizon: int,
    ack: int = 0,
    final: bool = False,
) -> bytes:
    """One event packet (module docstring); ``events`` ``(k,)`` of :data:`EVENT_DTYPE`,
    ``horizon`` [ticks]. Raises ``ValueError`` for timestamps out of order."""
    events = np.asarray(events, dtype=EVENT_DTYPE)
    (packet,) = encode_event_packets(kind, seq, events, horizon, max(events.size, 1), ack, final)
    return packet


def encode_event_packets(
    kind: Kind,
    seq: int,
    events: np.ndarray,
    horizon: int,
    max_events: int,
    ack: int = 0,
    final: bool = False,
) -> list[bytes]:
    """``events`` ``(k,)`` of :data:`EVENT_DTYPE` as consecutive event packets of at most
    ``max_events`` events each (at least one packet), numbered ``seq``, ``seq + 1``, ... (mod
    65536). A packet's horizon [ticks] is the next packet's first tick, the last one's
    ``horizon``; all carry ``ack``, the last one FINAL when ``final``. The events are checked
    once, as a whole (``ValueError`` for timestamps out of order), not packet by packet."""
    if kind not in (Kind.INPUT_EVENTS, Kind.OUTPUT_EVENTS):
        raise ValueError(f"{Kind(kind).name} is not an event-packet kind")
    raw = np.asarray(events, dtype=EVENT_DTYPE).tobytes()
    words = np.frombuffer(raw, "<u4")
    _check_events(words, horizon, (kind, seq), ValueError)
    if not 0 <= ack <= 0xFFFF:
        raise ValueError(f"ack must be a u16, got {ack}")
    ticks, size, n_events = words[0::2], EVENT_DTYPE.itemsize, words.size // 2
    starts = range(0, max(n_events, 1), max_events)
    packets = []
    for i, start in enumerate(starts):
        stop = start + max_events
        last = stop >= n_events
        payload = EVENT_PREFIX.pack(horizon if last else int(ticks[stop]), ack, 0)
        payload += raw[start * size : stop * size]
        flags = Flags.FINAL if final and last else Flags.NONE
        packets.append(encode_packet(kind, (seq + i) & 0xFFFF, payload, flags))
    return packets


def decode_events(packet: Packet) -> EventBlock:
    """Events of an event packet; :class:`WireError` for a malformed or out-of-order payload."""
    if packet.kind not in (Kind.INPUT_EVENTS, Kind.OUTPUT_EVENTS):
        raise WireError(f"{_packet_name((packet.kind, packet.seq))} is not an event packet")
    size = len(packet.payload) - EVENT_PREFIX.size
    if size < 0 or size % EVENT_DTYPE.itemsize:
        raise WireError(
            f"{_packet_name((packet.kind, packet.seq))}: event payload of "
            f"{len(packet.payload)} bytes is not {EVENT_PREFIX.size} + {EVENT_DTYPE.itemsize}*k"
        )
    horizon, ack, reserved = EVENT_PREFIX.unpack_from(packet.payload)
    if reserved:
        raise WireError(
            f"{_packet_name((packet.kind, packet.seq))}: reserved payload bytes are "
            f"0x{reserved:04x}, must be 0"
        )
    words = np.frombuffer(packet.payload, "<u4", offset=EVENT_PREFIX.size)
    _check_events(words, horizon, (packet.kind, packet.seq), WireError)
    # a read-only view of the payload (bytes): the link joins the packets' events into one array
    events = np.frombuffer(packet.payload, EVENT_DTYPE, offset=EVENT_PREFIX.size)
    return EventBlock(horizon, ack, events)


#: Largest port number an event may carry.
MAX_PORT = int(max(Port))
#: Largest second word (address, port, reserved byte) of a valid event, as a u32.
_MAX_HIGH_WORD = (MAX_PORT << 16) | 0xFFFF


def _check_events(
    words: np.ndarray, horizon: int, packet: tuple[int, int], error: type[Exception]
) -> None:
    """Raise ``error`` naming ``packet`` (kind, seq) for a horizon beyond a u32, ticks out of
    order, a reserved byte set or an unknown port. ``words``: the events as little-endian u32
    words, shape ``(2 k,)`` (tick, then address | port << 16 | reserved << 24). Runs once per
    packet on each side of the link, so the checks are two reductions over these words."""
    if not 0 <= horizon <= MAX_TICK:
        raise error(f"{_packet_name(packet)}: horizon {horizon} is not a u32 tick")
    if words.size == 0:
        return
    ticks, high = words[0::2], words[1::2]
    if (ticks[1:] < ticks[:-1]).any():
        i = int(np.flatnonzero(ticks[1:] < ticks[:-1])[0])
        raise error(
            f"{_packet_name(packet)}: out-of-order timestamps, event {i + 1} at tick "
            f"{ticks[i + 1]} after tick {ticks[i]}"
        )
    if high.max() > _MAX_HIGH_WORD:  # a port above MAX_PORT or a reserved byte set
        if (high >> 24).any():
            raise error(f"{_packet_name(packet)}: event reserved byte must be 0")
        port = int(((high >> 16) & 0xFF).max())
        raise error(f"{_packet_name(packet)}: unknown event port {port}")


def _packet_name(packet: tuple[int, int]) -> str:
    """``"OUTPUT_EVENTS packet seq 7"`` for ``(kind, seq)``."""
    kind, seq = packet
    return f"{Kind(kind).name} packet seq {seq}"


def check_stream_order(block: EventBlock, previous: int, where: str) -> int:
    """Check a packet against its stream: no tick and no horizon below ``previous`` (the
    preceding packet's horizon or last tick, whichever is later) [ticks]. Returns the value to
    pass for the next packet; :class:`WireError` when the stream went back in time."""
    if block.events.size and int(block.events["tick"][0]) < previous:
        raise WireError(
            f"{where}: out-of-order timestamps, tick {int(block.events['tick'][0])} after the "
            f"stream reached tick {previous}"
        )
    if block.horizon < previous:
        raise WireError(f"{where}: horizon went back from {previous} to {block.horizon}")
    last = int(block.events["tick"][-1]) if block.events.size else 0
    return max(block.horizon, last)
