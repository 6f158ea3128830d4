"""The LX bus (robot/bus/lx/bus.py) at the wire, against the emulated LX chain: what the
emulator's servos were told (goal, move time, load state per servo) after each call, and
faults: dropped answers, a silent servo, overheating, a wrong baud."""

from __future__ import annotations

import time
from collections.abc import Iterator

import pytest
from waiting import wait_for

from robot.bus.factory import make_bus
from robot.bus.lx.bus import LxBus
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.errors import BusError, ConfigError
from robot.loop.streamer import Streamer
from robot.motion.posing import PoseMove
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)


@pytest.fixture
def protocol() -> str:
    return "lx"


@pytest.fixture
def bus(emu: Emulator, robot: RobotConfig) -> Iterator[LxBus]:
    b = make_bus("lx", robot=robot, port=emu.port, timeout_ms=100.0)
    assert isinstance(b, LxBus)
    b.open()
    yield b
    b.close()


def loads(emu: Emulator, robot: RobotConfig) -> dict[int, int]:
    return {i: emu.registers(i)["torque_enable"] for i in robot.ids}


def test_scan_names_the_configured_model_and_skips_silent_ids(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    emu.set_faults(missing_ids=[5])
    found = bus.scan(range(1, 21))
    assert [s.id for s in found] == [i for i in robot.ids if i != 5]
    assert {s.model_name for s in found} == {"LX-16A (config)"}
    assert {s.baud for s in found} == {115200}


def test_torque_on_and_off_per_servo_confirmed_by_read_back(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    assert set(loads(emu, robot).values()) == {1}
    bus.set_torque(robot.ids, enabled=False)
    assert set(loads(emu, robot).values()) == {0}


def test_goals_are_one_move_per_servo_with_the_tick_as_move_time(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    goals = {i: 500 for i in robot.ids} | {4: 560}      # r_knee, inside 0..2 rad
    emu.log(clear=True)
    bus.write_goals(goals)
    time.sleep(0.05)
    bus.write_goals(goals)
    moves = [p for p in emu.log() if p.instruction == "move_time_write"]
    assert [p.ids[0] for p in moves] == list(robot.ids) * 2          # no sync write
    assert moves[3].values == {4: 560}
    regs = emu.registers(4)
    assert regs["goal_position"] == 560
    assert 50 <= regs["move_time_ms"] <= 1000     # the gap between the two writes
    assert wait_for(lambda: bus.read_positions([4])[4] == 560)


def test_a_goal_outside_the_joint_limits_is_refused_and_nothing_sent(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    emu.log(clear=True)
    with pytest.raises(BusError, match=r"id 4 \(r_knee\) is outside its limits"):
        bus.write_goals({1: 500, 4: 1000})
    assert not [p for p in emu.log() if p.instruction == "move_time_write"]


def test_read_state_survives_dropped_answers_and_names_a_silent_servo(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    emu.set_faults(drop_rate=0.2)
    states = bus.read_state(robot.ids)
    assert {s.position for s in states.values()} == {500}
    emu.set_faults(drop_rate=0.0, missing_ids=[7])
    with pytest.raises(BusError, match=r"id 7 \(l_hip_yaw\): read present_position failed"):
        bus.read_state(robot.ids)


def test_status_values_come_round_robin_and_overheating_is_seen(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    ids = robot.ids[:2]
    bus.set_torque(ids, enabled=True)
    for _ in range(4 + 3 * len(ids)):       # limits of each, then temp/voltage/load each
        states = bus.read_state(ids)
    assert states[ids[0]].temperature == 30 and states[ids[0]].voltage == pytest.approx(7.4)
    emu.set_faults(hw_error={ids[1]: "overheating"})
    assert emu.registers(ids[1])["torque_enable"] == 0           # the servo unloads itself
    assert wait_for(lambda: "overheating" in bus.read_state(ids)[ids[1]].errors, timeout_s=5)


def test_release_unloads_every_servo_without_an_answer(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    emu.set_faults(drop_rate=1.0)                 # no answer comes back at all
    bus.release(robot.ids)
    assert set(loads(emu, robot).values()) == {0}


def test_close_unloads_every_servo(emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    bus.set_torque(robot.ids, enabled=True)
    bus.close()
    assert set(loads(emu, robot).values()) == {0}


def test_wrong_baud_and_nothing_answering_say_so(emu: Emulator, robot: RobotConfig) -> None:
    with pytest.raises(BusError, match="115200 only"):
        make_bus("lx", robot=robot, port=emu.port, baud=57600)
    emu.set_faults(missing_ids=robot.ids)
    b = make_bus("lx", robot=robot, port=emu.port, timeout_ms=30.0, retries=0)
    with pytest.raises(BusError, match="no servo answers .* LX servos talk only at 115200"):
        b.open()
    assert not b.is_open


def test_a_rate_the_wire_cannot_carry_is_refused_before_anything_moves(
        emu: Emulator, bus: LxBus, robot: RobotConfig) -> None:
    sm = ServoMap(robot)
    move = PoseMove(robot, sm.from_positions(bus.read_positions(sm.ids)))
    emu.log(clear=True)
    with pytest.raises(ConfigError, match=r"--rate 200: 18 LX servos .* use --rate 5\d"):
        Streamer(sm, bus, move, rate_hz=200.0)
    assert not [p for p in emu.log() if p.instruction.endswith("_write")]
    Streamer(sm, bus, move, rate_hz=50.0)      # fits: 15.6 ms of moves in a 20 ms tick
