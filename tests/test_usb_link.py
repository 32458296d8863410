"""UsbLink over pyusb against the board emulator: protocol, flow control and every fault.

The emulator is a real pyusb backend (``usb.core.find(backend=...)``), so these tests run
pyusb's own Device/Configuration/Endpoint code. The board's network computation is replaced by
:class:`EchoCore`, whose output is known in advance, so every lost event can be counted; the
real fixed-point core is exercised in ``test_usb_end_to_end.py``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
import usb.core
import usb.util

from mappings.usb import (
    DEFAULT_PID,
    DEFAULT_VID,
    DeviceBusyError,
    DeviceDisconnectedError,
    DeviceError,
    DeviceNotFoundError,
    DevicePermissionError,
    DeviceTimeoutError,
    NoUsbBackendError,
    StreamError,
    UsbLink,
)
from mappings.usb.emulator import EmulatedBoard, EmulatorBackend, Faults
from mappings.usb.link import EP_EVENTS_IN, EP_EVENTS_OUT
from mappings.usb.protocol import Status
from mappings.usb.wire import EVENT_DTYPE, Kind, Port, encode_events, make_events

TIMEOUT = 0.1  # s: every transfer's bound in these tests


class EchoCore:
    """Test double of a board's network: input spike at tick t -> TDE spike of sPLL t % n at t.

    The image is one byte, n. It honours the core contract: outputs below the horizon only.
    """

    n_spll = 0

    def load(self, image: bytes) -> None:
        if len(image) != 1 or image[0] == 0:
            raise ValueError("echo image is one byte, the number of sPLLs (>= 1)")
        self.n_spll = image[0]

    def start(self, duration: int) -> None:
        self.pending = np.zeros(0, np.int64)

    def advance(self, ticks: np.ndarray, horizon: int, final: bool) -> np.ndarray:
        self.pending = np.concatenate([self.pending, ticks])
        ready = self.pending if final else self.pending[self.pending < horizon]
        self.pending = self.pending[len(ready) :]
        return expected_echo(ready, self.n_spll)


def expected_echo(ticks: np.ndarray, n_spll: int) -> np.ndarray:
    return make_events(ticks, np.asarray(ticks) % n_spll, Port.TDE)


N_SPLL = 5
TICKS = np.sort(np.random.default_rng(7).integers(1, 20_001, 600))
DURATION = 20_000


def board(faults: Faults | None = None, **kwargs) -> EmulatedBoard:
    options = {"max_events": 32, "input_credits": 3, "output_buffer": 2} | kwargs
    return EmulatedBoard(EchoCore(), faults=faults, **options)


def open_link(b: EmulatedBoard) -> UsbLink:
    link = UsbLink(DEFAULT_VID, DEFAULT_PID, backend=EmulatorBackend(b), timeout=TIMEOUT).open()
    link.load(bytes([N_SPLL]))
    return link


# ------------------------------------------------------------------------------ pyusb
def test_pyusb_finds_and_describes_the_emulated_board():
    dev = usb.core.find(
        idVendor=DEFAULT_VID, idProduct=DEFAULT_PID, backend=EmulatorBackend(board())
    )
    assert isinstance(dev, usb.core.Device)
    assert (dev.serial_number, dev.manufacturer) == ("SPLLEMU0001", "spll-hw")
    intf = dev.get_active_configuration()[(0, 0)]
    addresses = sorted(e.bEndpointAddress for e in intf)
    assert addresses == [0x01, 0x02, 0x81, 0x82]
    assert all(usb.util.endpoint_type(e.bmAttributes) == usb.util.ENDPOINT_TYPE_BULK for e in intf)
    assert (
        usb.core.find(idVendor=DEFAULT_VID, idProduct=0x9999, backend=EmulatorBackend(board()))
        is None
    )


def test_serial_selects_among_several_boards():
    a, b = board(), board()
    b.serial = "SECOND"
    link = UsbLink(serial="SECOND", backend=EmulatorBackend(a, b), timeout=TIMEOUT).open()
    link.close()
    assert b.claimed_by is None and link.device is None
    with pytest.raises(DeviceNotFoundError, match="serial THIRD"):
        UsbLink(serial="THIRD", backend=EmulatorBackend(a, b), timeout=TIMEOUT).open()


# ------------------------------------------------------------------------------ streaming
def test_run_returns_every_event_with_consistent_counters():
    b = board()
    with open_link(b) as link:
        assert link.info.max_events == 32 and link.info.input_credits == 3
        result = link.run(TICKS, DURATION)
    np.testing.assert_array_equal(result.events, expected_echo(TICKS, N_SPLL))
    s = result.stats
    assert s.complete and s.horizon == DURATION + 1
    assert (s.input_sent, s.input_consumed, s.output_received) == (600, 600, 600)
    c = s.counters
    assert (c.input_events, c.output_events, c.horizon) == (600, 600, DURATION + 1)
    assert c.crc_errors == c.seq_errors == c.input_dropped_events == 0
    assert c.input_packets == int(np.ceil(600 / 32))
    tde = result.spikes(Port.TDE, N_SPLL)
    assert sum(len(t) for t in tde) == 600 and np.all(tde[3] % N_SPLL == 3)


def test_empty_input_and_repeated_ticks():
    with open_link(board()) as link:
        empty = link.run(np.zeros(0, np.int64), 1)
        assert empty.events.size == 0 and empty.stats.complete
        same = np.full(100, 42)  # 100 spikes in one time step span 4 packets
        result = link.run(same, 100)
    np.testing.assert_array_equal(result.events, expected_echo(same, N_SPLL))


def test_back_pressure_keeps_every_event_with_tiny_buffers():
    b = board(max_events=4, input_credits=1, output_buffer=1)
    with open_link(b) as link:
        result = link.run(TICKS, DURATION)
    assert result.stats.complete and result.events.size == 600


def test_a_full_input_fifo_naks_until_the_timeout():
    """Without the link's credit accounting the board refuses data: a bounded wait, no loss."""
    b = board(input_credits=2, output_buffer=1)
    with open_link(b) as link:
        link.start(DURATION)
        dev = link.device
        packets = [
            encode_events(Kind.INPUT_EVENTS, seq, make_events([seq + 1], 0, 0), seq + 2)
            for seq in range(4)
        ]
        for packet in packets[:3]:  # the board consumes one, buffers two; its output FIFO is full
            dev.write(EP_EVENTS_OUT, packet)
        t0 = time.monotonic()
        with pytest.raises(usb.core.USBTimeoutError):
            dev.write(EP_EVENTS_OUT, packets[3], 50)
        assert 0.04 < time.monotonic() - t0 < 1.0
        assert len(b.input_fifo) == 2
        dev.read(EP_EVENTS_IN, 1024, 50)  # reading frees the output FIFO: the board moves on
        assert len(b.input_fifo) == 1


