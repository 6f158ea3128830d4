"""The optional [imu] section of robot files, and the IMU factory."""

from __future__ import annotations

import tomllib
from typing import Any

import pytest

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot, parse_robot
from robot.errors import ConfigError
from robot.imu import Imu, ImuConfig, ImuSample, imu_kinds, open_imu, register_imu
from robot.imu.bno055 import Bno055Imu

SRC = "my.toml"


def robot_data(imu: Any = None) -> dict[str, Any]:
    with (ROBOTS_DIR / "biped18-dynamixel.toml").open("rb") as f:
        data = tomllib.load(f)
    data.pop("imu", None)
    if imu is not None:
        data["imu"] = imu
    return data


def test_bundled_robots_have_the_sim_imu(any_robot: RobotConfig) -> None:
    assert any_robot.imu == ImuConfig(kind="sim")


def test_imu_is_optional() -> None:
    assert parse_robot(robot_data(), source=SRC).imu is None


def test_imu_fields_load() -> None:
    robot = parse_robot(robot_data({"kind": "bno055", "port": "/dev/ttyAMA0",
                                    "mount_rpy_deg": [180, 0, -90]}), source=SRC)
    assert robot.imu == ImuConfig(kind="bno055", port="/dev/ttyAMA0",
                                  mount_rpy_deg=(180.0, 0.0, -90.0))
    sim = parse_robot(robot_data({"kind": "sim", "noise": 0, "bias": 2.5, "latency_ms": 20,
                                  "seed": 3, "fusion": False}), source=SRC).imu
    assert sim == ImuConfig(kind="sim", noise=0.0, bias=2.5, latency_ms=20.0, seed=3,
                            fusion=False)


@pytest.mark.parametrize("imu,message", [
    ({"kind": "sim", "rate": 1}, "imu.rate: unknown key; valid: kind, port, mount_rpy_deg"),
    ({"noise": 1.0}, "imu.kind: missing (expected one of "),
    ({"kind": "mpu6050"}, "bno055, got 'mpu6050'"),
    ({"kind": "sim", "noise": -1}, "imu.noise: expected a number in [0, 100], got -1"),
    ({"kind": "sim", "latency_ms": 900}, "imu.latency_ms: expected a number in [0, 500] ms"),
    ({"kind": "sim", "seed": 1.5}, "imu.seed: expected an integer"),
    ({"kind": "sim", "fusion": "yes"}, "imu.fusion: expected true or false, got 'yes'"),
    ({"kind": "sim", "mount_rpy_deg": [0, 0]}, "imu.mount_rpy_deg: expected [roll, pitch, yaw]"),
    ({"kind": "sim", "mount_rpy_deg": [0, 270, 0]},
     "imu.mount_rpy_deg[1]: expected a number in [-180, 180] deg, got 270"),
    ({"kind": "sim", "port": "/dev/ttyUSB1"}, "imu.port: not used by kind \"sim\""),
    ({"kind": "bno055", "noise": 1.0}, "imu.noise: only for kind \"sim\""),
    ({"kind": "bno055", "port": ""}, "imu.port: expected a non-empty string"),
    ("sim", "imu: expected a table, got 'sim'"),
])
def test_imu_errors_name_file_field_and_range(imu: Any, message: str) -> None:
    with pytest.raises(ConfigError) as e:
        parse_robot(robot_data(imu), source=SRC)
    text = str(e.value)
    assert text.startswith(f"{SRC}: ") and message in text, text
    assert "\n" not in text


def test_factory_kinds_and_errors() -> None:
    assert imu_kinds()[-1] == "bno055" and "sim" in imu_kinds()
    assert isinstance(open_imu(ImuConfig(kind="bno055", port="/dev/null")), Bno055Imu)
    with pytest.raises(ConfigError, match=r"unknown IMU 'nope'; valid: .*sim.*bno055"):
        open_imu(ImuConfig(kind="nope"))
    with pytest.raises(ConfigError, match="needs the sim bus"):
        open_imu(ImuConfig(kind="sim"))
    with pytest.raises(ConfigError, match="built in"):
        register_imu("bno055", lambda config, bus=None: None)


class ConstantImu(Imu):
    kind = "constant"

    def __init__(self, config: ImuConfig, *, bus: object = None) -> None:
        self.opened = False

    def open(self) -> None:
        self.opened = True

    def close(self) -> None:
        self.opened = False

    @property
    def is_open(self) -> bool:
        return self.opened

    def read(self) -> ImuSample:
        return ImuSample(0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 9.81))


def test_registered_plugin_is_a_valid_kind() -> None:
    register_imu("constant", ConstantImu)
    assert "constant" in imu_kinds()
    robot = parse_robot(robot_data({"kind": "constant"}), source=SRC)
    assert robot.imu is not None
    with open_imu(robot.imu) as imu:
        assert imu.is_open and imu.read().accel[2] == 9.81
    assert not imu.is_open


def test_load_robot_by_name_keeps_imu() -> None:
    assert load_robot("biped18-feetech").imu == ImuConfig(kind="sim")
