"""Live steering within the documented ranges keeps the robot up: the joint steering
budget (robot.gait.engine.STEER_BUDGET) and a seeded random sequence of panel-style changes
walked in MuJoCo with balance on."""

from __future__ import annotations

import random

import pytest

from robot.balance.stage import Balance, attitude_reader
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.params import SPECS, GaitParams
from robot.config.robot_file import load_robot
from robot.gait.engine import STEER_BUDGET, GaitEngine, within_steering_budget
from robot.imu import open_imu
from robot.loop.streamer import Streamer, Telemetry
from sim.mujoco.bus import MujocoBus
from sim.mujoco.metrics import WalkMonitor

WALK = load_gait("walk").params


def used(p: GaitParams) -> float:
    """The budget a steering set uses, written out by hand from the ranges."""
    speed = p.speed / 1.5 if p.speed > 0 else -p.speed / 1.0
    return speed + abs(p.turn) / 0.5 + abs(p.side_step) / 0.025


def test_the_ranges_the_budget_is_written_against() -> None:
    assert (SPECS["speed"].lo, SPECS["speed"].hi) == (-1.0, 1.5)
    assert (SPECS["turn"].lo, SPECS["turn"].hi) == (-0.5, 0.5)
    assert (SPECS["side_step"].lo, SPECS["side_step"].hi) == (-0.025, 0.025)


@pytest.mark.parametrize("change", [{"speed": 1.5}, {"speed": -1.0},
                                    {"speed": 0.0, "turn": -0.5},
                                    {"speed": 0.0, "side_step": 0.025},
                                    {"speed": 1.0, "turn": 0.29}])
def test_steering_inside_the_budget_is_left_alone(change: dict[str, float]) -> None:
    p = WALK.replace(change)
    assert within_steering_budget(p) is p


@pytest.mark.parametrize("change", [{"speed": 1.5, "turn": 0.5},
                                    {"speed": -1.0, "side_step": -0.025, "turn": 0.2},
                                    {"speed": 1.0, "turn": 0.4, "side_step": -0.025}])
def test_a_combination_beyond_it_is_scaled_down_alike(change: dict[str, float]) -> None:
    p = WALK.replace(change)
    q = within_steering_budget(p)
    assert used(q) == pytest.approx(STEER_BUDGET)
    k = STEER_BUDGET / used(p)
    assert (q.speed, q.turn, q.side_step) == pytest.approx((p.speed * k, p.turn * k,
                                                            p.side_step * k))
    assert q.replace({"speed": p.speed, "turn": p.turn, "side_step": p.side_step}) == p


def test_the_engine_walks_the_budgeted_steering_and_reports_what_was_set() -> None:
    robot = load_robot("biped18-dynamixel")
    engine = GaitEngine(robot, WALK)
    engine.set_params({"speed": 1.5, "turn": 0.5})
    assert engine.params.speed == 1.5                      # what the user set
    assert used(engine.live_params) == pytest.approx(STEER_BUDGET)   # what it walks


@pytest.mark.parametrize("seed", [3])
def test_a_random_sequence_of_live_steering_changes_keeps_the_robot_up(seed: int) -> None:
    """Every 0.2-3 s one of speed, turn, side step jumps to an end of its range, zero
    or a random value (as a panel user dragging sliders would); 20 s with balance on."""
    robot = load_robot("biped18-dynamixel")
    assert robot.imu is not None
    rng = random.Random(seed)
    plan, t = [], 1.0
    while t < 20.0:
        name = rng.choice(["speed", "turn", "side_step"])
        lo, hi = SPECS[name].lo, SPECS[name].hi
        plan.append((t, name, rng.choice([lo, hi, 0.0, rng.uniform(lo, hi)])))
        t += rng.uniform(0.2, 3.0)
    bus = MujocoBus(robot)
    bus.open()
    engine = GaitEngine(robot, WALK)
    imu = open_imu(robot.imu, bus=bus)
    imu.open()
    monitor = WalkMonitor(standing_height=bus.standing_height, floor_normal=bus.floor_normal)
    todo = list(plan)
    t0: list[float] = []
    streamer: Streamer

    def observe(tel: Telemetry) -> None:
        monitor.update_qpos(tel.t, bus.data.qpos[:7].tolist())
        if tel.state != "walking":
            return
        t0 or t0.append(tel.t)
        while todo and todo[0][0] <= tel.t - t0[0]:
            _, name, value = todo.pop(0)
            streamer.set_params({name: value})
    streamer = Streamer(ServoMap(robot), bus, engine, observer=observe,
                        feedback=Balance(engine, attitude_reader(imu)))
    try:
        stats = streamer.run(seconds=20.0)
    finally:
        imu.close()
        bus.close()
    assert not todo and len(plan) >= 10
    assert stats.stop_reason == "completed" and not stats.fault
    assert not monitor.fell, f"fell at {monitor.fell_at} s; plan {plan}"
