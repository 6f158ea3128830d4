"""The emulated servo's motion: what the horn does in each operating mode while torque is on.

- Position modes (X 3 / 4, STS 0 / 3, AX joint) of a servo with a model
  (``servo.dynamics``, ``sim.emulator.servo_dynamics``): the servo model moves it toward
  the goal (through the homing offset, ``servo_frame``), torque on or off, and gives the
  motor state the load / current / PWM registers report; it is "moving" while its speed
  exceeds one position step per ``MOVING_WINDOW_S``.
- Position modes without one: constant-speed travel to the goal. Speed: the model's
  no-load speed, or slower when the host set one: X Profile Velocity(112) (0.229 rev/min,
  0 = no limit), STS Goal Speed(46) (1 step/s, 0 = maximum), AX Moving Speed(32) (0.111 rev/min, 0 = maximum).
  STS step mode (3) travels to the target its last goal write set (relative steps).
- Velocity mode (X 1, STS 1): the commanded speed, at most the no-load speed.
- PWM / wheel (X 16, STS 2, AX wheel): the commanded duty x the no-load speed (no load).

Acceleration (X Profile Acceleration, STS Acceleration) is not modelled: the speed is
reached at once. What the host reads back: Present Position (one turn in position mode,
counting turns in the others), Moving, Present Velocity (X, signed, 0.229 rev/min) /
Present Speed (STS, bit 15 = direction; AX, bit 10 = CW), X Moving Status(123) bit 0 "in
position" / bit 1 "profile ongoing", and present load / current / PWM
(``servo_effort``).
"""

from __future__ import annotations

import math

from sim.emulator import servo_effort, servo_frame, servo_modes
from sim.emulator.control_tables import STS_SPEED_UNIT_TICKS_S
from sim.emulator.servo_dynamics import VOLTAGE_REGISTERS
from sim.emulator.servo_modes import Mode
from sim.emulator.servo_state import ServoState, kin

STS_DIRECTION_BIT = 0x8000
STS_POSITION_SIGN_BIT = 15
#: AX-12A Moving Speed(32) / Present Speed(38): 0.111 rev/min per unit, bits 0-9; bit 10
#: is the direction (CW) in Present Speed.
P1_SPEED_UNIT_RPM = 0.111
P1_SPEED_MASK = 0x3FF
P1_DIRECTION_BIT = 0x400
MOVING_IN_POSITION = 0x01
MOVING_PROFILE_ONGOING = 0x02
POSITION_MODES = (Mode.POSITION, Mode.EXTENDED, Mode.STEP)
#: Registers this module and ``servo_effort`` compute (a test may pin them, ``servo.pin``).
COMPUTED = frozenset({"moving", "moving_status", "present_velocity", "present_speed",
                      "present_pwm", "present_load", "present_current", "present_voltage",
                      "present_input_voltage"})
MOVING_WINDOW_S = 0.1          # [s] (see the module docstring)


def dxl_velocity_unit_ticks_s(resolution: int) -> float:
    """One X velocity unit (0.229 rev/min) in ticks/s."""
    return servo_modes.x_velocity_unit_ticks_s(resolution)


def speed_ticks_s(servo: ServoState) -> float:
    """How fast the horn travels to a position goal now [ticks/s]."""
    top = servo.speed_tps
    if servo.family == "dynamixel_x":
        pv = servo.get("profile_velocity")
        if pv > 0:
            return min(top, pv * dxl_velocity_unit_ticks_s(servo.model.resolution))
        return top
    if kin(servo.family) == "dynamixel_p1":
        ms = servo.get("moving_speed") & P1_SPEED_MASK    # 0: as fast as it can
        per_rpm = servo.model.ticks_per_rad * 2 * math.pi / 60.0
        return min(top, ms * P1_SPEED_UNIT_RPM * per_rpm) if ms > 0 else top
    gs = servo.get("goal_speed") & ~STS_DIRECTION_BIT
    return min(top, gs * STS_SPEED_UNIT_TICKS_S) if gs > 0 else top


def target(servo: ServoState, mode: Mode) -> float:
    """Where a position mode takes the horn [ticks, actual]."""
    if mode is Mode.STEP:
        return servo.step_target
    goal = servo_frame.actual_goal(servo, servo.get("goal_position"))
    if mode is Mode.POSITION and kin(servo.family) == "feetech_sts":
        return float(goal % servo.model.resolution)
    return float(goal)


