"""The USB AER wire format, control protocol and fixed-point image: golden bytes, round trips,
corrupt input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mappings.usb.image import FIXED_PARAM_NAMES, FixedPointImage
from mappings.usb.protocol import (
    Counters,
    DeviceInfo,
    Opcode,
    Status,
    decode_command,
    decode_response,
    encode_command,
    encode_response,
)
from mappings.usb.wire import (
    EVENT_DTYPE,
    Flags,
    Kind,
    Port,
    WireError,
    check_stream_order,
    decode_events,
    decode_packet,
    encode_events,
    encode_packet,
    make_events,
)


def reference_crc32(data: bytes) -> int:
    """Bit-by-bit CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, init/xorout all ones)."""
    crc = 0xFFFFFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ (0xEDB88320 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


def test_reference_crc_is_the_standard_crc32():
    assert reference_crc32(b"123456789") == 0xCBF43926  # the catalogue's check value


def _check_trailer(packet: bytes) -> None:
    assert int.from_bytes(packet[-4:], "little") == reference_crc32(packet[:-4])


# ------------------------------------------------------------------------------ golden vectors
GET_INFO_SEQ0 = bytes.fromhex(
    "5350 01 10 0000 0000 04000000"  # magic "SP", v1, COMMAND, seq 0, flags 0, 4-byte payload
    "01 00 0000"  # opcode GET_INFO, reserved
    "c2fd4d96"  # CRC-32 of the 16 bytes above, little-endian
)

INPUT_SEQ1_FINAL = bytes.fromhex(
    "5350 01 01 0100 0100 18000000"  # INPUT_EVENTS, seq 1, FINAL, 24-byte payload
    "e8030000 0000 0000"  # horizon 1000 ticks, ack 0, reserved
    "05000000 0000 00 00"  # tick 5, address 0, port INPUT
    "07000000 0000 00 00"  # tick 7
    "d5436fff"
)

OUTPUT_SEQ4660 = bytes.fromhex(
    "5350 01 02 3412 0000 10000000"  # OUTPUT_EVENTS, seq 0x1234, 16-byte payload
    "0e0c0b0a 0300 0000"  # horizon 0x0A0B0C0E, ack 3
    "0d0c0b0a 0201 01 00"  # tick 0x0A0B0C0D, sPLL 0x0102, port TDE
    "02533732"
)

COUNTERS_RESPONSE = bytes.fromhex(
    "5350 01 11 0700 0000 24000000"  # RESPONSE to seq 7, 36-byte payload
    "06 00 0000"  # opcode COUNTERS, status OK
    "01000000 02000000 03000000 04000000 05000000 06000000 07000000 08000000"
    "7ba175b6"
)


def test_golden_command_packet():
    _check_trailer(GET_INFO_SEQ0)
    assert encode_command(0, Opcode.GET_INFO) == GET_INFO_SEQ0
    packet = decode_packet(GET_INFO_SEQ0)
    assert (packet.kind, packet.seq, packet.flags) == (Kind.COMMAND, 0, Flags.NONE)
    assert decode_command(packet) == (Opcode.GET_INFO, b"")


def test_golden_input_events_packet():
    _check_trailer(INPUT_SEQ1_FINAL)
    events = make_events([5, 7], 0, Port.INPUT)
    assert encode_events(Kind.INPUT_EVENTS, 1, events, 1000, final=True) == INPUT_SEQ1_FINAL
    packet = decode_packet(INPUT_SEQ1_FINAL)
    assert packet.final and packet.seq == 1
    block = decode_events(packet)
    assert (block.horizon, block.ack) == (1000, 0)
    assert block.events.tolist() == [(5, 0, 0, 0), (7, 0, 0, 0)]


def test_golden_output_events_packet():
    _check_trailer(OUTPUT_SEQ4660)
    events = make_events([0x0A0B0C0D], 0x0102, Port.TDE)
    assert encode_events(Kind.OUTPUT_EVENTS, 0x1234, events, 0x0A0B0C0E, ack=3) == OUTPUT_SEQ4660
    block = decode_events(decode_packet(OUTPUT_SEQ4660))
    assert block.events.tolist() == [(0x0A0B0C0D, 0x0102, Port.TDE, 0)]
    assert (block.horizon, block.ack) == (0x0A0B0C0E, 3)


def test_golden_counters_response():
    _check_trailer(COUNTERS_RESPONSE)
    counters = Counters(1, 2, 3, 4, 5, 6, 7, 8)
    assert encode_response(7, Opcode.COUNTERS, Status.OK, counters.pack()) == COUNTERS_RESPONSE
    opcode, status, data = decode_response(decode_packet(COUNTERS_RESPONSE))
    assert (opcode, status, Counters.unpack(data)) == (Opcode.COUNTERS, Status.OK, counters)


def test_golden_device_info():
    info = DeviceInfo(0x00010000, 1 << 20, 1024, 256, 4, 8)
    assert info.pack() == bytes.fromhex("00000100 00001000 0004 0001 0400 0800")
    assert DeviceInfo.unpack(info.pack()) == info
    assert info.max_packet_bytes == 16 + 8 + 8 * 256


# ------------------------------------------------------------------------------ round trips
events_st = st.lists(
    st.tuples(st.integers(0, 2**32 - 2), st.integers(0, 0xFFFF), st.sampled_from(list(Port))),
    max_size=40,
).map(sorted)


@settings(max_examples=200, deadline=None)
@given(
    kind=st.sampled_from([Kind.INPUT_EVENTS, Kind.OUTPUT_EVENTS]),
    seq=st.integers(0, 0xFFFF),
    ack=st.integers(0, 0xFFFF),
    final=st.booleans(),
    rows=events_st,
    extra=st.integers(0, 1000),
)
def test_event_packets_round_trip(kind, seq, ack, final, rows, extra):
    ticks = [r[0] for r in rows]
    events = make_events(ticks, [r[1] for r in rows], [int(r[2]) for r in rows])
    horizon = min((ticks[-1] if ticks else 0) + extra, 2**32 - 1)
    data = encode_events(kind, seq, events, horizon, ack=ack, final=final)
    assert len(data) == 16 + 8 + 8 * len(rows)
    packet = decode_packet(data)
    assert (packet.kind, packet.seq, packet.final) == (kind, seq, final)
    block = decode_events(packet)
    assert (block.horizon, block.ack) == (horizon, ack)
    np.testing.assert_array_equal(block.events, events)


@settings(max_examples=100, deadline=None)
@given(
    seq=st.integers(0, 0xFFFF),
    opcode=st.sampled_from(list(Opcode)),
    status=st.sampled_from(list(Status)),
    data=st.binary(max_size=300),
)
def test_commands_and_responses_round_trip(seq, opcode, status, data):
    command = decode_packet(encode_command(seq, opcode, data))
    assert command.seq == seq and decode_command(command) == (opcode, data)
    response = decode_packet(encode_response(seq, opcode, status, data))
    assert response.seq == seq and decode_response(response) == (opcode, status, data)


@settings(max_examples=50, deadline=None)
@given(values=st.lists(st.integers(0, 2**32 - 1), min_size=8, max_size=8))
def test_counters_round_trip(values):
    assert Counters.unpack(Counters(*values).pack()) == Counters(*values)


# ------------------------------------------------------------------------------ bad input
@settings(max_examples=200, deadline=None)
@given(position=st.integers(0, len(INPUT_SEQ1_FINAL) - 1), mask=st.integers(1, 255))
def test_any_corrupted_byte_is_detected(position, mask):
    data = bytearray(INPUT_SEQ1_FINAL)
    data[position] ^= mask
    with pytest.raises(WireError):
        decode_packet(bytes(data))


@pytest.mark.parametrize("size", range(len(OUTPUT_SEQ4660)))
def test_truncated_packets_are_detected(size):
    with pytest.raises(WireError, match="truncated"):
        decode_packet(OUTPUT_SEQ4660[:size])


def test_decode_errors_name_the_problem():
    with pytest.raises(WireError, match="overlong"):
        decode_packet(OUTPUT_SEQ4660 + b"\x00")
    with pytest.raises(WireError, match="bad magic"):
        decode_packet(b"XX" + OUTPUT_SEQ4660[2:])
    v2 = bytearray(encode_packet(Kind.COMMAND, 0, b"\x01\x00\x00\x00"))
    v2[2] = 2
    with pytest.raises(WireError, match="version 2"):
        decode_packet(bytes(v2))
    body = bytes.fromhex("5350 01 7f 0000 0000 00000000")
    unknown = body + reference_crc32(body).to_bytes(4, "little")
    with pytest.raises(WireError, match="unknown packet kind 0x7f"):
        decode_packet(unknown)
    with pytest.raises(WireError, match="not 8 \\+ 8\\*k"):
        decode_events(decode_packet(encode_packet(Kind.OUTPUT_EVENTS, 0, b"\x00" * 9)))


def test_out_of_order_timestamps_are_rejected_on_both_sides():
    backwards = np.zeros(2, EVENT_DTYPE)
    backwards["tick"] = [9, 4]
    with pytest.raises(ValueError, match="out-of-order timestamps, event 1 at tick 4 after tick 9"):
        encode_events(Kind.INPUT_EVENTS, 0, backwards, 10)
    # a packet whose CRC is right but whose events go back in time (a firmware bug)
    payload = (10).to_bytes(4, "little") + bytes(4) + backwards.tobytes()
    packet = decode_packet(encode_packet(Kind.OUTPUT_EVENTS, 3, payload))
    with pytest.raises(WireError, match="out-of-order timestamps"):
        decode_events(packet)


def test_stream_order_across_packets():
    first = decode_events(decode_packet(OUTPUT_SEQ4660))
    reached = check_stream_order(first, 0, "p0")
    assert reached == 0x0A0B0C0E
    earlier = decode_events(
        decode_packet(encode_events(Kind.OUTPUT_EVENTS, 0, make_events([5], 0, Port.TDE), 6))
    )
    with pytest.raises(WireError, match="out-of-order timestamps, tick 5"):
        check_stream_order(earlier, reached, "p1")
    empty_back = decode_events(
        decode_packet(encode_events(Kind.OUTPUT_EVENTS, 0, make_events([], 0, 0), 7))
    )
    with pytest.raises(WireError, match="horizon went back"):
        check_stream_order(empty_back, reached, "p1")


def test_encoder_rejects_values_that_do_not_fit():
    with pytest.raises(ValueError, match="tick out of range"):
        make_events([2**32], 0, Port.INPUT)
    with pytest.raises(ValueError, match="address out of range"):
        make_events([1], 70000, Port.TDE)
    with pytest.raises(ValueError, match="u16"):
        encode_packet(Kind.COMMAND, 65536)
    with pytest.raises(ValueError, match="not an event-packet kind"):
        encode_events(Kind.COMMAND, 0, make_events([], 0, 0), 0)


# ------------------------------------------------------------------------------ image
P = len(FIXED_PARAM_NAMES)

IMAGE_ONE_SPLL = bytes.fromhex(
    "5350494d 0100 0100 10 18 0c 00"  # "SPIM", v1, 1 sPLL, 16 params, 24-bit state, 12-bit decay
    "f168e388b5f8e43e"  # dt = 1e-5 s, float64
    + "".join(f"{v:02x}000000" for v in range(1, 17))  # u32 parameters 1 .. 16
)


def test_golden_fixed_point_image():
    assert P == 16  # the golden bytes are for quantize's 16 integer parameters
    image = FixedPointImage(np.arange(1, P + 1).reshape(1, P), 24, 12, 1e-5)
    assert image.pack() == IMAGE_ONE_SPLL
    back = FixedPointImage.unpack(IMAGE_ONE_SPLL)
    np.testing.assert_array_equal(back.params, image.params)
    assert (back.state_bits, back.decay_bits, back.dt, back.n_spll) == (24, 12, 1e-5, 1)


@settings(max_examples=50, deadline=None)
@given(
    params=st.lists(st.integers(0, 2**32 - 1), min_size=P, max_size=P * 6).map(
        lambda v: v[: len(v) // P * P]
    ),
    state_bits=st.integers(2, 32),
    decay_bits=st.integers(1, 30),
    dt=st.floats(1e-9, 1.0),
)
def test_images_round_trip(params, state_bits, decay_bits, dt):
    image = FixedPointImage(np.array(params, np.int64).reshape(-1, P), state_bits, decay_bits, dt)
    back = FixedPointImage.unpack(image.pack())
    np.testing.assert_array_equal(back.params, image.params)
    assert (back.state_bits, back.decay_bits, back.dt) == (state_bits, decay_bits, dt)


def test_bad_images_are_named():
    with pytest.raises(ValueError, match="shorter than its header"):
        FixedPointImage.unpack(IMAGE_ONE_SPLL[:10])
    with pytest.raises(ValueError, match="header declares 84"):
        FixedPointImage.unpack(IMAGE_ONE_SPLL[:-1])
    with pytest.raises(ValueError, match="unsupported image version 2"):
        FixedPointImage.unpack(IMAGE_ONE_SPLL[:4] + b"\x02" + IMAGE_ONE_SPLL[5:])
    with pytest.raises(ValueError, match="declares 15 parameters per sPLL, this board runs 16"):
        FixedPointImage.unpack(IMAGE_ONE_SPLL[:8] + b"\x0f" + IMAGE_ONE_SPLL[9:])
    with pytest.raises(ValueError, match="cco_weight = -1 does not fit"):
        FixedPointImage(np.array([[0, 0, -1] + [0] * (P - 3)]), 24, 12, 1e-5)
    with pytest.raises(ValueError, match=r"shape \(N, 16\)"):
        FixedPointImage(np.zeros((1, P - 1), np.int64), 24, 12, 1e-5)
    with pytest.raises(ValueError, match="state_bits"):
        FixedPointImage(np.zeros((1, P), np.int64), 33, 12, 1e-5)
