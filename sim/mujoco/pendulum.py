"""Pendulum logs replayed in MuJoCo: one hinge per log, a weight on an arm, driven by the
servo model (``sim.mujoco.servo_law``) closed loop from the log's first recorded state.

All logs of a set swing side by side in one model (they never touch), so one ``mj_step``
advances every log: a replay of 16 logs costs about what one costs. Per log sample (the
logs are resampled to ``robot.servo.pendulum_log.DT``) the firmware's tick runs with the
log's goal and torque enable, then the physics steps to the next sample.

The rig: q = 0 is the arm hanging down; the weight ``mass`` [kg] sits at ``length`` [m]
on the arm (a uniform arm of ``arm_mass`` [kg] adds its share); ``offset`` [rad] is the
rig's mounting error (gravity acts on q + offset), a property of the test bench, not of
the servo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence

import mujoco
import numpy as np
import numpy.typing as npt

from robot.servo.firmware import log_gains
from robot.servo.models import ServoModel
from robot.servo.pendulum_log import DT, PendulumLog
from robot.servo.physics import ServoPhysics
from sim.mujoco.servo_law import Firmware, ServoArrays

Floats = npt.NDArray[np.float64]
TIMESTEP = 0.0025  # physics step [s]: 2 per log sample (0.5 ms changes the replay < 0.001 rad)
_SPACING = 1.0    # [m] between the pendulums


def _pendulum_xml(logs: Sequence[PendulumLog], timestep: float) -> str:
    root = ET.Element("mujoco", model="pendulums")
    ET.SubElement(root, "option", timestep=repr(timestep), integrator="implicitfast",
                  jacobian="sparse")
    world = ET.SubElement(root, "worldbody")
    act = ET.SubElement(root, "actuator")
    for i, log in enumerate(logs):
        body = ET.SubElement(world, "body", name=f"arm{i}", pos=f"{i * _SPACING} 0 0")
        ET.SubElement(body, "joint", name=f"q{i}", type="hinge", axis="0 1 0")
        m, a, length = log.mass, log.arm_mass, log.length
        total = m + a
        c = (m * length + a * length / 2) / total                 # centre of mass [m]
        pivot = m * length**2 + a * length**2 / 3                 # about the pivot [kg m^2]
        iy = max(pivot - total * c * c, 1e-9)
        ET.SubElement(body, "inertial", pos=f"0 0 {-c!r}", mass=repr(total),
                      diaginertia=f"{iy!r} {iy!r} 1e-9")
        ET.SubElement(act, "position", name=f"s{i}", joint=f"q{i}", kp="0")
    return ET.tostring(root, encoding="unicode")


class PendulumBench:
    """The logs' rigs in one MuJoCo model; ``replay`` runs them with a servo model."""

    def __init__(self, logs: Sequence[PendulumLog], servo: ServoModel, *,
                 timestep: float = TIMESTEP, copies: int = 1) -> None:
        one = [log.resampled(DT) for log in logs]
        self.copies = copies   # the set is repeated: one copy per candidate model
        self.logs = one * copies
        self.servo = servo
        self.model = mujoco.MjModel.from_xml_string(_pendulum_xml(self.logs, timestep))
        self.data = mujoco.MjData(self.model)
        self.substeps = max(1, round(DT / timestep))
        n = len(self.logs)
        self.steps = max(len(log.t) for log in self.logs)
        self.length = np.array([len(log.t) for log in self.logs])
        pad = self.steps
        self.goal = np.array([np.pad(log.goal, (0, pad - len(log.t)), mode="edge")
                              for log in self.logs])
        self.enable = np.array([np.pad(log.torque_enable, (0, pad - len(log.t)), mode="edge")
                                for log in self.logs])
        self.recorded = np.array([np.pad(log.position, (0, pad - len(log.t)), mode="edge")
                                  for log in self.logs])
        self._act = np.arange(n)
        self._dof = np.arange(n)
        self._com = self.model.body_ipos[1:].copy()

    def _set_offset(self, offset: Floats) -> None:
        c = -self._com[:, 2]
        self.model.body_ipos[1:, 0] = -c * np.sin(offset)
        self.model.body_ipos[1:, 2] = -c * np.cos(offset)

    def replay(self, physics: ServoPhysics | Sequence[ServoPhysics], *,
               offset: float | Sequence[float] = 0.0) -> Floats:
        """Simulated positions [rad], one row per log (padded past each log's end); with
        ``copies`` > 1, one model and offset [rad] per copy of the set."""
        m, d = self.model, self.data
        models = [physics] * self.copies if isinstance(physics, ServoPhysics) else physics
        offsets = np.broadcast_to(np.asarray(offset, float), (self.copies,))
        n = len(self.logs) // self.copies
        arrays = ServoArrays([(self.servo, models[i // n], log_gains(self.servo, models[i // n], log.kp),
                               log.vin) for i, log in enumerate(self.logs)])
        arrays.install(m, self._act, self._dof)
        self._set_offset(np.repeat(offsets, n))
        mujoco.mj_resetData(m, d)
        d.qpos[:] = [log.position[0] for log in self.logs]
        d.qvel[:] = [log.speed[0] for log in self.logs]
        firmware = Firmware(arrays, d.qpos.copy())
        on = np.zeros(len(self.logs), dtype=bool)
        out = np.empty((len(self.logs), self.steps))
        for k in range(self.steps):
            enable = self.enable[:, k]
            if (enable != on).any():
                firmware.reset(d.qpos, enable & ~on)
                on = enable.copy()
                arrays.set_torque(m, self._act, self._dof, on)
            out[:, k] = d.qpos
            d.ctrl[:] = firmware.ctrl(self.goal[:, k], d.qpos, DT)
            if arrays.variable_friction:
                m.dof_frictionloss[:] = arrays.friction(d.qvel, d.actuator_force, on)
            mujoco.mj_step(m, d, self.substeps)
        return out

    def errors(self, simulated: Floats) -> Floats:
        """Mean |q_sim - q_log| per log [rad] (each over its own samples); shape
        (copies, logs of the set)."""
        diff = np.abs(simulated - self.recorded)
        valid = np.arange(self.steps) < self.length[:, None]
        per_log = (diff * valid).sum(axis=1) / self.length
        return per_log.reshape(self.copies, -1)