def advance(servo: ServoState, pos: float, dt: float) -> float:
    """Move from ``pos`` [ticks, actual] for ``dt`` [s]; update the feedback registers;
    return the new position."""
    mode = servo_modes.mode(servo)
    torque = bool(servo.get("torque_enable"))
    free = torque and not servo.stuck     # the velocity read back does not depend on dt
    velocity, error, duty = 0.0, 0.0, None
    dynamics = servo.dynamics
    if dynamics is not None and mode in POSITION_MODES:
        pos, velocity = dynamics.advance(servo, pos, target(servo, mode), dt, torque=torque,
                                         stuck=servo.stuck)
        moving = abs(velocity) * MOVING_WINDOW_S > 1.0
        _feedback(servo, mode, pos, velocity, moving=moving, torque=torque)
        servo_effort.write_effort(servo, servo_effort.Effort(
            dynamics.duty, dynamics.torque_share, dynamics.current_a))
        for name in VOLTAGE_REGISTERS:
            if name in servo.table:
                servo.set_raw(name, dynamics.voltage_tenths)
        return pos
    if mode in POSITION_MODES:
        goal = target(servo, mode)
        speed = speed_ticks_s(servo)
        if free:
            step = speed * dt
            pos = min(goal, pos + step) if goal > pos else max(goal, pos - step)
            if pos != goal:
                velocity = speed if goal > pos else -speed
        error = goal - pos
        moving = torque and round(pos) != round(goal)
        if not moving:       # within half a tick of its goal it has stopped: the servo is
            velocity = 0.0   # at rest (and is no longer stepped), so it reads 0 speed
    else:
        top = servo.speed_tps
        if mode is Mode.VELOCITY:
            command = max(-top, min(top, servo_modes.velocity_command(servo)))
        else:
            duty = servo_modes.duty_command(servo)
            command = duty * top
        if free:
            pos += command * dt
            velocity = command
        moving = torque and velocity != 0
    _feedback(servo, mode, pos, velocity, moving=moving, torque=torque)
    servo_effort.write_effort(servo, servo_effort.estimate(
        servo, torque_on=torque, velocity=velocity, error_ticks=error, duty=duty))
    return pos


def at_rest(servo: ServoState) -> bool:
    """Not moving, and (with a model) held by friction with nothing left to change: its
    registers hold until something is set."""
    return not servo.get("moving") and (servo.dynamics is None or servo.dynamics.resting)


def _feedback(servo: ServoState, mode: Mode, pos: float, velocity: float, *,
              moving: bool, torque: bool) -> None:
    single = servo_modes.single_turn(servo, mode)
    present = servo_frame.present(servo, pos, single_turn=single)
    if kin(servo.family) == "feetech_sts":
        present = servo_frame.to_sign_magnitude(present, STS_POSITION_SIGN_BIT)
    elif kin(servo.family) == "dynamixel_p1":
        turn = servo.model.resolution * 360.0 / servo.model.span_deg
        present = min(servo.model.resolution - 1, int(pos % turn)) if not single else present
    servo.set_raw("present_position", present)
    servo.set_raw("moving", int(moving))
    if servo.family == "dynamixel_x":
        servo.set_raw("present_velocity",
                      round(velocity / dxl_velocity_unit_ticks_s(servo.model.resolution)))
        servo.set_raw("moving_status", 0 if not torque else (
            MOVING_PROFILE_ONGOING if moving else MOVING_IN_POSITION))
    elif kin(servo.family) == "dynamixel_p1":
        # Joint mode: 0.111 rev/min a unit; wheel mode: the output share, 0-1023 (AX-12A
        # e-Manual, Present Speed(38)).
        per_unit = (servo.speed_tps / P1_SPEED_MASK if mode is Mode.PWM else
                    P1_SPEED_UNIT_RPM * servo.model.ticks_per_rad * 2 * math.pi / 60.0)
        magnitude = min(round(abs(velocity) / per_unit), P1_SPEED_MASK)
        servo.set_raw("present_speed", magnitude | (P1_DIRECTION_BIT if velocity < 0 else 0))
    else:
        magnitude = min(round(abs(velocity)), STS_DIRECTION_BIT - 1)
        servo.set_raw("present_speed", magnitude | (STS_DIRECTION_BIT if velocity < 0 else 0))
