"""The emulated servo's motion and what it reports of it.

A servo with a model (``sim.emulator.servo_dynamics``: every servo of a chain the emulator
builds, LX aside) moves by it; it is "moving" while its speed exceeds one position step
per ``MOVING_WINDOW_S``. Without one: constant-speed travel toward the goal while torque is on.

Speed: the model's no-load speed, or slower when the host set one: Dynamixel X Profile
Velocity(112) (0.229 rev/min per unit, 0 = no limit; X manual), Feetech STS Goal Speed(46)
(1 step/s per unit, 0 = maximum; STS memory table). Profile Acceleration / Acceleration are
not modelled (the servo reaches its speed at once). What the host reads back: Present
Position, Moving, Present Velocity (X, signed, 0.229 rev/min) / Present Speed (STS, bit 15
= direction), and on X Moving Status(123) bit 0 "in position" / bit 1 "profile ongoing".
"""

from __future__ import annotations

import math

from sim.emulator.control_tables import DXL_VELOCITY_UNIT_RPM, STS_SPEED_UNIT_TICKS_S
from sim.emulator.servo_state import ServoState

STS_DIRECTION_BIT = 0x8000
#: AX-12A Moving Speed(32) / Present Speed(38): 0.111 rev/min per unit, bits 0-9; bit 10
#: is the direction (CW) in Present Speed.
P1_SPEED_UNIT_RPM = 0.111
P1_SPEED_MASK = 0x3FF
P1_DIRECTION_BIT = 0x400
MOVING_IN_POSITION = 0x01
MOVING_PROFILE_ONGOING = 0x02
MOVING_WINDOW_S = 0.1          # [s] (see the module docstring)


def dxl_velocity_unit_ticks_s(resolution: int) -> float:
    """One X velocity unit (0.229 rev/min) in ticks/s."""
    return DXL_VELOCITY_UNIT_RPM * resolution / 60.0


def speed_ticks_s(servo: ServoState) -> float:
    """How fast the horn travels now [ticks/s]."""
    top = servo.speed_tps
    if servo.family == "dynamixel_x":
        pv = servo.get("profile_velocity")
        if pv > 0:
            return min(top, pv * dxl_velocity_unit_ticks_s(servo.model.resolution))
        return top
    if servo.family == "dynamixel_p1":
        ms = servo.get("moving_speed") & P1_SPEED_MASK    # 0: as fast as it can
        per_rpm = servo.model.ticks_per_rad * 2 * math.pi / 60.0
        return min(top, ms * P1_SPEED_UNIT_RPM * per_rpm) if ms > 0 else top
    gs = servo.get("goal_speed") & ~STS_DIRECTION_BIT
    return min(top, gs * STS_SPEED_UNIT_TICKS_S) if gs > 0 else top


def advance(servo: ServoState, pos: float, dt: float) -> float:
    """Move from ``pos`` [ticks] for ``dt`` [s]; update the feedback registers; new pos."""
    goal = servo.get("goal_position")
    torque = bool(servo.get("torque_enable"))
    velocity = 0.0
    dynamics = servo.dynamics
    if dynamics is not None:
        pos, velocity = dynamics.advance(servo, pos, dt)
        dynamics.report(servo, servo.names)
    elif torque and not servo.stuck and dt > 0:
        speed = speed_ticks_s(servo)
        step = speed * dt
        pos = min(goal, pos + step) if goal > pos else max(goal, pos - step)
        if pos != goal:
            velocity = speed if goal > pos else -speed
    present = round(pos)
    servo.set_raw("present_position", present)
    moving = (present != goal and torque if dynamics is None
              else abs(velocity) * MOVING_WINDOW_S > 1.0)
    servo.set("moving", int(moving))
    if servo.family == "dynamixel_x":
        servo.set("present_velocity",
                  round(velocity / dxl_velocity_unit_ticks_s(servo.model.resolution)))
        servo.set("moving_status", 0 if not torque else (
            MOVING_PROFILE_ONGOING if moving else MOVING_IN_POSITION))
    elif servo.family == "dynamixel_p1":
        per_unit = P1_SPEED_UNIT_RPM * servo.model.ticks_per_rad * 2 * math.pi / 60.0
        magnitude = min(round(abs(velocity) / per_unit), P1_SPEED_MASK)
        servo.set("present_speed", magnitude | (P1_DIRECTION_BIT if velocity < 0 else 0))
    else:
        magnitude = min(round(abs(velocity)), STS_DIRECTION_BIT - 1)
        servo.set("present_speed", magnitude | (STS_DIRECTION_BIT if velocity < 0 else 0))
    return pos
