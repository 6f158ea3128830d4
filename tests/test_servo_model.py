"""The servo model (robot/servo/physics.py, firmware.py, the table) against the manuals, the
datasheets and the recordings, measured on the simulated servo (MuJoCo), not read back
from the model's own formulas.

Oracles: the e-Manual's X-series register scale (KPP = P / 128 on the error in pulses, PWM
885 = full duty), the AX-12A manual's compliance slope, each datasheet's stall torque and
no-load speed, and the XL330 recordings' own Present PWM column.
"""

from __future__ import annotations

import gzip
import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robot.config.robot_file import load_robot
from robot.config.servo_file import physics_for
from robot.servo.models import MODELS
from robot.servo.physics import ServoPhysics
from robot.servo.physics_table import PHYSICS
from sim.mujoco.servo_law import ServoArrays

#: Rhoban/bam's recordings, published data kept beside the repository (not in it).
DATA = Path(__file__).resolve().parents[1].parent / "shared" / "servo_logs" / "bam"


def _one_servo(physics: ServoPhysics, gains: dict[str, int], voltage: float,
               inertia: float = 1e-4) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """A bare servo horn (no gravity) driven by ``physics`` at ``gains`` and ``voltage``,
    torque on."""
    xml = f"""<mujoco><option gravity="0 0 0" timestep="0.0005" integrator="implicitfast"/>
      <worldbody><body><joint name="q" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 0" mass="0.01" diaginertia="{inertia} {inertia} {inertia}"/>
      </body></worldbody><actuator><position joint="q" kp="0"/></actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    arrays = ServoArrays([(MODELS[physics.name], physics, gains, voltage)])
    idx = np.array([0])
    arrays.install(model, idx, idx)
    arrays.set_torque(model, idx, idx, np.array([True]))
    return model, data


def _measured_stiffness(physics: ServoPhysics, gains: dict[str, int], voltage: float) -> float:
    """Torque per radian of error the simulated servo pushes with, at 0.005 rad error."""
    model, data = _one_servo(physics, gains, voltage)
    data.ctrl[0] = 0.005
    mujoco.mj_forward(model, data)
    return float(data.actuator_force[0]) / 0.005


def test_every_model_has_physics_with_a_source_for_every_number() -> None:
    assert set(PHYSICS) == set(MODELS)
    for name in MODELS:
        physics = physics_for(name)
        assert physics.name == name
        assert physics.law == MODELS[name].gain_set, name
        assert physics.unsourced() == [], name


@pytest.mark.parametrize("name", ["XL430-W250", "XM430-W350", "XC430-W150"])
def test_x_series_stiffness_is_the_manuals_register_scale(name: str) -> None:
    """e-Manual (X series, Position P Gain): KPP = P / 128 acts on the error in pulses and
    885 is full duty; full duty gives the datasheet's stall torque. So at small error the
    output stiffness is P / 128 * (4096 / 2 pi) / 885 * stall torque [N m/rad]."""
    m = MODELS[name]
    p_gain = 640
    expected = p_gain / 128 * (4096 / (2 * math.pi)) / 885 * m.stall_torque
    gains = {**m.factory_gains, "position_p_gain": p_gain, "position_d_gain": 0}
    measured = _measured_stiffness(PHYSICS[name], gains, m.nominal_voltage)
    assert measured == pytest.approx(expected, rel=1e-6)


def test_xl430_factory_gains_are_4_to_10_times_softer_than_the_old_sim() -> None:
    """The issue's figures: XL430 P 640 is ~5.2 N m/rad by the manual's scale; the old sim
    servo was stall / 0.05 rad = 28 N m/rad."""
    m = MODELS["XL430-W250"]
    measured = _measured_stiffness(PHYSICS["XL430-W250"], dict(m.factory_gains), 11.1)
    assert measured == pytest.approx(5.16, abs=0.01)
    assert 4 < (m.stall_torque / 0.05) / measured < 10


def test_ax12_stiffness_is_the_compliance_slope() -> None:
    """AX-12A e-Manual: the output reaches full torque over the compliance slope [pulses]
    beyond the margin; 1024 pulses span 300 deg. Slope 32: stall / (32 * 300/1024 deg)."""
    m = MODELS["AX-12A"]
    expected = m.stall_torque / math.radians(32 * 300 / 1024)
    measured = _measured_stiffness(PHYSICS["AX-12A"], dict(m.factory_gains), 12.0)
    assert measured == pytest.approx(expected, rel=1e-6)


def test_xl330_recordings_show_the_identified_register_scale() -> None:
    """The XL330 logs record Present PWM: it is P / 256 (not the manual's 128) times the
    error in pulses, of 885. The bundled XL330-M288 model runs that scale."""
    ratios = []
    for path in sorted((DATA / "xl330").glob("*.json.gz")):
        log = json.loads(gzip.decompress(path.read_bytes()))
        for e in log["entries"][::25]:
            pwm = e["load"] - 65536 if e["load"] > 32767 else e["load"]
            error_pulses = (e["goal_position"] - e["position"]) * 4096 / (2 * math.pi)
            expected = log["kp"] / 256 * error_pulses
            if e["torque_enable"] and 50 < abs(expected) < 800:   # clear of noise and 885
                ratios.append(pwm / expected)
    assert len(ratios) > 100
    assert np.median(ratios) == pytest.approx(1.0, abs=0.03)
    physics = physics_for("XL330-M288")
    m = MODELS["XL330-M288"]
    duty_per_rad = 400 / 256 * (4096 / (2 * math.pi)) / 885
    expected = duty_per_rad * physics.stall_torque(7.4) / physics.max_duty
    measured = _measured_stiffness(physics, {"position_p_gain": 400}, 7.4)
    assert measured == pytest.approx(expected, rel=1e-6)
    assert m.gain_set == "dynamixel_x"


@pytest.mark.parametrize("name", ["XL430-W250", "AX-12A", "MX-28", "STS3032"])
def test_datasheet_models_stall_and_run_at_their_datasheet_figures(name: str) -> None:
    """A datasheet model at its nominal voltage, driven at full duty: the torque against
    a locked horn is the stall torque, and the free horn's top speed is the no-load speed
    (where the drive meets the back-EMF and the gearbox's friction)."""
    m = MODELS[name]
    physics = PHYSICS[name]
    gains = dict(m.factory_gains)
    model, data = _one_servo(physics, gains, m.nominal_voltage)
    data.ctrl[0] = 3.0                           # far from the horn: full duty
    mujoco.mj_forward(model, data)
    assert data.actuator_force[0] == pytest.approx(m.stall_torque, rel=1e-6)
    for _ in range(4000):                        # 2 s: the horn reaches its top speed
        data.ctrl[0] = data.qpos[0] + 3.0
        mujoco.mj_step(model, data)
    speed = float(data.qvel[0])
    assert speed == pytest.approx(m.no_load_speed, rel=0.01)


def test_stall_torque_and_speed_follow_the_bus_voltage(tmp_path: Path) -> None:
    """torque = kt (V duty - kt w) / R: the stall torque scales with the supply in the
    robot file ([bus] voltage), and so does the simulated servo's force limit."""
    from sim.mujoco.servo_law import robot_servos

    src = Path(load_robot("biped18-dynamixel").source).read_text()
    low = tmp_path / "low.toml"
    low.write_text(src.replace('[bus]\n', '[bus]\nvoltage = 7.4\n', 1))
    nominal = robot_servos(load_robot("biped18-dynamixel"))
    reduced = robot_servos(load_robot(low))
    assert nominal.force[0] == pytest.approx(1.4, rel=1e-9)          # datasheet, 11.1 V
    assert reduced.force[0] == pytest.approx(1.4 * 7.4 / 11.1, rel=1e-9)
    assert reduced.kp[0] == pytest.approx(nominal.kp[0] * 7.4 / 11.1, rel=1e-9)
    assert reduced.back_emf[0] == pytest.approx(nominal.back_emf[0])  # kt^2/R: no voltage
