"""Both vendor buses end to end: the real SDKs against the emulated chain on a pty."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from bus_harness import PATIENT_TIMEOUT_MS
from waiting import wait_for

from robot.bus import health
from robot.bus.sdk.bus import SdkBus
from robot.bus.servo_map import ServoMap
from robot.bus.tables import TABLES
from robot.config.robot import RobotConfig
from robot.errors import BusError
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)
Factory = Callable[..., SdkBus]


def sync_writes(emu: Emulator) -> list:
    return [p for p in emu.log() if p.instruction == "sync_write"]


def wait_until(predicate: Callable[[], bool]) -> bool:
    return wait_for(predicate, every_s=0.01)


def test_open_is_healthy_and_scan_lists_every_servo(bus: SdkBus, robot: RobotConfig) -> None:
    assert bus.is_open and bus.health == []
    found = bus.scan(range(1, 21))
    assert [s.id for s in found] == sorted(robot.ids)
    model = MODELS[robot.bus.model]
    assert {(s.model, s.model_name) for s in found} == {(model.number, model.name)}
    assert all(s.return_delay_us == 0 and s.baud == robot.bus.baud for s in found)
    assert all(s.firmware is not None and s.firmware > 0 for s in found)
    assert bus.ping(19) is None


def test_torque_on_off_reads_back(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {1}
    bus.set_torque([3], enabled=False)
    assert emu.registers(3)["torque_enable"] == 0 and emu.registers(4)["torque_enable"] == 1


def test_close_disables_torque_and_is_idempotent(bus_factory: Factory, emu: Emulator,
        robot: RobotConfig) -> None:
    bus = bus_factory(emu, robot)
    bus.set_torque(robot.ids, enabled=True)
    bus.close()
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    assert not bus.is_open
    bus.close()
    held = bus_factory(emu, robot)
    held.set_torque(robot.ids, enabled=True)
    held.close(torque_off=False)
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {1}


def test_write_goals_read_state_round_trip(bus: SdkBus, emu: Emulator,
                                           robot: RobotConfig) -> None:
    sm = ServoMap(robot)
    goals = sm.goals(sm.vector(robot.rest).tolist())
    bus.set_torque(robot.ids, enabled=True)
    bus.write_goals(goals)
    assert {i: emu.registers(i)["goal_position"] for i in robot.ids} == goals
    assert wait_until(lambda: bus.read_positions(robot.ids) == goals)
    state = bus.read_state(robot.ids)
    assert list(state) == list(robot.ids)
    s = state[4]
    assert s.errors == frozenset() and s.temperature == 35.0
    assert s.voltage == pytest.approx(emu.registers(4)[
        "present_input_voltage" if bus.kind == "dynamixel" else "present_voltage"] * 0.1)
    assert s.load == 0.0


def test_one_sync_write_packet_per_call(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    emu.log(clear=True)
    for k in range(10):
        bus.write_goals({i: 2048 + (k if i == 1 else 0) for i in robot.ids})
    # A sync write has no reply: the emulator may still be reading the last packets.
    assert wait_until(lambda: len(emu.log()) >= 10)
    log = emu.log()
    assert [p.instruction for p in log] == ["sync_write"] * 10
    goal = TABLES[bus.family]["goal_position"].address
    assert all(p.address == goal and p.ids == robot.ids for p in log)
    assert [p.values[1] for p in log] == [2048 + k for k in range(10)]


def test_refuses_goals_outside_the_limits(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    sm = ServoMap(robot)
    knee = sm.index("r_knee")
    emu.log(clear=True)
    with pytest.raises(BusError, match=r"id 4 \(r_knee\).*outside its limits"):
        bus.write_goals({1: 2048, 4: int(sm.tick_min[knee]) - 1})
    with pytest.raises(BusError, match="not a servo of robot"):
        bus.write_goals({30: 2048})
    with pytest.raises(BusError, match="whole ticks"):
        bus.write_goals({1: 2048.5})  # type: ignore[dict-item]
    assert sync_writes(emu) == []
    bus.write_goals({4: int(sm.tick_min[knee])})
    assert wait_until(lambda: len(sync_writes(emu)) >= 1)  # no reply to wait for: poll the log
    assert len(sync_writes(emu)) == 1


def test_dropped_replies_recovered_by_retry(bus_factory: Factory, emu: Emulator,
        robot: RobotConfig) -> None:
    bus = bus_factory(emu, robot, retries=6)
    emu.set_faults(drop_rate=0.04)
    for _ in range(20):
        assert set(bus.read_state(robot.ids)) == set(robot.ids)
    assert emu.counters()["dropped"] > 0
    bus.close()


def test_all_replies_dropped_raises_after_retries(bus: SdkBus, emu: Emulator) -> None:
    emu.set_faults(drop_rate=1.0)
    emu.log(clear=True)
    with pytest.raises(BusError, match=r"id 1 \(r_hip_yaw\).*after 3 attempts.*check power"):
        bus.read_state([1, 2, 3])
    assert [p.instruction for p in emu.log()] == ["sync_read"] * 3


def test_bad_checksum_is_reported_then_recovers(bus: SdkBus, emu: Emulator,
                                                robot: RobotConfig) -> None:
    emu.set_faults(corrupt_rate=1.0)
    with pytest.raises(BusError, match="Incorrect status packet.*garbled"):
        bus.read_state(robot.ids)
    with pytest.raises(BusError, match=r"id 2 \(r_hip_roll\): ping"):
        bus.ping(2)
    emu.clear_faults()
    assert len(bus.read_state(robot.ids)) == len(robot.ids)


def test_missing_servo_is_named_never_stale(bus: SdkBus, emu: Emulator,
                                           robot: RobotConfig) -> None:
    bus.read_state(robot.ids)
    emu.set_faults(missing_ids=[7])
    with pytest.raises(BusError, match=r"id 7 \(l_hip_yaw\).*check power and wiring of id 7"):
        bus.read_state(robot.ids)
    # Torque on writes the gains first: a servo whose gains cannot be verified stops it
    # before any servo takes torque.
    with pytest.raises(BusError, match=r"id 7 \(l_hip_yaw\): read gains"):
        bus.set_torque(robot.ids, enabled=True)
    assert emu.registers(8)["torque_enable"] == 0
    bus.set_torque([i for i in robot.ids if i != 7], enabled=True)
    with pytest.raises(BusError, match=r"id 7 \(l_hip_yaw\): write torque_enable"):
        bus.set_torque(robot.ids, enabled=False)
    assert emu.registers(8)["torque_enable"] == 0  # the others were still disabled
    emu.clear_faults()
    assert len(bus.read_state(robot.ids)) == len(robot.ids)


def test_servo_vanishing_mid_run(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    emu.set_faults(vanish={9: 0.3})
    assert 9 in bus.read_state(robot.ids)
    errors: list[str] = []

    def failed() -> bool:
        try:
            bus.read_state(robot.ids)
        except BusError as e:
            errors.append(str(e))
            return True
        return False

    assert wait_until(failed)
    assert "id 9 (l_hip_pitch)" in errors[0]


def test_hardware_errors_surface(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    emu.set_faults(hw_error={3: "overheating", 5: "overload"})
    state = bus.read_state(robot.ids)
    assert state[3].errors == {"overheating"}
    assert state[5].errors == {"overload"}
    assert state[4].errors == frozenset()


def test_port_closed_raises_quickly_and_close_is_safe(bus: SdkBus, emu: Emulator,
                                                      robot: RobotConfig) -> None:
    emu.set_faults(close_port=True)
    with pytest.raises(BusError, match="port error.*plugged in"):
        bus.read_state(robot.ids)
    with pytest.raises(BusError, match="port error"):
        bus.write_goals({1: 2048})
    bus.close()
    assert not bus.is_open
    with pytest.raises(BusError, match="not open"):
        bus.read_state(robot.ids)


def test_port_busy_never_sticks(bus: SdkBus, emu: Emulator, robot: RobotConfig) -> None:
    bus.port_handler.is_using = True  # what an exception inside the SDK leaves behind
    assert len(bus.read_state(robot.ids)) == len(robot.ids)
    emu.set_faults(missing_ids=[1])
    with pytest.raises(BusError):
        bus.ping(1) or bus.read_state([1])
    emu.clear_faults()
    bus.port_handler.is_using = True
    bus.write_goals({1: 2048})
    assert bus.ping(1) is not None


def test_wrong_baud_names_the_rate_that_answers(bus_factory: Factory, emu: Emulator,
        robot: RobotConfig) -> None:
    other = 57600 if emu.protocol == "dynamixel" else 500000
    emu.set_baud(other)
    # A ping is not retried: a starved emulator missed 100 ms for each id probed at 57600.
    b = bus_factory(emu, robot, open=False, timeout_ms=PATIENT_TIMEOUT_MS)
    with pytest.raises(BusError, match=rf"answers? at {other} baud.*--baud {other}"):
        b.open()
    assert not b.is_open


def test_nothing_answers_at_any_rate(bus_factory: Factory, emu: Emulator,
        robot: RobotConfig) -> None:
    emu.set_faults(missing_ids=robot.ids)
    b = bus_factory(emu, robot, open=False, timeout_ms=5)
    with pytest.raises(BusError, match="nor at any other standard rate"):
        b.open()


def test_health_warns_return_delay_and_missing_and_fixes(bus_factory: Factory, emu: Emulator,
        robot: RobotConfig) -> None:
    emu.set_register(3, "return_delay_time", 250)
    emu.set_faults(missing_ids=[12])
    bus = bus_factory(emu, robot)
    assert len(bus.health) == 2
    missing, delay = sorted(bus.health, key=lambda w: "return delay" in w)
    assert "id 12 (l_ankle_roll)" in missing
    assert "id 3 (r_hip_pitch)" in delay and "500 µs" in delay
    assert "--fix-return-delay" in delay
    assert health.fix_return_delay(bus, [1, 2, 3]) == [3]
    assert emu.registers(3)["return_delay_time"] == 0
    if "lock" in bus.table:
        assert emu.registers(3)["lock"] == 1
    bus.close()


def test_latency_timer_warning(tmp_path) -> None:  # type: ignore[no-untyped-def]
    timer = tmp_path / "ttyUSB0" / "latency_timer"
    timer.parent.mkdir()
    timer.write_text("16\n")
    w = health.latency_warning("/dev/ttyUSB0", sysfs=tmp_path)
    assert w is not None and "16 ms" in w and f"echo 1 | sudo tee {timer}" in w
    timer.write_text("1\n")
    assert health.latency_warning("/dev/ttyUSB0", sysfs=tmp_path) is None
    assert health.latency_warning("/dev/pts/3", sysfs=tmp_path) is None
