"""Encode -> USB board -> classify, on the emulator (the real fixed-point core behind pyusb),
against the ``golden-fixed-point`` backend spike for spike; the same on a real board when one
is attached (skipped, with the reason, otherwise)."""

from __future__ import annotations

import numpy as np
import pytest

import quantize
from mappings.fixed_point.backend import FixedPointBackend
from mappings.usb import (
    DeviceError,
    DeviceNotFoundError,
    DeviceTimeoutError,
    NoUsbBackendError,
    UsbLink,
    UsbLinkError,
)
from mappings.usb.backend import emulator_link, input_ticks, run_steps, simulate_usb
from mappings.usb.emulator import Faults
from mappings.usb.image import FixedPointCore, FixedPointImage
from mappings.usb.protocol import Status
from mappings.usb.wire import Port
from spll_hw import _engine, backends
from spll_hw.classify import cross_validate
from spll_hw.config import NetworkConfig
from spll_hw.datasets.synthetic import make_synthetic
from spll_hw.encoders import make_encoder

from .conftest import poisson_train

#: The fixed-point reference the board must match spike for spike.
FIXED = FixedPointBackend(profile="loihi2")


def _board_state() -> tuple[str, str]:
    """``("attached", "")`` if a board answers at the default VID:PID, else ``("absent", why)``
    or ``("unusable", why)`` (attached but not openable: permissions, busy, ...)."""
    try:
        UsbLink(timeout=0.5).open().close()
    except (NoUsbBackendError, DeviceNotFoundError) as exc:
        return "absent", str(exc)
    except UsbLinkError as exc:
        return "unusable", str(exc)
    return "attached", ""


BOARD, WHY = _board_state()
needs_board = pytest.mark.skipif(BOARD != "attached", reason=f"needs a USB sPLL board: {WHY}")
needs_no_board = pytest.mark.skipif(BOARD != "absent", reason="a USB sPLL board is attached")


@pytest.fixture(scope="module")
def network():
    return NetworkConfig.preset("vibtac-vary-offset-pacinian").with_n(12).build()


@pytest.fixture(scope="module")
def quantized(network):
    return quantize.quantize(network, "loihi2")


def assert_same_spikes(a, b):
    np.testing.assert_array_equal(a.tde_counts, b.tde_counts)
    np.testing.assert_array_equal(a.cco_counts, b.cco_counts)
    for x, y in zip(a.tde_spikes + a.cco_spikes, b.tde_spikes + b.cco_spikes, strict=True):
        np.testing.assert_array_equal(x, y)


# ------------------------------------------------------------------------------ spike for spike
@pytest.mark.parametrize("seed", [0, 1])
def test_emulated_board_equals_the_fixed_point_reference(network, quantized, seed):
    x = poisson_train(400, 0.4, seed=seed)
    board = simulate_usb(network, x, 0.4, device="emulator")
    reference = FIXED.simulate(quantized.requested, x, 0.4)
    assert board.backend == "usb-emulator" and board.info["complete"]
    assert board.tde_counts.sum() > 50 and board.cco_counts.sum() > 100
    assert_same_spikes(board, reference)


def test_many_small_packets_stream_the_same_spikes(quantized):
    """Tiny packets and buffers: the core advances dozens of times, and back-pressure holds
    the board back; the output is still the reference's, bit for bit."""
    x = poisson_train(300, 0.3, seed=5)
    image = FixedPointImage.from_fixed(quantized.fixed)
    steps = run_steps(0.3, image.dt)
    link = emulator_link(max_events=8, input_credits=2, output_buffer=1, timeout=0.5)
    with link.open():
        link.load(image.pack())
        run = link.run(input_ticks(x, image.dt, steps), steps)
    assert run.stats.counters.input_packets >= 10 and run.stats.complete
    reference = FIXED.simulate(quantized.requested, x, 0.3)
    for port, trains in ((Port.TDE, reference.tde_spikes), (Port.CCO, reference.cco_spikes)):
        got = run.spikes(port, image.n_spll)
        for ticks, times in zip(got, trains, strict=True):
            np.testing.assert_array_equal(ticks, np.rint(times / image.dt).astype(np.int64))


