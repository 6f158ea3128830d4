"""The MuJoCo mock bus: ticks in and out like a real bus, servo-like joints, sim-time clock."""

from __future__ import annotations

import math
import os
import time
from collections.abc import Iterator

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robot.bus.factory import make_bus  # noqa: E402
from robot.bus.servo_map import ServoMap  # noqa: E402
from robot.config.bundled import ROBOTS_DIR  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.errors import BusError  # noqa: E402
from sim.mujoco.bus import AMBIENT_C, MujocoBus  # noqa: E402

ROBOT = load_robot()
SM = ServoMap(ROBOT)
REST = SM.goals(SM.vector(ROBOT.rest))


@pytest.fixture
def bus() -> Iterator[MujocoBus]:
    b = MujocoBus(ROBOT)
    b.open()
    yield b
    b.close()


def _hold(bus: MujocoBus, goals: dict[int, int], seconds: float, rate: float = 100.0) -> None:
    t = bus.clock.now()
    for k in range(1, round(seconds * rate) + 1):
        bus.write_goals(goals)
        bus.clock.sleep_until(t + k / rate)


def test_constructor_does_no_work_and_factory_builds_it() -> None:
    b = make_bus("sim", robot=ROBOT, realtime=False)
    assert isinstance(b, MujocoBus) and b.kind == "sim" and not b.is_open
    with pytest.raises(BusError, match="not open"):
        b.read_state(ROBOT.ids)
    b.close()  # idempotent, even unopened


def test_ping_and_scan_answer_for_the_configured_servos(bus: MujocoBus) -> None:
    servo = ROBOT.bus.servo
    assert bus.ping(ROBOT.ids[0]) == servo.number
    assert bus.ping(200) is None
    found = bus.scan(range(0, 40))
    assert [s.id for s in found] == sorted(ROBOT.ids)
    assert {(s.model, s.model_name) for s in found} == {(servo.number, servo.name)}


def test_read_state_round_trips_ticks(bus: MujocoBus) -> None:
    assert bus.read_positions(ROBOT.ids) == REST  # the home keyframe is the rest pose
    state = bus.read_state([ROBOT.ids[0]])[ROBOT.ids[0]]
    assert state.temperature == AMBIENT_C and state.voltage == ROBOT.bus.servo.nominal_voltage
    assert state.errors == frozenset()
    with pytest.raises(BusError, match="servo id 99"):
        bus.read_state([99])
    with pytest.raises(BusError, match="servo id 99"):
        bus.write_goals({99: 2048})


@pytest.mark.parametrize("name", ["biped18-dynamixel.toml", "biped18-feetech.toml"])
def test_holding_the_rest_pose_stays_upright_for_5_s(name: str) -> None:
    robot = load_robot(ROBOTS_DIR / name)
    sm = ServoMap(robot)
    rest = sm.goals(sm.vector(robot.rest))
    with MujocoBus(robot) as b:
        assert isinstance(b, MujocoBus)
        b.set_torque(robot.ids, enabled=True)
        h0 = b.standing_height
        assert b.base_pose()[0][2] == pytest.approx(h0)
        t = 0.0
        while t < 5.0 - 1e-9:
            t += 0.01
            b.write_goals(rest)
            b.clock.sleep_until(t)
            assert b.base_pose()[0][2] > 0.9 * h0
            assert b.upright_angle() < math.radians(10)
        assert b.contacts_feet() == (True, True)
        state = b.read_state(robot.ids)
        knee = robot.joint("r_knee").servo_id
        assert abs(state[knee].load or 0) > 5  # the knees carry the robot
        for sid, s in state.items():
            assert abs(s.position - rest[sid]) <= 20, sid  # stiff: < 0.03 rad of sag
            assert s.errors == frozenset()


def test_a_joint_moves_no_faster_than_its_max_speed(bus: MujocoBus) -> None:
    """The goal is slewed at max_speed_rad_s, so the joint cannot arrive sooner than that
    allows; a soft servo lags its goal and catches up a little faster (overshoot), but
    never faster than its motor's no-load speed at the supply voltage."""
    bus.set_torque(ROBOT.ids, enabled=True)
    j = ROBOT.joint("r_shoulder_pitch")
    i = SM.index(j.name)
    target = SM.vector(ROBOT.rest)
    target[i] = -1.5
    goals = SM.goals(target)
    dt = 0.01
    qs = []
    for _ in range(80):
        bus.write_goals(goals)
        bus.clock.sleep_until(bus.clock.now() + dt)
        qs.append(SM.to_rad([bus.read_positions([j.servo_id])[j.servo_id]])[0])
    speed = np.abs(np.diff(qs)) / dt
    tick = 2 * math.pi / SM.resolution[i]
    top = ROBOT.servo_physics(j).no_load_speed(ROBOT.voltage(j))   # [rad/s]
    assert speed.max() <= top + 2 * tick / dt
    assert speed.max() > 0.8 * j.max_speed_rad_s  # it does slew at about full speed
    travel = abs(-1.5 - ROBOT.rest.get(j.name, 0.0))
    arrived = np.flatnonzero(np.abs(np.array(qs) - qs[0]) >= 0.9 * travel)[0]
    assert (arrived + 1) * dt >= 0.9 * travel / j.max_speed_rad_s - 2 * dt
    assert qs[-1] == pytest.approx(-1.5, abs=0.02)  # and gets there


