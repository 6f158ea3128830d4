"""The servo model (``robot.servo.physics``, ``robot.servo.firmware``) as MuJoCo parameters
plus a little firmware state, vectorised over servos.

MuJoCo carries the part that must run every physics step:

- the actuator (``<position>``): gain kp' = kt V kp / R, bias -kp' q - kv' dq with
  kv' = kt V kd / R, force clipped to +-kt V max_duty / R: exactly
  kt V / R * clip(kp (ctrl - q) - kd dq, +-max_duty), the duty law through the motor's
  drive term;
- the joint's damping: kt^2 / R (back-EMF, only while the torque is on: with the torque off
  the H-bridge is open) plus the gearbox's viscous friction, integrated implicitly;
- the joint's frictionloss (Coulomb, plus the Stribeck and load terms of the last control
  tick's speed and motor torque) and armature (the rotor).

``Firmware`` runs once per control tick (the bus's 5 ms, or a log's sample): it slews the
internal goal at the firmware's speed limit, integrates the I term and applies the dead
band, and returns the actuator's ``ctrl``, so ctrl - q carries the whole law.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mujoco
import numpy as np
import numpy.typing as npt

from robot.config.robot import RobotConfig
from robot.servo.firmware import law_terms
from robot.servo.models import ServoModel
from robot.servo.physics import ServoPhysics

Floats = npt.NDArray[np.float64]
Ints = npt.NDArray[np.intp]


class ServoArrays:
    """Per-servo MuJoCo parameters for one chain (arrays in servo order).

    servos: (model, physics, gain registers, supply voltage [V]) per servo.
    """

    def __init__(self, servos: Sequence[tuple[ServoModel, ServoPhysics, Mapping[str, int], float]]
                 ) -> None:
        terms = [law_terms(m, p, g) for m, p, g, _ in servos]
        drive = np.array([p.kt * v / p.resistance for _, p, _, v in servos])  # [N m/duty]
        self.kp = drive * [t.kp for t in terms]                 # [N m/rad]
        self.kv = drive * [t.kd for t in terms]                 # [N m s/rad]
        self.ki_over_kp = np.array([t.ki / t.kp if t.kp else 0.0 for t in terms])  # [1/s]
        self.margin = np.array([t.margin for t in terms])       # [rad]
        self.max_velocity = np.array([t.max_velocity for t in terms])  # [rad/s]
        self.force = drive * [p.max_duty for _, p, _, _ in servos]     # [N m]
        self.back_emf = np.array([p.back_emf_damping for _, p, _, _ in servos])
        self.viscous = np.array([p.viscous for _, p, _, _ in servos])
        self.coulomb = np.array([p.coulomb for _, p, _, _ in servos])
        self.stribeck = np.array([p.stribeck for _, p, _, _ in servos])
        self.stribeck_speed = np.array([p.stribeck_speed for _, p, _, _ in servos])
        self.load_friction = np.array([p.load_friction for _, p, _, _ in servos])
        self.armature = np.array([p.armature for _, p, _, _ in servos])
        #: frictionloss changes with the state (updated once per control tick)
        self.variable_friction = bool(self.stribeck.any() or self.load_friction.any())

    def install(self, model: mujoco.MjModel, act: Ints, dof: Ints) -> None:
        """Write the constant parameters (force range, armature, frictionloss) into
        ``model`` for actuators ``act`` driving dofs ``dof``; the torque starts off."""
        model.actuator_forcerange[act] = np.stack([-self.force, self.force], axis=1)
        model.actuator_forcelimited[act] = 1
        model.dof_armature[dof] = self.armature
        model.dof_frictionloss[dof] = self.coulomb + self.stribeck
        self.set_torque(model, act, dof, np.zeros(len(act), dtype=bool))

    def set_torque(self, model: mujoco.MjModel, act: Ints, dof: Ints,
                   on: npt.NDArray[np.bool_]) -> None:
        """Torque on/off per servo: the drive and the back-EMF brake act only while on."""
        f = on.astype(float)
        model.actuator_gainprm[act, 0] = self.kp * f
        model.actuator_biasprm[act, 1] = -self.kp * f
        model.actuator_biasprm[act, 2] = -self.kv * f
        model.dof_damping[dof] = self.viscous + self.back_emf * f

    def friction(self, speed: Floats, drive: Floats, on: npt.NDArray[np.bool_]) -> Floats:
        """Gearbox friction [N m] at ``speed`` [rad/s] with the actuators' ``drive`` force
        [N m] (torque ``on`` per servo): Coulomb, Stribeck, and the load term on the motor
        torque (drive minus the back-EMF brake)."""
        fade = np.exp(-np.square(speed / self.stribeck_speed))
        motor = np.abs(drive - self.back_emf * speed * on)
        return self.coulomb + self.stribeck * fade + self.load_friction * motor


def robot_servos(robot: RobotConfig) -> ServoArrays:
    """The arrays for ``robot``'s joints: each servo's model, physics (a model file the
    robot file names, else the bundled one), gains and supply voltage."""
    return ServoArrays([(robot.servo(j), robot.servo_physics(j), robot.gains(j),
                         robot.voltage(j)) for j in robot.joints])


class Firmware:
    """The per-tick part of the law for one chain: goal slew, I term, dead band."""

    def __init__(self, arrays: ServoArrays, q0: Floats) -> None:
        self.arrays = arrays
        self.goal = np.array(q0, float)      # the firmware's internal goal [rad]
        self.integral = np.zeros(len(q0))    # integral of the error [rad s]
        self._slewed = bool(np.isfinite(arrays.max_velocity).any())
        self._integrating = bool(arrays.ki_over_kp.any())
        self._dead_band = bool(arrays.margin.any())
        #: the ctrl depends on the present position (dead band or I term)
        self.shapes = self._integrating or self._dead_band

    def reset(self, q: Floats, idx: Ints | npt.NDArray[np.bool_] | slice = slice(None)) -> None:
        """Torque on at ``q``: the internal goal starts at the present position."""
        self.goal[idx] = q[idx]
        self.integral[idx] = 0.0

    def ctrl(self, goal: Floats, q: Floats, dt: float) -> Floats:
        """The actuator's ctrl for this tick of ``dt`` [s] toward ``goal`` from ``q``."""
        a = self.arrays
        if self._slewed:
            step = a.max_velocity * dt
            self.goal = np.clip(goal, self.goal - step, self.goal + step)
        else:
            self.goal = goal
        return self.shape(self.goal, q, dt) if self.shapes else self.goal

    def shape(self, target: Floats, q: Floats, dt: float) -> Floats:
        """ctrl for the internal goal ``target`` [rad] at ``q``: the dead band (no drive
        within the margin) and the I term integrated over ``dt`` [s]."""
        a = self.arrays
        out = target
        if self._dead_band:
            out = out - np.clip(target - q, -a.margin, a.margin)
        if self._integrating:
            self.integral += (target - q) * dt
            out = out + a.ki_over_kp * self.integral
        return out


