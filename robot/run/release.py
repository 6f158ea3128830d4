"""Releasing a limb for posing by hand: every joint outside the limb holds where it is,
through the streamer's start (refused if a joint is outside its limits; goal := present,
torque on, no snap), then torque goes off on the limb; ``"all"`` only turns torque off.
"""

from __future__ import annotations

import logging

from robot.bus.base import Bus, bus_rate
from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.errors import ConfigError
from robot.loop.streamer import Streamer
from robot.motion.posing import PoseMove, limb_joints

log = logging.getLogger(__name__)


def release(robot: RobotConfig, bus: Bus, limb: str) -> tuple[str, ...]:
    """Hold the other joints where they are (torque on), torque off on ``limb``'s."""
    joints = limb_joints(robot, limb)
    smap = ServoMap(robot)
    if len(joints) < len(robot.joints):
        here = PoseMove(robot, smap.from_positions(bus.read_positions(smap.ids)))
        stats = Streamer(smap, bus, here, rate_hz=bus_rate(bus), hold_at_end=True).run()
        if not stats.holding:
            raise ConfigError(f"could not hold the other joints: {stats.stop_reason}")
    bus.set_torque([robot.joint(j).servo_id for j in joints], enabled=False)
    log.info("released %s (%d joints); the rest holds", limb, len(joints))
    return joints
