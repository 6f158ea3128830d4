"""Robots with real legs' offsets for ``biped bench --only core``, until imported robots
are bundled: a bundled robot whose leg chains (robot.body.legs) carry the offsets of
real kits, so the tick of robot.gait.ik_chain's closed form is timed beside the box
model's.

- "duck-like": the Open Duck Mini v2's hip, the yaw axis 16 mm ahead of the roll-pitch
  point (in x only: the closed form without Newton steps), the pitch axis 12 mm below the
  roll axis, 6 mm sideways, the sole 10 mm ahead of the ankle, ankle roll 10 mm below it.
- "yaw-off-side": as "duck-like" with the yaw axis also 10 mm inside the hip (the
  lateral constraint then takes robot.gait.ik_chain.NEWTON Newton steps).
"""

from __future__ import annotations

import dataclasses

from robot.body.legs import LegChain
from robot.config.robot import RobotConfig

#: name: (yaw axis - hip (x, y) for the left leg [m], mirrored for the right)
OFFSETS = {"duck-like": (0.016, 0.0), "yaw-off-side": (0.016, -0.010)}


def offset_legs(robot: RobotConfig, name: str) -> RobotConfig:
    """``robot`` with the legs of ``OFFSETS[name]`` (its own thigh, shin, hip width)."""
    dx, dy = OFFSETS[name]
    g = robot.geometry

    def leg(side: str, sign: float) -> LegChain:
        hip = (0.0, sign * g.hip_width / 2, 0.012)
        return LegChain(side, hip, g.thigh, g.shin, (0.01, 0.0, -(g.ankle_height - 0.01)),
                        yaw_axis=(dx, hip[1] + sign * dy) if robot.has_hip_yaw else None,
                        roll_drop=0.012, lateral=sign * 0.006,
                        ankle_drop=0.01 if robot.has_ankle_roll else 0.0,
                        has_ankle_roll=robot.has_ankle_roll)
    return dataclasses.replace(robot, name=f"{robot.name} ({name} legs)",
                               leg_chains=(leg("r", -1.0), leg("l", 1.0)))
