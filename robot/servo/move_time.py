"""How fast a servo swings a load: the trajectory of one joint driven by its servo law
(``robot.servo.law``: the firmware's position law at the robot's gains, the DC motor at
the supply voltage, the gearbox's friction, the rotor's armature) against a rigid load,
for a goal that the driver slews toward its target at the joint's slew limit.

The load is a pendulum about the joint's axis: ``inertia`` [kg m^2] (the limb's, the
servo's armature is added from its law) and a gravity torque -m g r sin(q) for a limb
of ``mass`` [kg] whose centre of mass hangs ``arm`` [m] below the axis at q = 0 (q in rad
from hanging straight down). The ODE

    (inertia + armature) q'' = servo torque(goal(t), q, q') - m g r sin(q)

is integrated with semi-implicit Euler at ``dt``; the servo torque is the law's
(``output_torque``) while the shaft moves, and the shaft sticks while the drive stays
within the gearbox's static friction (``friction`` at zero speed). Used for the shortest
step time a robot's legs allow (robot.balance.capture_robot), not for the simulation
(MuJoCo integrates the same law: sim.mujoco.servo_law).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from robot.servo.law import Law, duty, friction, motor_torque, output_torque

GRAVITY = 9.81  # [m/s^2]


class Load(NamedTuple):
    """A limb on the joint: inertia about the axis [kg m^2] (without the servo's
    armature), mass [kg], arm: its centre of mass below the axis at q = 0 [m]."""

    inertia: float
    mass: float = 0.0
    arm: float = 0.0


def trajectory(law: Law, load: Load, *, start: float, target: float, slew: float,
               times: npt.ArrayLike, dt: float = 2e-4) -> npt.NDArray[np.float64]:
    """The joint's angle [rad] at each of ``times`` [s, ascending, >= 0] after the driver
    starts moving the goal from ``start`` toward ``target`` [rad] at ``slew`` [rad/s] (inf:
    at once; the firmware's own goal slew, ``law.max_velocity``, also applies), the joint
    starting at rest at ``start`` (holding it: the gravity torque is met by the servo's
    error, found first)."""
    t_out = np.asarray(times, dtype=float)
    out = np.empty(len(t_out))
    inertia = load.inertia + law.armature
    if inertia <= 0.0:
        raise ValueError(f"trajectory: the load's inertia must be > 0, got {inertia}")
    rate = min(slew, law.max_velocity)
    sign = 1.0 if target >= start else -1.0
    q = _holding(law, load, start)
    dq, t, k = 0.0, 0.0, 0
    n = len(t_out)
    while k < n:
        while k < n and t_out[k] <= t + 1e-12:
            out[k] = q
            k += 1
        goal = target if math.isinf(rate) else start + sign * min(rate * t, abs(target - start))
        tau_g = -load.mass * GRAVITY * load.arm * math.sin(q)
        if dq == 0.0:
            drive = motor_torque(law, duty(law, goal, q, 0.0, 0.0), 0.0, on=True) + tau_g
            if abs(drive) <= friction(law, 0.0, drive - tau_g):
                t += dt
                continue
            acc = (drive - math.copysign(friction(law, 0.0, drive - tau_g), drive)) / inertia
        else:
            acc = (output_torque(law, goal, q, dq, 0.0, on=True) + tau_g) / inertia
        new = dq + acc * dt
        # Friction stops the shaft rather than turn it back within one step.
        dq = 0.0 if dq != 0.0 and new * dq < 0.0 else new
        q += dq * dt
        t += dt
    return out


def _holding(law: Law, load: Load, q: float) -> float:
    """Where the servo holds the load with its goal at ``q`` [rad]: the angle at which
    its static torque meets gravity (its error is small next to a step: fixed-point
    iteration from ``q``)."""
    stiffness = law.kp * law.drive
    if load.mass == 0.0 or load.arm == 0.0 or stiffness <= 0.0:
        return q
    x = q
    for _ in range(50):
        x = q - load.mass * GRAVITY * load.arm * math.sin(x) / stiffness
    return x


def time_to(law: Law, load: Load, *, start: float, target: float, slew: float,
            reach: float, horizon: float = 2.0, dt: float = 2e-4) -> float:
    """The first time [s] the joint, driven from ``start`` toward ``target`` [rad] as in
    ``trajectory``, passes ``reach`` [rad, between the two]; inf if not within
    ``horizon`` [s]."""
    times = np.arange(0.0, horizon + dt / 2, dt)
    q = trajectory(law, load, start=start, target=target, slew=slew, times=times, dt=dt)
    passed = (q >= reach) if target >= start else (q <= reach)
    hit = np.flatnonzero(passed)
    return float(times[hit[0]]) if len(hit) else math.inf
