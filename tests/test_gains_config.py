"""Gains and supply voltage in the robot file: ``[bus] voltage``, ``[bus.gains]``,
``[joints.<name>.gains]``, resolved by ``RobotConfig.gains`` / ``RobotConfig.voltage``.

Expected factory values are the manuals' "Initial Value" columns written out here (ROBOTIS
e-Manual XL430-W250 / XM430-W350 / XC430-W150 / AX-12A / AX-18A / MX-28 RAM tables; the
Feetech STS3215 memory table), not read from robot/servo/models.py."""

from __future__ import annotations

import copy
import re
from typing import Any

import pytest

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import parse_robot
from robot.config.toml_io import read_toml
from robot.errors import ConfigError
from robot.servo.gains import GAIN_SETS
from robot.servo.models import MODELS

#: The manuals' factory values.
MANUAL_FACTORY: dict[str, dict[str, int]] = {
    "XL430-W250": {"position_d_gain": 4000, "position_i_gain": 0, "position_p_gain": 640,
                   "profile_acceleration": 0, "profile_velocity": 0},
    "XM430-W350": {"position_d_gain": 0, "position_i_gain": 0, "position_p_gain": 800,
                   "profile_acceleration": 0, "profile_velocity": 0},
    "XC430-W150": {"position_d_gain": 0, "position_i_gain": 0, "position_p_gain": 460,
                   "profile_acceleration": 0, "profile_velocity": 0},
    "AX-12A": {"cw_compliance_margin": 1, "ccw_compliance_margin": 1,
               "cw_compliance_slope": 32, "ccw_compliance_slope": 32},
    "AX-18A": {"cw_compliance_margin": 1, "ccw_compliance_margin": 1,
               "cw_compliance_slope": 32, "ccw_compliance_slope": 32},
    "MX-28": {"d_gain": 0, "i_gain": 0, "p_gain": 32},
    "STS3215": {"p_coefficient": 32, "d_coefficient": 32, "i_coefficient": 0},
}


def robot_data(name: str) -> dict[str, Any]:
    return copy.deepcopy(read_toml(ROBOTS_DIR / f"{name}.toml"))


def error(data: dict[str, Any]) -> str:
    with pytest.raises(ConfigError) as e:
        parse_robot(data, source="r.toml")
    msg = str(e.value)
    assert "\n" not in msg
    return msg


@pytest.mark.parametrize("model", sorted(MANUAL_FACTORY))
def test_factory_gains_are_the_manuals(model: str) -> None:
    assert dict(MODELS[model].factory_gains) == MANUAL_FACTORY[model]


def test_every_model_has_a_gain_set_of_its_family_and_a_value_for_each_gain() -> None:
    for name, m in MODELS.items():
        gs = GAIN_SETS[m.gain_set]
        assert gs.family == m.family, name
        assert set(m.factory_gains) == set(gs.names), name
        for g, v in m.factory_gains.items():
            assert gs.gains[g].accepts(v), (name, g, v)


def test_gain_sets_name_the_manuals_registers_and_memory() -> None:
    assert GAIN_SETS["dynamixel_x"].names == ("position_d_gain", "position_i_gain",
                                              "position_p_gain", "profile_acceleration",
                                              "profile_velocity")
    assert GAIN_SETS["dynamixel_ax"].names == ("cw_compliance_margin", "ccw_compliance_margin",
                                               "cw_compliance_slope", "ccw_compliance_slope")
    assert GAIN_SETS["dynamixel_mx1"].names == ("d_gain", "i_gain", "p_gain")
    assert GAIN_SETS["feetech_sts"].names == ("p_coefficient", "d_coefficient",
                                              "i_coefficient")
    # Only the STS coefficients live in EEPROM; X, AX and MX gains are RAM.
    assert GAIN_SETS["feetech_sts"].eeprom == GAIN_SETS["feetech_sts"].names
    for name in ("dynamixel_x", "dynamixel_ax", "dynamixel_mx1"):
        assert GAIN_SETS[name].eeprom == ()
    x = GAIN_SETS["dynamixel_x"].gains
    assert (x["position_p_gain"].lo, x["position_p_gain"].hi) == (0, 16383)
    assert (x["profile_velocity"].lo, x["profile_velocity"].hi) == (0, 32767)


def test_without_gain_tables_every_joint_gets_its_models_factory_values() -> None:
    data = robot_data("biped18-dynamixel")
    data["bus"].pop("gains", None)      # the bundled file sets [bus.gains]: none here
    robot = parse_robot(data, source="r.toml")
    for j in robot.joints:
        assert dict(robot.gains(j)) == MANUAL_FACTORY["XL430-W250"]
        assert robot.voltage(j) == 11.1     # XL430-W250 datasheet: 11.1 V nominal


