"""Robots other than the bundled 18-joint one (docs/robots.md): legs only (12 joints),
5-DoF legs (no hip yaw), extra joints held at a fixed angle (a head), mixed servo models."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
from five_dof import HEAD_RAD, LEGS, five_dof_with_head

from robot.bus.servo_map import ServoMap
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.gait import expressions as gaitmod
from robot.gait.engine import GaitEngine
from robot.gait.ik import leg_fk_full
from robot.gait.targets import body_targets
from robot.loop.streamer import Streamer, Telemetry
from sim.mujoco.bus import MujocoBus
from sim.mujoco.mjcf import build_mjcf


@pytest.fixture
def five(tmp_path: Path) -> RobotConfig:
    return load_robot(five_dof_with_head(tmp_path))


def test_legs_only_robot_loads_and_has_twelve_joints() -> None:
    r = load_robot(LEGS)
    assert len(r.joints) == 12 and not r.has_arms and r.has_hip_yaw
    assert r.mass.total == pytest.approx(0.85 + 2 * (0.06 + 0.07 + 0.12 + 0.12 + 0.06 + 0.08))


def test_five_dof_legs_reach_their_targets_with_yaw_zero(five: RobotConfig) -> None:
    """FK of each 5-DoF leg (hip yaw 0) lands on the sole target built without yaw, for a
    whole stride, even when a turn is asked for (it steers by step length: no joint yaws). Not
    exactly: a pitched foot under a rolled hip would need a trace of yaw; dropping it
    misses by micrometres."""
    params = load_gait("walk").params.replace({"turn": 0.4})
    engine = GaitEngine(five, params)
    engine.start()
    g = five.geometry
    worst = 0.0
    for _ in range(300):
        q = dict(zip(five.joint_names, engine.tick(0.01), strict=True))
        ch = gaitmod.channels(engine.phase, engine.live_params, amplitude=engine.amplitude)
        t = body_targets(ch, engine.live_params, g, amplitude=engine.amplitude, leg_yaw=False)
        for side, sole in (("r", t.r_sole), ("l", t.l_sole)):
            leg = (0.0, *(q[f"{side}_{j}"] for j in ("hip_roll", "hip_pitch", "knee",
                                                      "ankle_pitch", "ankle_roll")))
            p, _ = leg_fk_full(g, side, leg)
            miss = float(np.linalg.norm(np.asarray(p, float) - np.asarray(sole, float)))
            worst = max(worst, miss)
        assert q["head_pan"] == HEAD_RAD
    assert worst < 1e-4                       # [m]: 0.1 mm


def test_five_dof_legs_need_no_hip_yaw_mass(five: RobotConfig, tmp_path: Path) -> None:
    """The file has no mass.hip_yaw_link: the robot's mass is the rest of the links, and the
    simulated model weighs that much less than the same file with the 0.06 kg link back in
    (MuJoCo's own body masses, summed)."""
    path = five_dof_with_head(tmp_path)
    assert "hip_yaw_link" not in path.read_text()
    legs = load_robot(LEGS)
    assert five.mass.hip_yaw_link == 0.0
    assert five.mass.total == pytest.approx(legs.mass.total - 2 * legs.mass.hip_yaw_link)
    with_link = tmp_path / "with_link.toml"
    with_link.write_text(path.read_text().replace("[mass]", "[mass]\nhip_yaw_link = 0.06", 1))
    heavy = build_mjcf(load_robot(with_link)).model()
    model = build_mjcf(five).model()
    assert model.body("r_hip_yaw_link").mass[0] == 0.0
    assert float(heavy.body_mass.sum() - model.body_mass.sum()) == pytest.approx(0.12)
    six = tmp_path / "six.toml"
    six.write_text(re.sub(r"(?m)^hip_yaw_link = .*\n", "", LEGS.read_text()))
    with pytest.raises(ConfigError, match=r"mass\.hip_yaw_link: missing \(the robot has hip "
                                          r"yaw joints"):
        load_robot(six)


def test_six_dof_legs_do_turn(tmp_path: Path) -> None:
    """The oracle for the test above: with hip yaw the same turn does yaw the hips."""
    engine = GaitEngine(load_robot(LEGS), load_gait("walk").params.replace({"turn": 0.4}))
    engine.start()
    yaws = [engine.tick(0.01)[0] for _ in range(300)]
    assert max(abs(y) for y in yaws) > 0.05


def test_curves_hold_the_extra_joint(five: RobotConfig) -> None:
    _, q = GaitEngine(five, load_gait("walk").params).curves(np.linspace(0, 2, 200))
    assert q.shape == (len(five.joints), 200)
    assert np.all(q[five.joint_names.index("head_pan")] == HEAD_RAD)


def test_mixed_models_in_the_simulation(five: RobotConfig) -> None:
    model = build_mjcf(five).model()
    knee = model.actuator("r_knee").id
    hip = model.actuator("r_hip_pitch").id
    # XM430-W350 stalls at 4.1 N m, XL430-W250 at 1.4 N m (ROBOTIS e-Manual).
    assert model.actuator_forcerange[knee, 1] > 2 * model.actuator_forcerange[hip, 1]
    assert model.actuator("head_pan").id == len(five.joints) - 1   # actuators in joint order
    with pytest.raises(KeyError):
        model.joint("r_hip_yaw")                                   # 5-DoF: no such joint
    bus = MujocoBus(five)
    with bus:
        models = {s.id: s.model for s in bus.scan(range(30))}
    assert models[five.joint("r_knee").servo_id] == 1020          # XM430-W350
    assert models[five.joint("r_hip_pitch").servo_id] == 1060     # XL430-W250
    assert models[20] == 1060


def test_five_dof_robot_with_head_walks_in_sim(five: RobotConfig) -> None:
    bus = MujocoBus(five)
    heads: list[float] = []
    with bus:
        def watch(tel: Telemetry) -> None:
            if tel.state == "walking":
                heads.append(float(bus.data.qpos[bus.model.joint("head_pan").qposadr[0]]))
        stats = Streamer(ServoMap(five), bus, GaitEngine(five, load_gait("walk").params),
                         observer=watch).run(seconds=6)
        height, standing = float(bus.base_pose()[0][2]), bus.standing_height
    assert stats.stop_reason == "completed"
    assert height > 0.8 * standing                                 # still up
    assert heads and np.allclose(heads, HEAD_RAD, atol=0.02)       # held at its angle


@pytest.mark.parametrize(("edit", "needle"), [
    (lambda s: s.replace("[rest]", "[joints.r_hip_yaw]\nservo_id = 1\nsign = 1\nzero_ticks = "
                                   "2048\nmin_rad = -0.6\nmax_rad = 0.6\nmax_speed_rad_s = 5.0"
                                   "\n\n[rest]"),
     "joints.l_hip_yaw: missing (hip yaw on both legs, or neither"),
    (lambda s: s.replace("fixed_rad = 0.3\n", ""),
     "joints.head_pan: unknown joint; the gait drives"),
    (lambda s: s.replace("[joints.r_knee]\n", "[joints.r_knee]\nfixed_rad = 0.5\n"),
     "joints.r_knee.fixed_rad: the gait drives r_knee"),
    (lambda s: s.replace("fixed_rad = 0.3", "fixed_rad = 2.0"),
     "joints.head_pan.fixed_rad: 2 is outside the joint limits [-1, 1]"),
    (lambda s: s.replace('model = "XM430-W350"', 'model = "STS3215"', 1),
     "joints.r_knee.model: 'STS3215' is not a dynamixel servo model; valid: XL430-W250"),
    (lambda s: s.replace("[joints.head_pan]", "[joints.Head-Pan]"),
     "joints.Head-Pan: not a joint name"),
])
def test_bad_own_robot_files(tmp_path: Path, edit, needle: str) -> None:  # type: ignore[no-untyped-def]
    path = five_dof_with_head(tmp_path)
    path.write_text(edit(path.read_text()))
    with pytest.raises(ConfigError) as e:
        load_robot(path)
    assert needle in str(e.value) and "\n" not in str(e.value)


def test_arms_need_their_geometry(tmp_path: Path) -> None:
    s = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
    path = tmp_path / "r.toml"
    path.write_text(re.sub(r"(?m)^upper_arm = 0\.08.*\n", "", s))
    with pytest.raises(ConfigError, match=r"geometry\.upper_arm: missing \(the robot has arms\)"):
        load_robot(path)
    assert mujoco is not None


def test_mixed_models_on_the_emulated_chain(five: RobotConfig, tmp_path: Path) -> None:
    """The pty emulator serves each joint's own model: a scan with the real SDK reports the
    XM430 knees (model number 1020, ROBOTIS e-Manual) among XL430s (1060)."""
    from robot.bus.factory import make_bus
    from sim.emulator.chain import Emulator

    with Emulator("dynamixel", five) as emu:
        bus = make_bus("dynamixel", robot=five, port=emu.port, timeout_ms=50.0)
        bus.open()
        try:
            found = {s.id: s.model for s in bus.scan(five.ids)}
        finally:
            bus.close()
    assert found[five.joint("l_knee").servo_id] == 1020
    assert found[five.joint("l_hip_roll").servo_id] == 1060
    assert found[20] == 1060
