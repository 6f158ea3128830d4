"""What a simulated walk costs the servos: mechanical energy and knee load.

``EffortMonitor`` is fed once per control tick (a streamer observer, after the physics):
it integrates the absolute mechanical power of every actuated joint, |tau * qdot|, over the
tick (the state at the end of the tick held over it) and averages the knees' load (|tau| /
the simulated servo's stall torque, its actuator's force limit). Actuators are named after
their joints (sim/mujoco/mjcf_robot.py).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from robot.config.robot import RobotConfig

KNEES = ("r_knee", "l_knee")


class EffortMonitor:
    """model, data: the sim bus's MuJoCo model and data; robot: its joints and servos."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, robot: RobotConfig) -> None:
        self.data = data
        names = [j.name for j in robot.joints]
        self._act = np.array([model.actuator(n).id for n in names])
        self._dof = np.array([model.jnt_dofadr[model.joint(n).id] for n in names])
        knees = [names.index(k) for k in KNEES if k in names]
        self._knees = np.array(knees, dtype=int)
        # the simulated servos' stall torque at the robot's supply (sim/mujoco/servo_law.py)
        stall = model.actuator_forcerange[self._act, 1]
        self._knee_stall = stall[self._knees] if knees else np.ones(0)
        self.energy_j = 0.0
        self._knee_sum = 0.0
        self._ticks = 0
        self._t: float | None = None

    def update(self, t: float) -> None:
        """One control tick ending at sim time ``t`` [s]."""
        force = self.data.actuator_force[self._act]
        if self._t is not None and t > self._t:
            qdot = self.data.qvel[self._dof]
            self.energy_j += float(np.abs(force * qdot).sum()) * (t - self._t)
        self._t = t
        if len(self._knees):
            self._knee_sum += float(np.mean(np.abs(force[self._knees]) / self._knee_stall))
        self._ticks += 1

    def summary(self, distance_m: float) -> dict[str, Any]:
        """energy_j [J], energy_per_m [J/m] (None for no forward distance), knee_load_pct:
        the knees' mean |torque| as a share of their stall torque [%]."""
        per_m = self.energy_j / distance_m if distance_m > 0.01 else None
        knee = 100.0 * self._knee_sum / self._ticks if self._ticks else 0.0
        return {"energy_j": self.energy_j, "energy_per_m": per_m, "knee_load_pct": knee}