# ------------------------------------------------------------------------------ errors on open
def test_no_device():
    with pytest.raises(DeviceNotFoundError, match="no USB board 1209:0001 attached"):
        UsbLink(backend=EmulatorBackend(), timeout=TIMEOUT).open()


def test_no_permission_names_the_udev_rule():
    with pytest.raises(DevicePermissionError) as err:
        UsbLink(backend=EmulatorBackend(board(Faults(deny_access=True))), timeout=TIMEOUT).open()
    message = str(err.value)
    assert 'ATTRS{idVendor}=="1209", ATTRS{idProduct}=="0001"' in message
    assert "/etc/udev/rules.d/70-spll-hw.rules" in message and "udevadm" in message
    # choosing by serial number reads a string descriptor, which already needs access
    denied = EmulatorBackend(board(Faults(deny_access=True)))
    with pytest.raises(DevicePermissionError, match="udev"):
        UsbLink(serial="SPLLEMU0001", backend=denied, timeout=TIMEOUT).open()


def test_a_claimed_board_is_busy():
    b = board()
    backend = EmulatorBackend(b)
    with UsbLink(backend=backend, timeout=TIMEOUT):
        with pytest.raises(DeviceBusyError, match="claimed by another"):
            UsbLink(backend=backend, timeout=TIMEOUT).open()
    UsbLink(backend=backend, timeout=TIMEOUT).open().close()  # released on exit


