"""Dynamixel-specific behaviour: alert bit → Hardware Error Status, signed values,
instruction errors from the status packet."""

from __future__ import annotations

import pytest

from robot.bus.sdk.bus import SdkBus
from robot.bus.tables import DYNAMIXEL_X
from robot.errors import BusError
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


@pytest.fixture
def protocol() -> str:
    return "dynamixel"


def test_alert_bit_reads_hardware_error_status(bus: SdkBus, emu: Emulator) -> None:
    emu.set_faults(hw_error={2: "voltage"})
    emu.log(clear=True)
    state = bus.read_state([1, 2, 3])
    assert state[2].errors == {"voltage"} and state[1].errors == frozenset()
    reads = [p for p in emu.log() if p.instruction == "read"]
    assert [(p.ids, p.address) for p in reads] == [
        ((2,), DYNAMIXEL_X["hardware_error_status"].address)]


def test_signed_load_and_position(bus: SdkBus, emu: Emulator) -> None:
    emu.set_register(1, "present_load", (1 << 16) - 300)
    s = bus.read_state([1])[1]
    assert s.load == pytest.approx(-30.0)
    assert s.position == 2048


def test_instruction_error_is_not_retried_and_names_the_sdk_message(
        bus: SdkBus, emu: Emulator) -> None:
    emu.log(clear=True)
    with pytest.raises(BusError, match=r"id 1 \(r_hip_yaw\): write present_position.*"
                                       r"RxPacketError"):
        bus.write_register(1, "present_position", 5)
    assert len([p for p in emu.log() if p.instruction == "write"]) == 1
