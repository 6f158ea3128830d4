"""The robot file's contents as frozen dataclasses: bus, geometry, masses, joints, and the
robot that holds them (read and validated by robot/config/robot_file.py).

Frames: REP-103 (x forward, y left, z up); lengths [m], masses [kg], angles [rad].
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

from robot.body.legs import LegChain
from robot.body.model import BodyModel
from robot.config.imu_file import ImuConfig
from robot.config.joint_names import ARM_NAMES, JOINT_NAMES, LEG_NAMES
from robot.config.servo_file import physics_for
from robot.config.toml_io import Range, spec
from robot.errors import ConfigError
from robot.servo.models import MODELS, ServoModel
from robot.servo.physics import ServoPhysics

# Valid ranges of the numeric fields (checked at load; see robot/config/toml_io.py).
#: bus.retries: extra attempts per transaction; more than 10 only hides a broken bus.
RETRIES = Range(0, 10)
#: bus.timeout_ms: reply timeout; under 1 ms nothing answers, over 1 s the loop is dead.
TIMEOUT_MS = Range(1.0, 1000.0, "ms")
#: Geometry: 1 mm (no servo link is smaller; 0 divides by zero in IK) to 2 m.
LENGTH = Range(0.001, 2.0, "m")
#: An offset that may be 0 or negative (a sole centred on or behind the ankle) [m].
OFFSET = Range(-0.5, 0.5, "m")
#: Link masses: 1 g to 100 kg.
MASS = Range(0.001, 100.0, "kg")
#: Joint limits: one turn, centred on zero.
ANGLE = Range(-math.pi, math.pi, "rad", label="[-pi, pi]")
#: Slew limit: 0.05 rad/s (3 deg/s: a 2 pi ramp still ends within 4 min) to 20 rad/s (above
#: the no-load speed of every hobby servo in tables.MODELS).
SPEED = Range(0.05, 20.0, "rad/s")
#: Servo ids: 0..252 (253..255 are broadcast / reserved in both protocols).
SERVO_ID = Range(0, 252)
#: bus.voltage: the supply; 3 V (below every hobby servo's minimum) to 30 V (above the
#: 24 V of the largest Dynamixel X).
VOLTAGE = Range(3.0, 30.0, "V")


@dataclass(frozen=True)
class BusConfig:
    """kind: "dynamixel" | "feetech"; model: servo model name; port: device; baud [bit/s];
    voltage: the supply [V] (None: each servo model's nominal voltage); gains: ``[bus.gains]``,
    register values every servo on the bus gets (robot/servo/gains.py names them)."""

    kind: str
    model: str
    port: str = "/dev/ttyUSB0"
    baud: int = 1_000_000
    retries: int = field(default=2, metadata=spec(RETRIES))
    timeout_ms: float = field(default=20.0, metadata=spec(TIMEOUT_MS))
    voltage: float | None = field(default=None, metadata=spec(VOLTAGE))
    gains: Mapping[str, int] = field(default_factory=dict)
    #: a fitted servo model file (robot/config/servo_file.py) for every joint on the bus,
    #: relative to the robot file; None: the bundled model of ``model``
    servo_file: str | None = None

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
    foot_forward: float = field(metadata=spec(OFFSET))
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
    """Link masses including the servos they carry [kg]. ``hip_yaw_link`` only with hip
    yaw joints (0: 5-DoF legs, the hip roll servo sits on the torso)."""

    torso: float = field(metadata=spec(MASS))
    hip_yaw_link: float = field(default=0.0, kw_only=True, metadata=spec(MASS))
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
    [rad] while the gait runs (only for joints the gait does not drive); gains:
    ``[joints.<name>.gains]``, register values overriding the bus's for this servo.
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
    gains: Mapping[str, int] = field(default_factory=dict)
    #: a fitted servo model file for this joint (overrides ``bus.servo_file``)
    servo_file: str | None = None
    #: dual-axis servos (2XL430-W250, 2XC430-W250): the case this joint's axis sits in; the
    #: two joints naming one case share it (two ids, one baud rate; setup-motors sets both)
    case: str | None = None
    #: an imported robot's joint in its model's terms (robot/body/model.py): the model's
    #: name for it, and model angle = model_sign * angle + model_offset [rad]
    model_joint: str | None = None
    model_sign: int = 1
    model_offset: float = field(default=0.0, metadata=spec(ANGLE))


@dataclass(frozen=True)
class RobotConfig:
    name: str
    bus: BusConfig
    geometry: Geometry
    mass: Masses | None
    joints: tuple[JointConfig, ...]
    rest: Mapping[str, float] = field(default_factory=dict)
    source: str = "<memory>"
    #: The ``[imu]`` section (optional; robot.config.imu_file): None when the robot has no IMU.
    imu: ImuConfig | None = None
    #: The ``[balance]`` section (optional): balance gains (robot/config/params.py group
    #: "balance feedback") for this robot; a gait preset that names a gain itself, and
    #: --set, take precedence.
    balance: Mapping[str, float] = field(default_factory=dict)
    #: The ``[gait]`` section (optional): gait parameters this robot's body needs (a
    #: cadence, a stance width, a crouch), over whatever preset is walked: preset <
    #: ``[gait]`` < --set (docs/robots.md); no balance gain (those are ``balance``) and no
    #: steering command.
    gait: Mapping[str, float] = field(default_factory=dict)
    #: Servo physics read from the model files the robot file names, per joint name
    #: (joints without one use their model's bundled physics: ``servo_physics``).
    physics: Mapping[str, ServoPhysics] = field(default_factory=dict)
    #: An imported robot's own body (the ``[model]`` section, robot/body/model.py); None:
    #: the box model built from ``geometry`` and ``mass``.
    body: BodyModel | None = None
    #: The legs' axes and offsets (right, left; robot.body.legs) the IK solves; None: the
    #: ``body``'s legs, else the box model's from ``geometry`` (see ``legs``).
    leg_chains: tuple[LegChain, LegChain] | None = None

    def __post_init__(self) -> None:
        if self.leg_chains is None and self.body is None:
            return
        for leg, side in zip(self.legs, ("r", "l"), strict=True):
            if leg.side != side or (leg.has_yaw, leg.has_ankle_roll) != (
                    self.has_hip_yaw, self.has_ankle_roll):
                raise ConfigError(
                    f"{self.source}: leg_chains: the {side} leg's chain (side {leg.side!r}, "
                    f"hip yaw {leg.has_yaw}, ankle roll {leg.has_ankle_roll}) does not match "
                    f"the joints (hip yaw {self.has_hip_yaw}, ankle roll "
                    f"{self.has_ankle_roll}); expected (right, left) chains of these joints")

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

    @cached_property
    def has_ankle_roll(self) -> bool:
        """False for 5-DoF legs without ankle roll (the foot's roll goes with the leg's)."""
        return "r_ankle_roll" in self.joint_names

    @cached_property
    def legs(self) -> tuple[LegChain, LegChain]:
        """The right and left leg as the IK sees them: ``leg_chains``, else the imported
        ``body``'s, else the box model's from ``geometry`` (hip centre (0, -/+ hip_width / 2, 0), the yaw axis
        through it when the robot has hip yaw, sole ``ankle_height`` below the ankle)."""
        if self.leg_chains is not None:
            return self.leg_chains
        if self.body is not None:
            return self.body.legs
        g = self.geometry

        def box(side: str, sign: float) -> LegChain:
            y = sign * g.hip_width / 2
            return LegChain(side, (0.0, y, 0.0), g.thigh, g.shin, (0.0, 0.0, -g.ankle_height),
                            yaw_axis=(0.0, y) if self.has_hip_yaw else None,
                            has_ankle_roll=self.has_ankle_roll)
        return box("r", -1.0), box("l", 1.0)

    def servo(self, joint: JointConfig) -> ServoModel:
        """The servo model of ``joint`` (its own ``model``, else the bus's)."""
        return MODELS[joint.model or self.bus.model]

    def gains(self, joint: JointConfig) -> Mapping[str, int]:
        """The gain registers ``joint``'s servo gets [register values]: its model's factory
        values, overridden by ``[bus.gains]``, overridden by ``[joints.<name>.gains]``."""
        return {**self.servo(joint).factory_gains, **self.bus.gains, **joint.gains}

    def case_of(self, joint: JointConfig) -> tuple[JointConfig, ...]:
        """The joints whose axes share ``joint``'s dual-axis case, in file order (just
        ``joint`` for a one-axis servo)."""
        if joint.case is None:
            return (joint,)
        return tuple(j for j in self.joints if j.case == joint.case)

    def servo_physics(self, joint: JointConfig) -> ServoPhysics:
        """The physics ``joint``'s servo is simulated with: the model file the robot file
        names for it, else its model's bundled physics (robot/config/servo_file.py)."""
        named = self.physics.get(joint.name)
        return named if named is not None else physics_for(self.servo(joint).name)

    def voltage(self, joint: JointConfig) -> float:
        """The supply voltage ``joint``'s servo sees [V]: ``bus.voltage``, else its model's
        nominal voltage."""
        v = self.bus.voltage
        return self.servo(joint).nominal_voltage if v is None else v

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
