"""A robot without ankle roll (5-DoF legs as the Open Duck Mini's: hip yaw, roll, pitch,
knee, ankle pitch): its file loads, the joint rules name what is missing, the gait puts
the soles where it asks with the foot's heading and pitch (robot.gait.ik_chain), the
simulation runs it, and the balance stage sends its ankle roll correction to the hip
roll."""

from __future__ import annotations

import dataclasses
import re
import tomllib

import numpy as np
import pytest
from five_dof import five_dof_text, no_ankle_roll_robot, no_ankle_roll_text

from robot.balance.law import Correction
from robot.balance.stage import JointSlots, apply
from robot.bus.servo_map import ServoMap
from robot.config.gait_file import load_gait
from robot.config.robot_file import parse_robot
from robot.errors import ConfigError
from robot.gait import expressions as gaitmod
from robot.gait.engine import GaitEngine
from robot.gait.ik import leg_fk_full
from robot.gait.ik_chain import check_layout
from robot.gait.targets import body_targets
from robot.loop.streamer import Streamer
from sim.mujoco.bus import MujocoBus
from sim.mujoco.mjcf import build_mjcf

LEG = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch")


def test_it_loads_with_ten_leg_joints_and_its_own_chains() -> None:
    robot = no_ankle_roll_robot()
    assert len(robot.joints) == 10 and robot.has_hip_yaw and not robot.has_ankle_roll
    assert robot.layout is not None and len(robot.layout) == 10
    for leg in robot.legs:
        assert not leg.has_ankle_roll and not leg.simple
        check_layout(leg)


def test_the_gait_puts_the_soles_on_target_keeping_heading_and_pitch() -> None:
    """The box model's own FK (robot.gait.ik.leg_fk_full, ankle roll 0) at the engine's
    angles: each sole where the gait's targets put it, the foot's x axis as asked, while
    turning and with a toe tipped by the gait."""
    robot = no_ankle_roll_robot()
    params = load_gait("walk").params.replace({"turn": 0.3, "toe_gain": 0.3})
    engine = GaitEngine(robot, params)
    engine.start()
    g = robot.geometry
    worst = [0.0, 0.0]
    for _ in range(300):
        q = dict(zip(robot.joint_names, engine.tick(0.01), strict=True))
        ch = gaitmod.channels(engine.phase, engine.live_params, amplitude=engine.amplitude)
        t = body_targets(ch, engine.live_params, g, amplitude=engine.amplitude, leg_yaw=True)
        for side, sole, foot in (("r", t.r_sole, t.r_foot), ("l", t.l_sole, t.l_foot)):
            pos, rot = leg_fk_full(g, side, (*(q[f"{side}_{j}"] for j in LEG), 0.0))
            worst[0] = max(worst[0], float(np.abs(np.subtract(pos, sole)).max()))
            x_axis = np.subtract(np.array(rot).reshape(3, 3)[:, 0],
                                 np.array(foot, float).reshape(3, 3)[:, 0])
            worst[1] = max(worst[1], float(np.abs(x_axis).max()))
    assert worst[0] < 1e-9 and worst[1] < 1e-9, worst


def test_the_simulation_runs_it_without_ankle_roll_joints() -> None:
    """MuJoCo's model has no ankle roll joint, and the gait's rhythm with the feet kept
    down (no lift: the stance sole tips by the hip roll when the other foot is up, which
    the walk preset's gait does not plan for) keeps it standing."""
    robot = no_ankle_roll_robot()
    model = build_mjcf(robot).model()
    with pytest.raises(KeyError):
        model.joint("r_ankle_roll")
    bus = MujocoBus(robot)
    with bus:
        params = load_gait("walk").params.replace({"Fhgt_R": 0.0, "Fhgt_L": 0.0})
        stats = Streamer(ServoMap(robot), bus, GaitEngine(robot, params)).run(seconds=5)
        height, standing = float(bus.base_pose()[0][2]), bus.standing_height
    assert stats.stop_reason == "completed"
    assert height > 0.95 * standing


def test_the_ankle_roll_correction_goes_to_the_hip_roll() -> None:
    names = no_ankle_roll_robot().joint_names
    slots = JointSlots.of(names)
    hips = [names.index("r_hip_roll"), names.index("l_hip_roll")]
    assert slots.ankle_roll == hips == slots.hip_roll
    q = np.zeros(len(names))
    out = apply(q, Correction(ankle_roll=0.02, hip_roll=0.005, ankle_pitch=0.01), slots)
    assert out[hips].tolist() == [0.025, 0.025]
    assert out[names.index("r_ankle_pitch")] == 0.01


@pytest.mark.parametrize(("edit", "needle"), [
    (lambda s: s.replace("[rest]", "[joints.r_ankle_roll]\nservo_id = 6\nsign = 1\n"
                                   "zero_ticks = 2048\nmin_rad = -0.6\nmax_rad = 0.6\n"
                                   "max_speed_rad_s = 5.0\n\n[rest]"),
     "joints.l_ankle_roll: missing (ankle roll on both legs, or neither for 5-DoF legs)"),
    (lambda s: re.sub(r"(?ms)^\[joints\.[rl]_hip_yaw\].*?(?=^\[)", "", s).replace(
        "hip_yaw_link = ", "# "),
     "joints.r_hip_yaw: missing (a leg needs hip yaw or ankle roll"),
])
def test_the_joint_rules_name_what_is_missing(edit, needle: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError) as e:
        parse_robot(tomllib.loads(edit(no_ankle_roll_text())), source="r.toml")
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_leg_chains_must_match_the_joints() -> None:
    five = parse_robot(tomllib.loads(five_dof_text()), source="five.toml")   # no hip yaw
    chains = no_ankle_roll_robot().legs                                     # hip yaw
    with pytest.raises(ConfigError, match=r"five\.toml: leg_chains: the r leg's chain .*hip "
                                          r"yaw True, ankle roll False\) does not match"):
        dataclasses.replace(five, leg_chains=chains)
