"""Robot and gait TOML files → frozen, validated dataclasses.

Every error is one line: ``<file>: <field path>: <what is expected>, got <value>``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

from robot.config.bundled import (  # noqa: F401  (re-exported: where configs come from)
    CONFIG_DIR,
    DEFAULT_GAIT,
    DEFAULT_ROBOT,
    DEFAULT_ROBOT_NAME,
    GAITS_DIR,
    ROBOTS_DIR,
    gait_names,
    resolve_gait_path,
    resolve_robot_path,
    robot_names,
)
from robot.config.checks import check_bus, check_joint_extras, check_joint_set, check_ticks
from robot.config.gait_file import Gait, gait_to_toml, load_gait, parse_gait  # noqa: F401 (re-exported)
from robot.config.joint_names import (  # noqa: F401 (re-exported)
    ARM_JOINTS,
    ARM_NAMES,
    JOINT_NAMES,
    LEG_JOINTS,
    LEG_NAMES,
    SIDES,
)
from robot.config.params import BALANCE, SPECS, canonical_name, check_value
from robot.config.toml_io import Range, build, number, read_toml, show, spec, table
from robot.errors import ConfigError
from robot.imu.config import ImuConfig, parse_imu
from robot.servo.models import MODELS, ServoModel

# Valid ranges of the numeric fields (checked at load; see robot/config/toml_io.py).
#: bus.retries: extra attempts per transaction; more than 10 only hides a broken bus.
RETRIES = Range(0, 10)
#: bus.timeout_ms: reply timeout; under 1 ms nothing answers, over 1 s the loop is dead.
TIMEOUT_MS = Range(1.0, 1000.0, "ms")
#: Geometry: 1 mm (no servo link is smaller; 0 divides by zero in IK) to 2 m.
LENGTH = Range(0.001, 2.0, "m")
#: Link masses: 1 g to 100 kg.
MASS = Range(0.001, 100.0, "kg")
#: Joint limits: one turn, centred on zero.
ANGLE = Range(-math.pi, math.pi, "rad", label="[-pi, pi]")
#: Slew limit: 0.05 rad/s (3 deg/s: a 2 pi ramp still ends within 4 min) to 20 rad/s (above
#: the no-load speed of every hobby servo in tables.MODELS).
SPEED = Range(0.05, 20.0, "rad/s")
#: Servo ids: 0..252 (253..255 are broadcast / reserved in both protocols).
SERVO_ID = Range(0, 252)


@dataclass(frozen=True)
class BusConfig:
    """kind: "dynamixel" | "feetech"; model: servo model name; port: device; baud [bit/s]."""

    kind: str
    model: str
    port: str = "/dev/ttyUSB0"
    baud: int = 1_000_000
    retries: int = field(default=2, metadata=spec(RETRIES))
    timeout_ms: float = field(default=20.0, metadata=spec(TIMEOUT_MS))

    @property
    def servo(self) -> ServoModel:
        return MODELS[self.model]


@dataclass(frozen=True)
class Geometry:
    """Kinematic dimensions [m]. Frames: REP-103 (x forward, y left, z up).

    The pelvis frame's origin is midway between the two hip joint centres. All three hip
    axes (yaw z, roll x, pitch y) meet at the hip centre; the knee is ``thigh`` below it,
    the ankle (pitch y, roll x) ``shin`` below the knee, the sole ``ankle_height`` below
    the ankle. Shoulders (pitch y, roll x) sit ``torso_height`` above the pelvis origin and
    ``shoulder_width / 2`` to each side; the elbow (y) is ``upper_arm`` below, the hand
    ``forearm`` below the elbow.
    """

    hip_width: float = field(metadata=spec(LENGTH))
    thigh: float = field(metadata=spec(LENGTH))
    shin: float = field(metadata=spec(LENGTH))
    ankle_height: float = field(metadata=spec(LENGTH))
    foot_length: float = field(metadata=spec(LENGTH))
    foot_width: float = field(metadata=spec(LENGTH))
    foot_forward: float = field(metadata=spec(LENGTH))
    torso_height: float = field(metadata=spec(LENGTH))
    torso_depth: float = field(metadata=spec(LENGTH))
    shoulder_width: float = field(default=0.0, metadata=spec(LENGTH))  # arms only
    upper_arm: float = field(default=0.0, metadata=spec(LENGTH))       # arms only
    forearm: float = field(default=0.0, metadata=spec(LENGTH))         # arms only

    @property
    def leg_length(self) -> float:
        """Hip centre to ankle with straight knee [m]."""
        return self.thigh + self.shin


@dataclass(frozen=True)
class Masses:
    """Link masses including the servos they carry [kg]."""

    torso: float = field(metadata=spec(MASS))
    hip_yaw_link: float = field(metadata=spec(MASS))
    hip_roll_link: float = field(metadata=spec(MASS))
    thigh: float = field(metadata=spec(MASS))
    shin: float = field(metadata=spec(MASS))
    ankle_link: float = field(metadata=spec(MASS))
    foot: float = field(metadata=spec(MASS))
    upper_arm: float = field(default=0.0, metadata=spec(MASS))   # arms only
    forearm: float = field(default=0.0, metadata=spec(MASS))     # arms only
    shoulder_link: float = field(default=0.03, metadata=spec(MASS))

    @property
    def total(self) -> float:
        leg = (self.hip_yaw_link + self.hip_roll_link + self.thigh + self.shin
               + self.ankle_link + self.foot)
        arm = self.shoulder_link + self.upper_arm + self.forearm if self.upper_arm else 0.0
        return self.torso + 2 * leg + 2 * arm


@dataclass(frozen=True)
class JointConfig:
    """One joint and its servo.

    servo_id: bus id; sign: +1/-1 (servo direction vs joint axis); zero_ticks: ticks at
    0 rad; min_rad, max_rad: joint limits [rad]; max_speed_rad_s: slew limit [rad/s];
    model: this joint's servo model when it differs from ``bus.model`` (same family, e.g.
    stronger knees); fixed_rad: an extra joint (head pan, tilt, ...) held at this angle
    [rad] while the gait runs (only for joints the gait does not drive).
    """

    name: str
    servo_id: int = field(metadata=spec(SERVO_ID))
    sign: int
    zero_ticks: int
    min_rad: float = field(metadata=spec(ANGLE))
    max_rad: float = field(metadata=spec(ANGLE))
    max_speed_rad_s: float = field(metadata=spec(SPEED))
    model: str | None = None
    fixed_rad: float | None = field(default=None, metadata=spec(ANGLE))


@dataclass(frozen=True)
class RobotConfig:
    name: str
    bus: BusConfig
    geometry: Geometry
    mass: Masses
    joints: tuple[JointConfig, ...]
    rest: Mapping[str, float] = field(default_factory=dict)
    source: str = "<memory>"
    #: The ``[imu]`` section (optional; robot.imu.config): None when the robot has no IMU.
    imu: ImuConfig | None = None
    #: The ``[balance]`` section (optional): balance gains (robot/config/params.py group
    #: "balance feedback") for this robot; a gait preset that names a gain itself, and
    #: --set, take precedence.
    balance: Mapping[str, float] = field(default_factory=dict)

    def joint(self, name: str) -> JointConfig:
        for j in self.joints:
            if j.name == name:
                return j
        raise ConfigError(f"{self.source}: no joint {name!r}; valid: "
                          f"{', '.join(j.name for j in self.joints)}")

    @cached_property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.joints)

    @cached_property
    def has_arms(self) -> bool:
        return any(j.name in ARM_NAMES for j in self.joints)

    @cached_property
    def has_hip_yaw(self) -> bool:
        """False for 5-DoF legs (no hip yaw: the gait cannot turn by yawing the feet)."""
        return "r_hip_yaw" in self.joint_names

    def servo(self, joint: JointConfig) -> ServoModel:
        """The servo model of ``joint`` (its own ``model``, else the bus's)."""
        return MODELS[joint.model or self.bus.model]

    @cached_property
    def layout(self) -> tuple[tuple[int, float], ...] | None:
        """How the engine's full joint vector (``JOINT_NAMES`` order, legs then arms) maps
        onto this robot's joints: per joint (index into it, or -1 and the fixed angle).
        None when the robot is exactly the leading part of ``JOINT_NAMES`` (no mapping)."""
        full = JOINT_NAMES if self.has_arms else LEG_NAMES
        if self.joint_names == full:
            return None
        index = {n: i for i, n in enumerate(full)}
        return tuple((index[j.name], 0.0) if j.fixed_rad is None else (-1, j.fixed_rad)
                     for j in self.joints)

    @cached_property
    def ids(self) -> tuple[int, ...]:
        return tuple(j.servo_id for j in self.joints)

    def joint_by_id(self, servo_id: int) -> JointConfig | None:
        for j in self.joints:
            if j.servo_id == servo_id:
                return j
        return None


# ---------------------------------------------------------------------------- robots


def load_robot(name_or_path: str | Path | None = None) -> RobotConfig:
    """Load and validate a robot by bundled name or TOML path (default: the Dynamixel
    biped)."""
    p = resolve_robot_path(name_or_path) if name_or_path is not None else DEFAULT_ROBOT
    return parse_robot(read_toml(p), source=str(p))


def parse_robot(data: Mapping[str, Any], *, source: str = "<memory>") -> RobotConfig:
    src = source
    allowed = {"name", "bus", "geometry", "mass", "joints", "rest", "imu", "balance"}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ConfigError(f"{src}: {unknown[0]}: unknown key; valid: {', '.join(sorted(allowed))}")
    for key in ("name", "bus", "geometry", "mass", "joints"):
        if key not in data:
            raise ConfigError(f"{src}: {key}: missing")
    name = data["name"]
    if not isinstance(name, str) or not name:
        raise ConfigError(f"{src}: name: expected a non-empty string, got {show(name)}")

    bus = build(BusConfig, src, "bus", data["bus"])
    check_bus(src, bus)
    geometry = build(Geometry, src, "geometry", data["geometry"])
    mass = build(Masses, src, "mass", data["mass"])

    jtab = table(src, "joints", data["joints"])
    check_joint_set(src, jtab)
    if any(n in jtab for n in ARM_NAMES):
        for sect, obj in (("geometry", geometry), ("mass", mass)):
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
        j = build(JointConfig, src, jp, jtab[jn], overrides={"name": jn})
        check_joint_extras(src, jp, j, bus, extra=jn in extras)
        resolution = MODELS[j.model or bus.model].resolution
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
    robot = RobotConfig(name=name, bus=bus, geometry=geometry, mass=mass, joints=tuple(joints),
                        rest=rest, source=src, imu=imu, balance=balance)
    check_ticks(robot)
    return robot


# ---------------------------------------------------------------------------- gaits