def test_bad_arguments_and_commands():
    with pytest.raises(ValueError, match="timeout"):
        UsbLink(timeout=0)
    with open_link(board()) as link:
        with pytest.raises(DeviceError, match="BAD_IMAGE") as err:
            link.load(b"")
        assert err.value.status == Status.BAD_IMAGE
        with pytest.raises(DeviceError, match="START before LOAD"):
            link.start(10)
        link.load(bytes([N_SPLL]))
        with pytest.raises(ValueError, match="out of order"):
            link.run([5, 3], 10)
        with pytest.raises(ValueError, match="in 1..10"):
            link.run([5, 11], 10)
        with pytest.raises(ValueError, match="in 1..10"):
            link.run([0, 5], 10)
        with pytest.raises(ValueError, match="integer"):
            link.run([0.5], 10)
        with pytest.raises(ValueError, match="exceeds"):
            link.load(bytes(link.info.max_image + 1))
        link.start(10)
        with pytest.raises(DeviceError, match="BAD_STATE"):
            link.load(bytes([N_SPLL]))
        link.stop()
        with pytest.raises(DeviceError, match="STOP without a run"):
            link.stop()


# ------------------------------------------------------------------------------ faults
def _lost(faults: Faults) -> StreamError:
    with open_link(board(faults)) as link, pytest.raises(StreamError) as err:
        link.run(TICKS, DURATION)
    return err.value


def test_dropped_output_packet_is_counted():
    err = _lost(Faults(drop=frozenset({4})))
    s = err.result.stats
    assert s.missing_packets == 1 and s.output_lost == 600 - s.output_received > 0
    assert "1 output packet(s) missing" in str(err) and f"({s.output_lost} lost)" in str(err)
    assert set(err.result.events["tick"]) < set(TICKS)


@pytest.mark.parametrize(
    ("faults", "reason"),
    [
        (Faults(corrupt=frozenset({2})), "CRC"),
        (Faults(truncate=frozenset({2})), "truncated packet"),
        (Faults(reorder=frozenset({2})), "out-of-order timestamps"),
    ],
)
def test_rejected_output_packets_are_counted(faults, reason):
    err = _lost(faults)
    s = err.result.stats
    assert len(s.rejected_packets) == 1 and reason in s.rejected_packets[0]
    assert s.output_lost == s.counters.output_events - s.output_received > 0
    assert s.missing_packets == 0 and s.input_lost == 0
    assert reason in str(err)


class BeyondTheRunCore(EchoCore):
    """A faulty board: on its third advance the last output event gets tick 2**32 - 2, far past
    the run (valid CRC, its packet's events still in order); ``alone``: the event is added
    instead, in a packet of its own, so the packet before it has that tick as its horizon."""

    def __init__(self, alone: bool = False):
        self.alone = alone

    def start(self, duration: int) -> None:
        super().start(duration)
        self.calls = 0

    def advance(self, ticks: np.ndarray, horizon: int, final: bool) -> np.ndarray:
        out = super().advance(ticks, horizon, final)
        self.calls += 1
        if self.calls == 3 and self.alone:
            return np.concatenate([out, make_events([2**32 - 2], 0, Port.TDE)])
        if self.calls == 3:
            out["tick"][-1] = 2**32 - 2
        return out


def _run_beyond(alone: bool):
    b = EmulatedBoard(BeyondTheRunCore(alone), max_events=32, input_credits=3, output_buffer=2)
    with open_link(b) as link:
        result = link.run(TICKS, DURATION, strict=False)
    s = result.stats
    assert s.missing_packets == 0 and result.events["tick"].max() <= DURATION
    assert s.output_lost == s.counters.output_events - s.output_received
    assert set(result.events["tick"]) < set(TICKS) and int(result.events["tick"][-1]) == TICKS[-1]
    return s


def test_an_output_tick_beyond_the_run_rejects_its_packet_only():
    """The packet with the impossible tick is rejected, naming the tick and the run length; the
    good packets after it are kept (not blamed as out of order)."""
    s = _run_beyond(alone=False)
    # the board advances its core once per pair of buffered input packets (output_buffer 2):
    # the third advance answers input packets 4 and 5, one output packet each
    assert s.rejected_packets == [
        f"output packet 5: tick {2**32 - 2} is beyond the run of {DURATION} ticks (packet rejected)"
    ]
    assert s.output_received == 600 - 32  # the 32 events of that one packet
    # Alone in its packet, the tick is also the horizon of the packet before: both go.
    s = _run_beyond(alone=True)
    first, second = s.rejected_packets
    assert f"horizon {2**32 - 2} is beyond the end of the run of {DURATION} ticks" in first
    assert f"tick {2**32 - 2} is beyond the run" in second
    assert s.output_received == 600 - 32


