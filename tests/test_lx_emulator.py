"""The emulated LX servo behaves as the manual says (LewanSoul Bus Servo Communication
Protocol): the broadcast ID read is answered by a lone servo only (two collide), the
offset shifts positions (command 17: -125..125 = -30..30 deg), writes are never answered,
and a corrupted answer is refused by its checksum."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from waiting import wait_for

from robot.bus.lx.bus import LxBus
from robot.errors import BusError
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


@pytest.fixture
def pair() -> Iterator[tuple[Emulator, LxBus]]:
    with Emulator("lx", ids=[1, 2]) as emu:
        bus = LxBus(emu.port, timeout_ms=100.0, retries=1)
        bus.open()
        yield emu, bus
        bus.close()


def test_broadcast_id_read_finds_a_lone_servo_and_two_collide(
        pair: tuple[Emulator, LxBus]) -> None:
    emu, bus = pair
    emu.set_faults(missing_ids=[2])
    assert bus.broadcast_ping() == {1: 16}
    emu.set_faults(missing_ids=[])
    with pytest.raises(BusError, match="garbled"):
        bus.broadcast_ping()


def test_writes_get_no_answer_and_the_offset_shifts_positions(
        pair: tuple[Emulator, LxBus]) -> None:
    emu, bus = pair
    bus.set_torque([1], enabled=True)
    emu.log(clear=True)
    before = emu.counters()["tx_packets"]
    bus.write_register(1, "angle_offset", -20)       # -4.8 deg: the horn moves there
    assert emu.counters()["tx_packets"] == before     # no answer to a write
    assert emu.registers(1)["angle_offset"] == -20
    # the goal is unchanged, so the position (relative to the offset) settles back on it
    assert wait_for(lambda: bus.read_register(1, "present_position") == 500)
    bus.set_torque([1], enabled=False)
    emu.set_register(1, "present_position", 480)      # moved by hand, in offset terms
    assert bus.read_register(1, "present_position") == 480
    assert bus.read_register(1, "angle_offset") == -20


def test_a_corrupted_answer_is_refused(pair: tuple[Emulator, LxBus]) -> None:
    emu, bus = pair
    emu.set_faults(corrupt_rate=1.0)
    with pytest.raises(BusError, match=r"id 2: read present_position failed: no answer"):
        bus.read_register(2, "present_position")
    assert bus.bad_checksum >= 2
