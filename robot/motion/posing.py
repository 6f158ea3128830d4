"""Posing by hand: release a limb (torque off) while the rest holds, move it, capture poses.

``release`` holds every joint outside the limb where it is, through the streamer's start
(refused if a joint is outside its limits; goal := present, torque on, no snap), then
turns torque off on the limb; ``"all"`` only turns torque off. ``capture`` reads the
present positions (the bus never writes) and returns the limb's joint angles [rad],
clamped to the joint limits, as the next keyframe of a sequence (robot.motion.keyframes).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.config.joint_names import ARM_NAMES, JOINT_NAMES, LEG_NAMES
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.gait.engine import GaitEngine
from robot.loop.streamer import Streamer
from robot.motion.keyframes import Sequence

log = logging.getLogger(__name__)

#: Default time between captured keyframes [s].
STEP_S = 1.0


def limbs(robot: RobotConfig) -> dict[str, tuple[str, ...]]:
    """The limbs of ``robot`` that can be released: name → its joints (non-empty only)."""
    names = robot.joint_names
    out = {"all": names,
           "arms": tuple(n for n in names if n in ARM_NAMES),
           "right_arm": tuple(n for n in names if n in ARM_NAMES and n.startswith("r_")),
           "left_arm": tuple(n for n in names if n in ARM_NAMES and n.startswith("l_")),
           "legs": tuple(n for n in names if n in LEG_NAMES),
           "extras": tuple(n for n in names if n not in JOINT_NAMES)}
    return {k: v for k, v in out.items() if v}


def limb_joints(robot: RobotConfig, limb: object) -> tuple[str, ...]:
    valid = limbs(robot)
    if not isinstance(limb, str) or limb not in valid:
        raise ConfigError(f"limb {limb!r}: unknown; valid for {robot.name}: "
                          f"{', '.join(valid)}")
    return valid[limb]


def release(robot: RobotConfig, bus: Bus, limb: str) -> tuple[str, ...]:
    """Hold the other joints where they are (torque on), torque off on ``limb``'s."""
    joints = limb_joints(robot, limb)
    smap = ServoMap(robot)
    if len(joints) < len(robot.joints):
        hold = Streamer(smap, bus, GaitEngine(robot, GaitParams()), hold_at_end=True)
        stats = hold.move_to(smap.from_positions(bus.read_positions(smap.ids)))
        if not stats.holding:
            raise ConfigError(f"could not hold the other joints: {stats.stop_reason}")
    bus.set_torque([robot.joint(j).servo_id for j in joints], enabled=False)
    log.info("released %s (%d joints); the rest holds", limb, len(joints))
    return joints


@dataclass
class Capture:
    """Keyframes captured by hand for ``joints``: times [s] and poses [rad]."""

    robot: RobotConfig
    joints: tuple[str, ...]
    times: list[float] = field(default_factory=list)
    poses: list[list[float]] = field(default_factory=list)

    def add(self, bus: Bus, *, t: float | None = None, step_s: float = STEP_S) -> list[float]:
        """Read the present pose and append it at ``t`` (default: ``step_s`` after the
        last keyframe, 0 for the first). Returns the captured angles [rad]."""
        smap = ServoMap(self.robot)
        q = smap.clamp(smap.from_positions(bus.read_positions(smap.ids)))
        names = self.robot.joint_names
        pose = [float(q[names.index(j)]) for j in self.joints]
        when = t if t is not None else (self.times[-1] + step_s if self.times else 0.0)
        if self.times and when <= self.times[-1]:
            raise ConfigError(f"keyframe time {when:g} s is not after the last one "
                              f"({self.times[-1]:g} s)")
        self.times.append(float(when))
        self.poses.append(pose)
        return pose

    def sequence(self, name: str, *, interpolation: str = "min_jerk") -> Sequence:
        if not self.times:
            raise ConfigError("no keyframes captured yet")
        return Sequence(name, self.joints, np.array(self.times), np.array(self.poses),
                        interpolation, False, f"<captured {name}>")
