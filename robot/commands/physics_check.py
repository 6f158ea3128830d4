"""The physics check `biped play` runs on the sim bus (not a sub-command): the sim's show
watch (sim/mujoco/show_watch.py) as the run's observer, and its lists turned into the
report (robot/previs/show_check.py). Any other bus: no check."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from robot.bus.base import Bus
from robot.config.robot import RobotConfig
from robot.previs.show_check import ShowCheck, build_check
from sim.mujoco.bus import MujocoBus
from sim.mujoco.show_watch import ShowWatch


def physics_watch(bus: Bus) -> ShowWatch | None:
    return ShowWatch(bus) if isinstance(bus, MujocoBus) else None


def physics_check(watch: ShowWatch | None, robot: RobotConfig,
                  metrics: Mapping[str, Any] | None) -> ShowCheck | None:
    if watch is None or not watch.t:
        return None
    fell = (metrics or {}).get("fell_at_s")
    return build_check(robot, watch.t, watch.margin, watch.torque, watch.temperature,
                       start=watch.start if watch.start is not None else watch.t[0],
                       fell_at=float(fell) if fell is not None else None)