def test_corrupt_input_packet_is_reported_by_the_board():
    err = _lost(Faults(corrupt_input=frozenset({1})))
    c = err.result.stats.counters
    assert c.crc_errors == 1 and c.seq_errors == 1
    assert err.result.stats.input_lost == 32 and c.input_events == 600 - 32
    assert "32 lost: 1 corrupt packet(s)" in str(err)


def test_lost_final_packet_is_recovered_from_the_counters():
    b = board()
    with open_link(b) as link:
        n_out = link.run(TICKS, DURATION).stats.counters.output_packets
    b.faults = Faults(drop=frozenset({n_out - 1}))
    with open_link(b) as link:
        result = link.run(TICKS, DURATION, strict=False)
    assert "FINAL packet never arrived" in result.stats.rejected_packets
    assert result.stats.missing_packets == 0  # nothing after it to show the gap
    assert not result.stats.complete


def test_a_board_that_stops_answering_times_out_with_progress():
    with open_link(board(Faults(stall_after=3))) as link:
        t0 = time.monotonic()
        with pytest.raises(DeviceTimeoutError) as err:
            link.run(TICKS, DURATION)
        assert time.monotonic() - t0 < 6 * TIMEOUT  # the read, then one COUNTERS, each bounded
    s = err.value.stats
    assert s.output_received > 0 and s.input_sent > s.input_consumed
    assert "stopped answering" in str(err.value)
    assert f"{s.output_received} events received up to tick {s.horizon}" in str(err.value)


def test_unplugged_mid_run_then_reconnect():
    b = board(Faults(disconnect_after=4, reappear_after=0.2))
    link = open_link(b)
    with pytest.raises(DeviceDisconnectedError, match="disconnected during output read") as err:
        link.run(TICKS, DURATION)
    s = err.value.stats
    assert 0 < s.output_received < 600 and s.counters is None
    assert "device counters unavailable" in str(err.value)
    t0 = time.monotonic()
    link.reconnect(wait=2.0)
    assert 0.1 < time.monotonic() - t0 < 2.0
    assert b.generation == 1 and b.loaded  # replugged board powered up empty; image reloaded
    result = link.run(TICKS, DURATION)
    assert result.stats.complete
    link.close()


def test_reconnect_gives_up_in_time():
    b = board(Faults(disconnect_after=1))
    link = open_link(b)
    with pytest.raises(DeviceDisconnectedError):
        link.run(TICKS, DURATION)
    t0 = time.monotonic()
    with pytest.raises(DeviceNotFoundError, match="did not come back within 0.3 s"):
        link.reconnect(wait=0.3)
    assert time.monotonic() - t0 < 1.0


def test_emulator_refuses_an_unbounded_wait():
    with open_link(board()) as link, pytest.raises(RuntimeError, match="timeout 0"):
        link.device.read(EP_EVENTS_IN, 1024, 0)


def test_host_without_libusb_or_board():
    """Through pyusb's default backend search: no libusb or no board gives a clear error."""
    with pytest.raises(
        (NoUsbBackendError, DeviceNotFoundError), match="libusb|no USB board"
    ) as err:
        UsbLink(0x1209, 0xFFFE, timeout=TIMEOUT).open()  # a PID no board uses
    assert "emulator" in str(err.value)


def test_event_dtype_is_the_wire_layout():
    assert EVENT_DTYPE.itemsize == 8


def test_a_repeated_output_packet_is_rejected_not_counted_twice():
    """The wire delivers packet 3 twice: the copy is behind the expected seq; it is rejected with
    what happened (not reported as 65535 missing packets) and no event counts twice."""
    with open_link(board()) as link:
        clean = link.run(TICKS, DURATION)
    err = _lost(Faults(repeat=frozenset({3})))
    s = err.result.stats
    assert s.missing_packets == 0 and len(s.rejected_packets) == 1
    assert "arrived after seq 3 (a repeated or reordered packet" in s.rejected_packets[0]
    np.testing.assert_array_equal(err.result.events, clean.events)


def test_events_addressed_beyond_the_network_are_lost_not_dropped():
    with open_link(board()) as link:
        result = link.run(TICKS, DURATION)
    n = int(result.events["address"].max())  # a network one sPLL smaller than the board's
    with pytest.raises(StreamError, match=r"addressed to sPLL \d+ of a \d+-sPLL network"):
        result.spikes(result.events["port"][0], n)
    assert result.stats.misaddressed > 0 and not result.stats.complete
    assert "addressed beyond the network (lost)" in result.stats.summary()