def test_a_long_train_in_hundreds_of_packets_is_the_reference_in_linear_time(
    quantized, monkeypatch
):
    """3000 input spikes (bursts share a tick, across packet boundaries) in packets of 5: the
    core resumes each batch of buffered packets (up to the board's 4 input credits) from the
    last one's state, so over the whole run the reference steps each time step once, and the
    output is the reference's bit for bit."""
    x = np.sort(np.r_[poisson_train(6000, 0.5, seed=9), np.repeat([0.1, 0.25], 7)])
    image = FixedPointImage.from_fixed(quantized.fixed)
    steps = run_steps(0.5, image.dt)
    stepped = []  # steps each call of the reference ran
    simulate_fixed_point = _engine.simulate_fixed_point

    def counting(*args, start_step=0, **kwargs):
        stepped.append(round(args[3]) - start_step)
        return simulate_fixed_point(*args, start_step=start_step, **kwargs)

    monkeypatch.setattr(_engine, "simulate_fixed_point", counting)
    link = emulator_link(max_events=5, timeout=0.5)
    with link.open():
        link.load(image.pack())
        run = link.run(input_ticks(x, image.dt, steps), steps)
    monkeypatch.undo()
    assert run.stats.complete
    assert len(stepped) >= 600 // 4 and sum(stepped) == steps
    reference = FIXED.simulate(quantized.requested, x, 0.5)
    assert reference.tde_counts.sum() > 500
    for port, trains in ((Port.TDE, reference.tde_spikes), (Port.CCO, reference.cco_spikes)):
        for ticks, times in zip(run.spikes(port, image.n_spll), trains, strict=True):
            np.testing.assert_array_equal(ticks, np.rint(times / image.dt).astype(np.int64))


def test_usb_is_a_registered_backend(network, quantized):
    x = poisson_train(300, 0.2, seed=2)
    result = backends.run("usb-emulator:profile=loihi2", network, x, 0.2)
    assert result.backend == "usb-emulator"
    assert_same_spikes(result, FIXED.simulate(quantized.requested, x, 0.2))


@needs_no_board
def test_auto_uses_the_emulator_without_a_board(network):
    result = simulate_usb(network, poisson_train(200, 0.1, seed=1), 0.1)
    assert result.backend == "usb-emulator" and result.info["device"].startswith("emulator")


def test_encode_device_classify_matches_the_reference_pipeline(network, quantized):
    samples = make_synthetic(n_classes=3, samples_per_class=8, duration=0.5, seed=0)
    trains = make_encoder("pacinian").encode(samples.signals, samples.fs, ids=range(24))
    on_board = np.array(
        [simulate_usb(network, x, 0.5, device="emulator").tde_rates for x in trains]
    )
    reference = FIXED.simulate_batch(quantized.requested, trains, 0.5)
    np.testing.assert_array_equal(on_board, [r.tde_rates for r in reference])
    cv = cross_validate(on_board, samples.labels, samples.class_names, n_splits=4)
    assert cv.accuracy >= 0.75  # 3 classes: chance is 1/3
    assert cv.confusion.sum() == 24


# ------------------------------------------------------------------------------ bad input
def test_bad_input_is_named(network):
    with pytest.raises(ValueError, match="sorted"):
        simulate_usb(network, [0.2, 0.1], 0.3, device="emulator")
    with pytest.raises(ValueError, match="finite and >= 0"):
        simulate_usb(network, [-0.1], 0.3, device="emulator")
    with pytest.raises(ValueError, match="device must be one of"):
        simulate_usb(network, [0.1], 0.3, device="fpga")
    with pytest.raises(ValueError, match="not fixed point"):
        simulate_usb(network, [0.1], 0.3, profile="analog", device="emulator")
    with pytest.raises(ValueError, match="duration"):
        run_steps(0.0, 1e-5)


@needs_no_board
def test_board_mode_without_a_board_says_so(network):
    with pytest.raises((NoUsbBackendError, DeviceNotFoundError), match="emulator"):
        simulate_usb(network, [0.1], 0.3, device="board")


def test_the_board_rejects_a_malformed_image(quantized):
    image = FixedPointImage.from_fixed(quantized.fixed).pack()
    with emulator_link(timeout=0.5).open() as link:
        for bad, why in ((image[:-1], "header declares"), (b"NOPE" + image[4:], "magic")):
            with pytest.raises(DeviceError, match=why) as err:
                link.load(bad)
            assert err.value.status == Status.BAD_IMAGE
    core = FixedPointCore()
    core.load(image)
    assert core.n_spll == quantized.n_spll


def test_a_stalled_board_mid_run_is_reported_not_hung(network, quantized):
    image = FixedPointImage.from_fixed(quantized.fixed)
    steps = run_steps(0.2, image.dt)
    # small packets, so that the stall falls mid-run (~2 500 output events: ~10 packets of 256)
    link = emulator_link(timeout=0.1, max_events=256, faults=Faults(stall_after=5))
    with link.open(), pytest.raises(DeviceTimeoutError, match="stopped answering") as err:
        link.load(image.pack())
        link.run(input_ticks(poisson_train(300, 0.2, seed=3), image.dt, steps), steps)
    assert err.value.stats.output_received > 0


# ------------------------------------------------------------------------------ real board
@needs_board
def test_real_board_equals_the_fixed_point_reference(network, quantized):
    x = poisson_train(300, 0.3, seed=4)
    board = simulate_usb(network, x, 0.3, device="board")
    assert board.backend == "usb"
    assert_same_spikes(board, FIXED.simulate(quantized.requested, x, 0.3))
