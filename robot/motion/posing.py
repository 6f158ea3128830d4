"""Moves to a pose, and posing by hand: release a limb (torque off) while the rest holds,
move it, capture poses.

``PoseMove`` is the motion source (robot.loop.source) of a move to a pose: `biped pose`,
`biped torque on` (a move to the present pose) and ``release`` stream it.
``release`` holds every joint outside the limb where it is, through the streamer's start
(refused if a joint is outside its limits; goal := present, torque on, no snap), then
turns torque off on the limb; ``"all"`` only turns torque off. ``capture`` reads the
present positions (the bus never writes) and returns the limb's joint angles [rad],
clamped to the joint limits, as the next keyframe of a sequence (robot.motion.keyframes).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.config.joint_names import ARM_NAMES, JOINT_NAMES, LEG_NAMES
from robot.config.params import GaitParams
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.loop.streamer import Streamer
from robot.motion.keyframes import Sequence
from robot.motion.ramp import ramp

log = logging.getLogger(__name__)

#: Default time between captured keyframes [s].
STEP_S = 1.0
#: Shortest move to a pose [s]: a tiny move is gentle too.
MIN_MOVE_S = 0.3


class PoseMove:
    """A move to ``goal`` [rad] (joint order; clamped to the limits) as a motion source:
    minimum jerk in time from the present pose, at peak speed ``max_speed`` [rad/s] (scalar
    or per joint, capped by each joint's max_speed_rad_s; default: each joint's), lasting
    at least ``MIN_MOVE_S``. It has no parameters, no entry ramp and no exit pose: a stop
    request ends it where it is (the streamer then holds or turns torque off)."""

    def __init__(self, robot: RobotConfig, goal: npt.ArrayLike, *,
                 max_speed: npt.ArrayLike | None = None) -> None:
        self.robot = robot
        smap = ServoMap(robot)
        self.goal = smap.clamp(goal)
        self.max_speed = (smap.max_speed if max_speed is None
                          else np.minimum(smap.max_speed, max_speed))
        self._path: npt.NDArray[np.float64] = np.empty((0, len(smap.ids)))
        self._next = 0
        self._stop = False

    @property
    def params(self) -> GaitParams | None:
        return None

    def set_params(self, changes: Mapping[str, float], *,
                   where: str = "parameter") -> GaitParams:
        raise ConfigError(f"{where}: a move to a pose has no parameters")

    def entry(self, present: npt.NDArray[np.float64], dt: float) -> None:
        """Plan the ramp from ``present`` [rad] at ticks of ``dt`` [s]; no entry ramp."""
        self._path = ramp(present, self.goal, self.max_speed, 1.0 / dt,
                          min_duration=MIN_MOVE_S)
        self._next = 1                    # row 0 is the present pose itself

    def exit_pose(self) -> None:
        return None

    def start(self) -> None:
        self._stop = False

    def stop(self) -> None:
        self._stop = True

    @property
    def stopped(self) -> bool:
        return self._stop or self._next >= len(self._path)

    @property
    def state(self) -> str:
        return "pose"

    @property
    def amplitude(self) -> float:
        return 0.0

    def tick(self, dt: float) -> npt.NDArray[np.float64]:
        q = self._path[self._next]
        self._next += 1
        return q


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
        here = PoseMove(robot, smap.from_positions(bus.read_positions(smap.ids)))
        stats = Streamer(smap, bus, here, hold_at_end=True).run()
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