def test_torque_off_makes_the_robot_collapse(bus: MujocoBus) -> None:
    bus.set_torque(ROBOT.ids, enabled=True)
    _hold(bus, REST, 0.5)
    assert bus.base_pose()[0][2] > 0.95 * bus.standing_height
    bus.set_torque(ROBOT.ids, enabled=False)
    _hold(bus, REST, 2.0)
    assert bus.base_pose()[0][2] < 0.6 * bus.standing_height
    assert all(s.load == 0 for s in bus.read_state(ROBOT.ids).values())


def test_saturated_servo_reports_overload_and_warms(bus: MujocoBus) -> None:
    """An internal 2 N m torque across the right elbow (> 1.4 N m stall) saturates it."""
    bus.set_torque(ROBOT.ids, enabled=True)
    elbow = ROBOT.joint("r_elbow").servo_id
    fore, upper = bus.model.body("r_forearm").id, bus.model.body("r_upper_arm").id
    bus.data.xfrc_applied[fore, 4] = 2.0
    bus.data.xfrc_applied[upper, 4] = -2.0
    _hold(bus, REST, 0.5)
    assert bus.read_state([elbow])[elbow].errors == frozenset()  # not yet: needs > 1 s
    _hold(bus, REST, 1.0)
    state = bus.read_state(ROBOT.ids)
    assert state[elbow].errors == {"overload"}
    assert abs(state[elbow].load or 0) == pytest.approx(100, abs=0.5)
    assert (state[elbow].temperature or 0) > AMBIENT_C + 0.1
    assert all(not s.errors for sid, s in state.items() if sid != elbow)
    bus.data.xfrc_applied[:] = 0
    _hold(bus, REST, 0.3)
    assert bus.read_state([elbow])[elbow].errors == frozenset()


def test_clock_advances_the_sim_exactly_to_the_deadline(bus: MujocoBus) -> None:
    clock = bus.clock
    assert clock.now() == 0.0
    clock.sleep_until(0.0123)  # not a multiple of the 2 ms step
    assert clock.now() == 0.0123 and bus.data.time == 0.0123
    clock.sleep_until(0.01)  # in the past: no-op
    assert clock.now() == 0.0123
    clock.sleep_until(1.0)
    assert clock.now() == 1.0


def test_realtime_waits_on_the_wall_clock() -> None:
    with MujocoBus(ROBOT, realtime=True) as b:
        assert isinstance(b, MujocoBus)
        start = time.monotonic()
        b.clock.sleep_until(0.2)
        assert time.monotonic() - start >= 0.19
        assert b.clock.now() == 0.2


def test_start_pose_stands_on_the_floor() -> None:
    robot = ROBOT
    pose = {"r_knee": 0.6, "l_knee": 0.6, "r_hip_pitch": -0.3, "l_hip_pitch": -0.3,
            "r_ankle_pitch": -0.3, "l_ankle_pitch": -0.3}
    with MujocoBus(robot, pose=pose) as b:
        assert isinstance(b, MujocoBus)
        assert b.read_positions(robot.ids) == SM.goals(SM.vector(pose))
        assert b.data.site("r_sole").xpos[2] == pytest.approx(0.0, abs=1e-9)
        assert b.base_pose()[0][2] > b.standing_height  # less crouched than rest
    with pytest.raises(BusError, match="unknown joint 'r_tail'"):
        MujocoBus(robot, pose={"r_tail": 0.0}).open()


def test_view_without_a_display_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    b = MujocoBus(ROBOT, view=True)
    with pytest.raises(BusError, match="--view needs a display"):
        b.open()
    assert not b.is_open


def test_view_with_an_unreachable_display_is_a_clear_error(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """MuJoCo's viewer would exit the process; the bus checks the display first."""
    monkeypatch.setenv("DISPLAY", ":4321")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(BusError, match="cannot open display ':4321'"):
        MujocoBus(ROBOT, view=True).open()


def test_render_of_the_home_pose_is_not_blank(bus: MujocoBus) -> None:
    img = bus.render(160, 120)
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    assert img.std() > 10
    bus.clock.sleep_until(0.1)
    again = bus.render(160, 120)
    assert again.std() > 10
    with pytest.raises(BusError, match="no camera 'nope'"):
        bus.render(160, 120, camera="nope")
