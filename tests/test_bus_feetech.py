"""Feetech-specific behaviour: the SDK's module-wide endianness, sign-magnitude values,
status bits from the status register."""

from __future__ import annotations

import pytest
import scservo_sdk

from robot.bus.sdk.bus import SdkBus
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


@pytest.fixture
def protocol() -> str:
    return "feetech"


def test_endianness_global_flipped_by_someone_else(bus: SdkBus, emu: Emulator) -> None:
    scservo_sdk.SCS_SETEND(1)  # e.g. another SCS-series (big-endian) user in the process
    try:
        assert bus.ping(1) == MODELS["STS3215"].number
        bus.set_torque([1], enabled=True)
        bus.write_goals({1: 2100})
        assert emu.registers(1)["goal_position"] == 2100
    finally:
        scservo_sdk.SCS_SETEND(0)


def test_sign_magnitude_load(bus: SdkBus, emu: Emulator) -> None:
    emu.set_register(1, "present_load", (1 << 10) | 300)
    emu.set_register(2, "present_load", 250)
    state = bus.read_state([1, 2])
    assert state[1].load == pytest.approx(-30.0)
    assert state[2].load == pytest.approx(25.0)


def test_status_clears_when_condition_ends(bus: SdkBus, emu: Emulator) -> None:
    emu.set_faults(hw_error={6: "overload"})
    assert bus.read_state([6])[6].errors == {"overload"}
    emu.set_faults(hw_error={6: None})
    assert bus.read_state([6])[6].errors == frozenset()
