"""Robot TOML files → a validated ``RobotConfig`` (robot/config/robot.py).

Every error is one line: ``<file>: <field path>: <what is expected>, got <value>``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from robot.config.bundled import DEFAULT_ROBOT, resolve_robot_path
from robot.config.checks import (
    check_bus,
    check_cases,
    check_joint_extras,
    check_joint_set,
    check_model_joints,
    check_ticks,
)
from robot.config.gains_file import check_fits, parse_gains, split_gains
from robot.config.imu_file import parse_imu
from robot.config.joint_names import ARM_NAMES, HIP_YAW_NAMES, JOINT_NAMES
from robot.config.model_file import parse_model
from robot.config.params import BALANCE, SPECS, STEER, canonical_name, check_value
from robot.config.robot import ANGLE, BusConfig, Geometry, JointConfig, Masses, RobotConfig
from robot.config.servo_file import servo_files
from robot.config.toml_io import Range, TomlValue, build, number, read_toml, show, table
from robot.errors import ConfigError
from robot.servo.models import MODELS


def load_robot(name_or_path: str | Path | None = None) -> RobotConfig:
    """Load and validate a robot by bundled name or TOML path (default: the Dynamixel
    biped)."""
    p = resolve_robot_path(name_or_path) if name_or_path is not None else DEFAULT_ROBOT
    return parse_robot(read_toml(p), source=str(p))


def parse_robot(data: Mapping[str, TomlValue], *, source: str = "<memory>") -> RobotConfig:
    """A validated robot from a robot file's table (ConfigError, one line, on any problem)."""
    src = source
    allowed = {"name", "bus", "geometry", "mass", "joints", "rest", "imu", "balance", "gait",
               "model"}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ConfigError(f"{src}: {unknown[0]}: unknown key; valid: {', '.join(sorted(allowed))}")
    body = parse_model(src, data["model"]) if "model" in data else None
    for key in ("name", "bus", "geometry", "joints") + (() if body else ("mass",)):
        if key not in data:
            raise ConfigError(f"{src}: {key}: missing")
    name = data["name"]
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{src}: name: expected a non-empty string, got {show(name)}")

    bus_tab, bus_gains = split_gains(src, "bus", data["bus"])
    bus = build(BusConfig, src, "bus", bus_tab, overrides={"gains": {}})
    check_bus(src, bus)
    bus = replace(bus, gains=parse_gains(src, "bus.gains", bus_gains, bus.servo))
    geometry = build(Geometry, src, "geometry", data["geometry"])
    if body is not None and "mass" in data:
        raise ConfigError(f"{src}: mass: an imported robot's masses are its model's "
                          "([model.links]); remove [mass]")
    mass = build(Masses, src, "mass", data["mass"]) if body is None else None

    jtab = table(src, "joints", data["joints"])
    check_joint_set(src, jtab)
    if mass is not None and any(n in jtab for n in HIP_YAW_NAMES) and mass.hip_yaw_link == 0.0:
        raise ConfigError(f"{src}: mass.hip_yaw_link: missing (the robot has hip yaw joints; "
                          "only 5-DoF legs leave it out)")
    if any(n in jtab for n in ARM_NAMES):
        for sect, obj in (("geometry", geometry), ("mass", mass)):
            if obj is None:
                continue
            for f in ("shoulder_width", "upper_arm", "forearm"):
                if getattr(obj, f, None) == 0.0:
                    raise ConfigError(f"{src}: {sect}.{f}: missing (the robot has arms)")
    extras = [n for n in jtab if n not in JOINT_NAMES]
    joints: list[JointConfig] = []
    seen: dict[int, str] = {}
    for jn in [*JOINT_NAMES, *extras]:
        if jn not in jtab:
            continue
        jp = f"joints.{jn}"
        joint_tab, joint_gains = split_gains(src, jp, jtab[jn])
        j = build(JointConfig, src, jp, joint_tab, overrides={"name": jn, "gains": {}})
        check_joint_extras(src, jp, j, bus, extra=jn in extras)
        servo = MODELS[j.model or bus.model]
        check_fits(src, bus.gains, servo, jn)
        j = replace(j, gains=parse_gains(src, f"{jp}.gains", joint_gains, servo))
        resolution = servo.resolution
        if j.servo_id in seen:
            raise ConfigError(f"{src}: {jp}.servo_id: duplicate servo id {j.servo_id} "
                              f"(also joints.{seen[j.servo_id]})")
        seen[j.servo_id] = jn
        if j.sign not in (1, -1):
            raise ConfigError(f"{src}: {jp}.sign: expected +1 or -1, got {show(j.sign)}")
        number(src, f"{jp}.zero_ticks", j.zero_ticks, Range(0, resolution - 1), integer=True)
        if not j.min_rad < j.max_rad:
            raise ConfigError(f"{src}: {jp}: limits reversed or empty: min_rad {j.min_rad} "
                              f"must be < max_rad {j.max_rad}")
        joints.append(j)

    check_cases(src, joints, bus)
    rest_raw = table(src, "rest", data.get("rest", {}))
    rest: dict[str, float] = {}
    names = {j.name: j for j in joints}
    for jn, v in rest_raw.items():
        if jn not in names:
            raise ConfigError(f"{src}: rest.{jn}: unknown joint; valid: {', '.join(names)}")
        q = number(src, f"rest.{jn}", v, ANGLE)
        if not names[jn].min_rad <= q <= names[jn].max_rad:
            raise ConfigError(f"{src}: rest.{jn}: {q} is outside the joint limits "
                              f"[{names[jn].min_rad}, {names[jn].max_rad}]")
        rest[jn] = q
    imu = parse_imu(src, data["imu"]) if "imu" in data else None
    balance: dict[str, float] = {}
    for key, v in table(src, "balance", data.get("balance", {})).items():
        where = f"{src}: balance.{key}"
        canon = canonical_name(key, where=where)
        if SPECS[canon].group != BALANCE:
            gains = ", ".join(n for n, spec in SPECS.items() if spec.group == BALANCE)
            raise ConfigError(f"{where}: not a balance gain (a gait parameter belongs in a "
                              f"gait preset); valid: {gains}")
        balance[canon] = check_value(canon, v, where=where)
    if body is not None:
        check_model_joints(src, body, joints)
    robot = RobotConfig(name=name, bus=bus, geometry=geometry, mass=mass, joints=tuple(joints),
                        rest=rest, source=src, imu=imu, balance=balance,
                        gait=parse_gait_table(src, data.get("gait", {})), body=body,
                        physics=servo_files(src, bus.servo_file, [
                            (j.name, j.servo_file, j.model or bus.model) for j in joints]))
    check_ticks(robot)
    return robot


def parse_gait_table(src: str, value: TomlValue) -> dict[str, float]:
    """A robot file's ``[gait]``: gait parameters by name (aliases allowed), each checked
    against its documented range; a balance gain (``[balance]``'s) or a steering command
    is refused, naming the valid ones."""
    out: dict[str, float] = {}
    for key, v in table(src, "gait", value).items():
        where = f"{src}: gait.{key}"
        canon = canonical_name(key, where=where)
        group = SPECS[canon].group
        if group in (BALANCE, STEER):
            valid = ", ".join(n for n, spec in SPECS.items() if spec.group not in (BALANCE, STEER))
            why = ("a balance gain belongs in [balance]" if group == BALANCE
                   else "a steering command is given when walking (--set, the panel)")
            raise ConfigError(f"{where}: not a gait parameter of the robot ({why}); valid: {valid}")
        if canon in out:
            raise ConfigError(f"{where}: {canon} given twice (alias of {canon})")
        out[canon] = check_value(canon, v, where=where)
    return out