def test_precedence_factory_then_bus_then_joint() -> None:
    data = robot_data("biped18-dynamixel")
    data["bus"]["gains"] = {"position_p_gain": 300, "profile_velocity": 50}
    data["bus"]["voltage"] = 12.0
    data["joints"]["r_knee"]["gains"] = {"position_p_gain": 900}
    robot = parse_robot(data, source="r.toml")
    knee, hip = robot.joint("r_knee"), robot.joint("r_hip_pitch")
    assert dict(robot.gains(hip)) == {**MANUAL_FACTORY["XL430-W250"],
                                      "position_p_gain": 300, "profile_velocity": 50}
    assert dict(robot.gains(knee)) == {**MANUAL_FACTORY["XL430-W250"],
                                       "position_p_gain": 900, "profile_velocity": 50}
    assert robot.voltage(knee) == robot.voltage(hip) == 12.0


def test_a_joint_with_its_own_model_gets_that_models_factory_values() -> None:
    data = robot_data("biped18-dynamixel")
    data["bus"].pop("gains", None)      # the bundled file sets [bus.gains]: none here
    data["joints"]["r_knee"]["model"] = "XM430-W350"
    robot = parse_robot(data, source="r.toml")
    assert dict(robot.gains(robot.joint("r_knee"))) == MANUAL_FACTORY["XM430-W350"]
    assert robot.voltage(robot.joint("r_knee")) == 12.0    # XM430-W350 nominal
    assert robot.voltage(robot.joint("l_knee")) == 11.1


def test_ax_and_mx_on_one_protocol_1_bus() -> None:
    data = robot_data("biped18-ax12")
    data["joints"]["r_knee"].update(model="MX-28", zero_ticks=2048,
                                    gains={"p_gain": 16, "d_gain": 8})
    data["bus"]["gains"] = {"cw_compliance_slope": 64}
    with pytest.raises(ConfigError, match=r"r\.toml: bus\.gains\.cw_compliance_slope: not a "
                       r"gain of joints\.r_knee's servo MX-28 .*valid: d_gain \[0\.\.254\]"):
        parse_robot(data, source="r.toml")
    del data["bus"]["gains"]
    data["joints"]["l_knee"]["gains"] = {"ccw_compliance_slope": 128}
    robot = parse_robot(data, source="r.toml")
    assert dict(robot.gains(robot.joint("r_knee"))) == {"d_gain": 8, "i_gain": 0, "p_gain": 16}
    assert dict(robot.gains(robot.joint("l_knee"))) == {**MANUAL_FACTORY["AX-12A"],
                                                        "ccw_compliance_slope": 128}


@pytest.mark.parametrize(("where", "gains", "expected"), [
    ("bus", {"p_gain": 10},
     r"r\.toml: bus\.gains\.p_gain: not a gain of XL430-W250 \(gain set dynamixel_x\); valid: "
     r"position_d_gain \[0\.\.16383\], position_i_gain \[0\.\.16383\], position_p_gain "
     r"\[0\.\.16383\], profile_acceleration \[0\.\.32767\], profile_velocity \[0\.\.32767\]$"),
    ("bus", {"position_p_gain": 16384},
     r"r\.toml: bus\.gains\.position_p_gain: expected an integer in \[0, 16383\], got 16384$"),
    ("bus", {"position_p_gain": -1}, r"bus\.gains\.position_p_gain: expected an integer in"),
    ("bus", {"position_p_gain": 640.0}, r"bus\.gains\.position_p_gain: expected an integer"),
    ("bus", {"position_p_gain": "640"}, r"bus\.gains\.position_p_gain: expected an integer"),
    ("bus", 5, r"r\.toml: bus\.gains: expected a table, got 5$"),
    ("r_knee", {"profile_velocity": 40000},
     r"r\.toml: joints\.r_knee\.gains\.profile_velocity: expected an integer in \[0, 32767\]"),
    ("r_knee", {"cw_compliance_slope": 32},
     r"joints\.r_knee\.gains\.cw_compliance_slope: not a gain of XL430-W250"),
])
def test_bad_gains_are_one_line_errors(where: str, gains: object, expected: str) -> None:
    data = robot_data("biped18-dynamixel")
    (data["bus"] if where == "bus" else data["joints"][where])["gains"] = gains
    msg = error(data)
    assert re.search(expected, msg), msg


def test_sts_coefficients_range_and_voltage_range() -> None:
    data = robot_data("biped18-feetech")
    data["bus"]["gains"] = {"p_coefficient": 255}
    assert "bus.gains.p_coefficient: expected an integer in [0, 254], got 255" in error(data)
    data["bus"]["gains"] = {"p_coefficient": 16}
    data["bus"]["voltage"] = 40.0
    assert "bus.voltage: expected a number in [3, 30] V, got 40.0" in error(data)
    data["bus"]["voltage"] = 12
    robot = parse_robot(data, source="r.toml")
    j = robot.joints[0]
    assert robot.voltage(j) == 12.0
    assert dict(robot.gains(j)) == {**MANUAL_FACTORY["STS3215"], "p_coefficient": 16}
