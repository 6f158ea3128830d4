"""A stop that finishes its step (robot.gait.stop_close, issue 32 item 5): the ramp-out's
stages by hand, the engine's envelope against the feet's lift, the stop's heading measured
from the walk's own heading (sim.mujoco.metrics), and real stops in MuJoCo that end on
the heading they walked, unbraced (the 16 stop phases of every robot: robot.bench.stops,
in `biped bench --only sim`)."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import pytest

from robot.bench.stops import STOP_HEADING_DEG, stop_walk
from robot.bench.variants import write_five_dof
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import ENVELOPE_MIN_RATE, GaitEngine
from robot.gait.stop_close import CLOSE_SHARE, ramp_out, swing_share
from robot.gait.targets import BodyTrim
from sim.mujoco.metrics import WalkMonitor

WALK = load_gait("walk").params
DT = 0.005


def test_a_foot_is_up_for_its_share_of_the_cycle() -> None:
    """delta_f -0.25: the right foot is up while sin(theta) > 0.25, from asin(0.25) to
    pi - asin(0.25): (pi - 2 x 0.25268) / (2 pi) = 0.41957 of the cycle."""
    assert swing_share(WALK) == pytest.approx(0.41957, abs=1e-5)
    assert swing_share(WALK.replace({"delta_f": 0.0})) == pytest.approx(0.5)


def test_the_ramp_out_finishes_the_swing_then_closes_within_the_next() -> None:
    stage, ramp = ramp_out(None, 1.0, DT, True, WALK, least=0.0)           # told to stop mid-swing
    assert (stage, ramp) == ("finish", 1.0)
    stage, ramp = ramp_out(stage, ramp, DT, False, WALK, least=0.0)   # it lands
    assert (stage, ramp) == ("close", 1.0)
    assert ramp_out(stage, ramp, DT, False, WALK, least=0.0) == ("close", 1.0)  # holds
    swing = CLOSE_SHARE * swing_share(WALK) * WALK.cycle_s
    stage, ramp = ramp_out(stage, ramp, DT, True, WALK, least=0.0)  # the next one lifts
    assert ramp == pytest.approx(1.0 - DT / swing)
    assert ramp_out(None, 0.5, DT, False, WALK, least=0.0) == ("close", 0.5)  # both down
    # The least fall: a stop whose feet never lift again still ends.
    assert ramp_out("close", 0.5, DT, False, WALK, least=0.01) == ("close", 0.49)
    assert ramp_out("finish", 0.5, DT, True, WALK, least=0.01)[1] == 0.49


def test_the_engine_stops_on_both_feet_within_one_swing_after_the_one_in_progress() -> None:
    robot = load_robot("biped18-dynamixel")
    e = GaitEngine(robot, WALK)
    e.trim = BodyTrim(close=1.0)
    e.start()
    for _ in range(int(round(5.25 * WALK.cycle_s / DT))):   # full stride, right foot mid-swing
        e.tick(DT)
    assert e.amplitude == 1.0 and e.lift[0] > 0.0 and e.lift[1] == 0.0
    e.stop()
    swings: list[str] = []         # the feet in the air, tick by tick, until it stops
    amps = []
    while not e.stopped:
        e.tick(DT)
        swings.append("R" if e.lift[0] > 0 else "L" if e.lift[1] > 0 else "-")
        amps.append(e.amplitude)
        assert len(amps) < 400, "the stop took more than 2 s"
    runs = [s for i, s in enumerate(swings) if i == 0 or s != swings[i - 1]]
    assert runs[:3] == ["R", "-", "L"]           # the right swing lands, then the left closes
    first_left = swings.index("L")
    # Full stride until the close begins but for the engine's slowest ramp-out: at
    # ENVELOPE_MIN_RATE of its rate the ramp variable falls by under 0.07 over those ticks
    # (smoothstep: the amplitude by under 0.015).
    least = ENVELOPE_MIN_RATE * DT / (WALK.ramp_cycles * WALK.cycle_s)
    assert all(a >= 0.985 for a in amps[:first_left])
    assert amps[first_left - 1] == pytest.approx(
        1.0 - 3 * (first_left * least) ** 2 + 2 * (first_left * least) ** 3, abs=1e-9)
    # It reaches 0 inside the left swing: within CLOSE_SHARE of one swing's time.
    closing = len(amps) - first_left
    assert closing * DT <= swing_share(WALK) * WALK.cycle_s + DT
    assert e.pose() == pytest.approx(e.start_pose())     # feet side by side, both down


def test_a_stop_held_braced_with_both_feet_down_still_ends() -> None:
    """A robot lying braced on the ground (the phase held, no foot lifts again): the
    envelope falls at the engine's slowest rate, ENVELOPE_MIN_RATE of its own, and the
    stop ends within ramp_cycles / ENVELOPE_MIN_RATE cycles."""
    e = GaitEngine(load_robot("biped18-dynamixel"), WALK)
    e.start()
    for _ in range(int(round(5.0 * WALK.cycle_s / DT))):       # double support at 5 cycles
        e.tick(DT)
    assert e.lift == (0.0, 0.0)
    e.trim = BodyTrim(close=1.0, tempo=-1.0, land=1.0)
    e.stop()
    n = 0
    while not e.stopped:
        e.tick(DT)
        n += 1
        assert n * DT <= WALK.ramp_cycles * WALK.cycle_s / ENVELOPE_MIN_RATE + DT
    assert e.lift == (0.0, 0.0)


def test_the_stops_heading_is_measured_from_the_heading_the_walk_walked() -> None:
    """The torso yaws 2 deg each way with the steps around a heading of 10 deg: the stop's
    reference is the mean over the last cycle (right touchdown to right touchdown), 10
    deg, whatever tick the stop comes at."""
    for stop_tick in (0, 25, 50, 75):
        m = WalkMonitor(standing_height=0.3)
        n = 100                                     # ticks per cycle
        for k in range(3 * n + stop_tick):
            yaw = math.radians(10.0 + 2.0 * math.sin(2 * math.pi * k / n))
            m.update_qpos(k * 0.01, [0.0, 0.0, 0.3, math.cos(yaw / 2), 0.0, 0.0,
                                     math.sin(yaw / 2)])
            m.walking(right_landed=k % n == 0)
        m.mark_stop(0.0)
        assert m.stop_heading is not None
        # m.heading counts from the first tick's yaw (10 deg, sin 0 = 0)
        assert math.degrees(m.stop_heading) == pytest.approx(0.0, abs=0.02), stop_tick


@pytest.mark.parametrize("robot", ["biped18-dynamixel", "biped18-lx 5-DoF"])
def test_a_stop_ends_on_the_heading_it_walked_unbraced(robot: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = (str(write_five_dof(robot.split()[0], Path(folder)))
                if robot.endswith("5-DoF") else robot)
        for phase in (0.0, 0.5):
            r = stop_walk(path, phase)
            assert not r["fell"], r
            assert abs(r["stop_heading_deg"]) <= STOP_HEADING_DEG, r
            assert r["stop_braced_s"] == 0.0, r
