"""What the simulated bus watches during one run (robot.run.spec.RunWatch): the torso's
path and fall (sim.mujoco.metrics.WalkMonitor), the servos' energy and knee load
(sim.mujoco.effort.EffortMonitor), the feet on the ground (sim.mujoco.foot_contact), and
the world's pushes (sim.mujoco.world
.PushScheduler), with their JSON summary."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import mujoco

from robot.config.robot import RobotConfig
from robot.config.world import World
from robot.loop.telemetry import Telemetry
from sim.mujoco.effort import EffortMonitor
from sim.mujoco.foot_contact import FootContacts
from sim.mujoco.metrics import WalkMonitor
from sim.mujoco.world import PushScheduler, PushTarget


class SimRunWatch:
    """Built by ``MujocoBus.run_watch()`` on the open bus (its model, data, robot, standing
    height [m], floor normal, world, and itself as the push target); called every control
    tick."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, robot: RobotConfig, *,
                 standing_height: float, floor_normal: tuple[float, float, float],
                 world: World | None, push_target: PushTarget) -> None:
        self.world = world
        self.monitor = WalkMonitor(standing_height=standing_height, floor_normal=floor_normal)
        self.effort = EffortMonitor(model, data, robot)
        self.feet = FootContacts(model, data)
        self.pushes = (PushScheduler(push_target, world.pushes)
                       if world is not None and world.pushes else None)
        self._qpos = data.qpos
        self._walked = False
        self._right = True

    def __call__(self, tel: Telemetry) -> None:
        self.monitor.update_qpos(tel.t, self._qpos[:7].tolist())
        self.effort.update(tel.t)
        if tel.state == "walking" and not self.monitor.fell:   # on its feet, walking
            self.feet.update(tel.t)
            right = self.feet.right_down
            self.monitor.walking(right and not self._right)
            self._right = right
            self._walked = True
        elif tel.state == "ramp_out" and self._walked:
            self.monitor.mark_stop(tel.t)
        if self.pushes is not None:
            self.pushes(tel)

    @property
    def fell(self) -> bool:
        return self.monitor.fell

    def summary(self, seconds: float | None) -> Mapping[str, Any]:
        """The walk metrics (``seconds``: gait time for the speed [s]), the effort, and the
        "world" object: every field of the world (the defaults for the plain scene) and
        each applied push with its sim start time."""
        out: dict[str, Any] = self.monitor.summary(seconds or 0.0)
        out.update(self.effort.summary(out["distance_m"]))
        out["feet"] = self.feet.summary()
        world: dict[str, Any] = (self.world or World()).as_dict()
        world["pushes_applied"] = [] if self.pushes is None else self.pushes.as_list()
        out["world"] = world
        return out
