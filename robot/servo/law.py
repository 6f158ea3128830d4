"""The servo law as a pure function of state, gains and voltage: what torque one servo's
output shaft gets (``robot.servo.physics`` states the law, ``robot.servo.firmware`` turns
gain registers into its terms).

This is the reference implementation on plain floats, one servo at a time: the emulator's
servos (``sim.emulator.servo_dynamics``) integrate it. The MuJoCo servo
(``sim.mujoco.servo_law``) carries the same law as MuJoCo parameters (an actuator, joint
damping, frictionloss, armature) so that the physics step runs it without Python;
``tests/test_emulator_dynamics.py`` holds the two to the same pendulum motion (an emulated
servo and the MuJoCo replay of its log: mean |difference| 0.001-0.002 rad on a sine, up
to 0.037 on a fast chirp), so the emulator and the sim cannot drift apart unnoticed.

The law, per servo (SI units: rad, rad/s, N m, V)::

    error  = setpoint - q, less the dead band (no drive within +-margin)
    duty   = clip(kp * error - kd * dq + ki * integral, -max_duty, +max_duty)
    motor  = kt * (V * duty - kt * dq) / R            torque on; 0 with the torque off
    torque = motor - viscous * dq - friction           (friction opposes the motion)
    friction = coulomb + stribeck * exp(-(dq / stribeck_speed)^2) + load_friction * |motor|

At rest (dq = 0) the friction holds the shaft while the other torques stay within it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot.servo.firmware import LawTerms
from robot.servo.physics import ServoPhysics


@dataclass(frozen=True)
class Law:
    """One servo's law at its gains and supply: the firmware terms and the physics.

    kp [duty/rad], kd [duty s/rad], ki [duty/(rad s)], margin [rad], max_velocity: the
    firmware's goal slew [rad/s] (inf: none); drive: kt V / R [N m per unit duty];
    max_duty; back_emf: kt^2 / R [N m s/rad]; viscous [N m s/rad]; coulomb, stribeck
    [N m]; stribeck_speed [rad/s]; load_friction [-]; armature [kg m^2]; kt [N m/A];
    stall: drive * max_duty [N m].
    """

    kp: float
    kd: float
    ki: float
    margin: float
    max_velocity: float
    drive: float
    max_duty: float
    back_emf: float
    viscous: float
    coulomb: float
    stribeck: float
    stribeck_speed: float
    load_friction: float
    armature: float
    kt: float

    @property
    def stall(self) -> float:
        return self.drive * self.max_duty

    @classmethod
    def of(cls, terms: LawTerms, physics: ServoPhysics, voltage: float) -> Law:
        """The law of a servo with ``physics`` at firmware ``terms`` and ``voltage`` [V]."""
        return cls(kp=terms.kp, kd=terms.kd, ki=terms.ki, margin=terms.margin,
                   max_velocity=terms.max_velocity,
                   drive=physics.kt * voltage / physics.resistance, max_duty=physics.max_duty,
                   back_emf=physics.back_emf_damping, viscous=physics.viscous,
                   coulomb=physics.coulomb, stribeck=physics.stribeck,
                   stribeck_speed=physics.stribeck_speed, load_friction=physics.load_friction,
                   armature=physics.armature, kt=physics.kt)


def slew(internal: float, goal: float, max_velocity: float, dt: float) -> float:
    """The firmware's internal goal after ``dt`` [s] of moving toward ``goal`` at no more
    than ``max_velocity`` [rad/s] (inf: it jumps)."""
    if math.isinf(max_velocity):
        return goal
    step = max_velocity * dt
    return min(max(goal, internal - step), internal + step)


def error(law: Law, setpoint: float, q: float) -> float:
    """The error the position law acts on [rad]: setpoint - q less the dead band."""
    e = setpoint - q
    return e - min(max(e, -law.margin), law.margin)


def duty(law: Law, setpoint: float, q: float, dq: float, integral: float) -> float:
    """The PWM duty (-max_duty..max_duty) at position ``q`` [rad], speed ``dq`` [rad/s] and
    the integral of the error ``integral`` [rad s]."""
    u = law.kp * error(law, setpoint, q) - law.kd * dq + law.ki * integral
    return min(max(u, -law.max_duty), law.max_duty)


def motor_torque(law: Law, duty_: float, dq: float, *, on: bool) -> float:
    """The motor's torque at the output [N m]: kt (V duty - kt dq) / R, or 0 with the
    torque off (the H-bridge open: no drive, no back-EMF braking)."""
    return law.drive * duty_ - law.back_emf * dq if on else 0.0


def friction(law: Law, dq: float, motor: float) -> float:
    """The gearbox's friction magnitude [N m] at speed ``dq`` [rad/s] with ``motor`` [N m]
    pushed through it (Coulomb, Stribeck, load term); at dq = 0 the most it can hold."""
    fade = math.exp(-(dq / law.stribeck_speed) ** 2) if law.stribeck else 0.0
    return law.coulomb + law.stribeck * fade + law.load_friction * abs(motor)


def output_torque(law: Law, setpoint: float, q: float, dq: float, integral: float, *,
                  on: bool) -> float:
    """The shaft's torque from the servo [N m] while it moves (dq != 0): motor, viscous
    and the friction against the motion."""
    motor = motor_torque(law, duty(law, setpoint, q, dq, integral), dq, on=on)
    return motor - law.viscous * dq - math.copysign(friction(law, dq, motor), dq)