class ChainLaw:
    """The law installed in one MuJoCo model for a chain of servos: actuators ``act``
    driving dofs ``dof`` whose positions are ``qpos[qadr]``; the torque starts off."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, arrays: ServoArrays,
                 act: Ints, dof: Ints, qadr: Ints) -> None:
        self.model, self.data, self.arrays = model, data, arrays
        self.act, self.dof, self.qadr = act, dof, qadr
        arrays.install(model, act, dof)
        self.firmware = Firmware(arrays, data.qpos[qadr])
        self.enabled = np.zeros(len(act), dtype=bool)

    def set_torque(self, enabled: npt.NDArray[np.bool_]) -> None:
        """Torque per servo; a servo turned on restarts its I term at the present position."""
        turned_on = enabled & ~self.enabled
        if turned_on.any():
            self.firmware.reset(self.data.qpos[self.qadr], turned_on)
        self.enabled = enabled.copy()
        self.arrays.set_torque(self.model, self.act, self.dof, self.enabled)

    def ctrl(self, setpoint: Floats, span: float = 0.0) -> Floats:
        """The actuators' ctrl for ``setpoint`` [rad], the I term integrated over ``span``."""
        f = self.firmware
        return f.shape(setpoint, self.data.qpos[self.qadr], span) if f.shapes else setpoint

    def tick(self, setpoint: Floats, span: float) -> None:
        """Once per control tick of ``span`` [s]: the state-dependent friction from the
        state now, and the ctrl where the law depends on the position."""
        m, d, a = self.model, self.data, self.arrays
        if a.variable_friction:
            m.dof_frictionloss[self.dof] = a.friction(d.qvel[self.dof], d.actuator_force[self.act],
                                                      self.enabled)
        if self.firmware.shapes:
            d.ctrl[self.act] = self.ctrl(setpoint, span)
