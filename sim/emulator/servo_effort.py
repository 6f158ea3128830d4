"""Present load, current and PWM: the read-back registers as one function of the motor state.

:class:`Effort` is the motor's state in physical terms (duty, the share of stall torque
the motor makes, its current); :func:`write_effort` turns it into each table's registers.
Whatever computes the motor state (the kinematic estimate below, or the physical servo
model when it drives the emulator) feeds that one function, so the registers stay
consistent with one another.

Registers (each written only where the servo's table has it):

- Dynamixel X (e-Manual XL430-W250): Present PWM(124) = duty x 885 (PWM Limit's 100 %);
  Present Load(126) [0.1 % of maximum torque, signed]; Present Current(126) on models with
  current sensing [2.69 mA, signed].
- Feetech STS (memory table): Present Load(60) "the voltage duty cycle of the current
  control output driving motor" [0.1 %, BIT10 the direction]; Present Current(69) [6.5 mA].
- Dynamixel AX (e-Manual AX-12A): Present Load(40) 0-1023 of maximum torque, bit 10 the
  direction (1 = CW, negative).

:func:`estimate` is the kinematic emulator's motor state: a DC motor with no load on its
horn (torque = stall x (duty - speed / no-load speed)) driven by the firmware's position
law where it holds a position (X: KPP = P / 128 of PWM 885 per tick, e-Manual; STS 0.166
duty per P unit and radian, measured on an STS3215 by Rhoban/bam, and 0.158 on MX-64/106
for the MX Protocol 1.0 P Gain; AX: full output over the compliance slope past the
margin), by the speed it travels at where it moves (the duty that sustains it against
back-EMF), and by the command in PWM / wheel modes. With nothing
on the horn a free servo reads load ~0 and a jammed one (``stuck``) its holding effort.
"""

from __future__ import annotations

from dataclasses import dataclass

from sim.emulator.servo_frame import to_sign_magnitude
from sim.emulator.servo_state import ServoState, kin

#: Register scales.
X_PWM_FULL = 885
X_CURRENT_UNIT_A = 2.69e-3
LOAD_UNIT = 1e-3                 # 0.1 %
STS_LOAD_SIGN_BIT = 10
STS_CURRENT_UNIT_A = 6.5e-3
P1_LOAD_FULL = 1023
P1_LOAD_CW_BIT = 10
#: Position-law scales (see the module doc).
X_KPP_DIVISOR = 128.0
STS_DUTY_PER_P_RAD = 0.166
MX_DUTY_PER_P_RAD = 0.158
XL320_DUTY_PER_P_RAD = 0.0505     # Rhoban/bam, XL-320 (oscilloscope)
#: Stall (locked-rotor) current at the nominal voltage [A], where a datasheet gives one:
#: Feetech STS3215 (7.4 V): 2.7 A; ROBOTIS e-Manual XM430-W350 (12 V): 2.3 A.
STALL_CURRENT_A: dict[str, float] = {"STS3215": 2.7, "XM430-W350": 2.3}


@dataclass(frozen=True)
class Effort:
    """duty: motor PWM duty [-1..1]; torque: output torque as a share of stall [-1..1];
    current_a: motor current [A] (None: the model's stall current is not known)."""

    duty: float
    torque: float
    current_a: float | None


def _clip(x: float) -> float:
    return max(-1.0, min(1.0, x))


def holding_duty(servo: ServoState, error_ticks: float) -> float:
    """The firmware position law's duty for a position error [ticks, goal - present]."""
    t = servo.table
    if "position_p_gain" in t:
        return _clip(servo.get("position_p_gain") / X_KPP_DIVISOR * error_ticks / X_PWM_FULL)
    if "p_gain" in t:               # MX on Protocol 1.0: 0.158 duty per P unit and radian
        per_p = XL320_DUTY_PER_P_RAD if servo.family == "dynamixel_xl320" else MX_DUTY_PER_P_RAD
        per_tick = per_p / servo.model.ticks_per_rad
        return _clip(servo.get("p_gain") * per_tick * error_ticks)
    if "p_coefficient" in t:
        per_tick = STS_DUTY_PER_P_RAD / servo.model.ticks_per_rad
        return _clip(servo.get("p_coefficient") * per_tick * error_ticks)
    if "cw_compliance_slope" in t:
        cw = error_ticks < 0
        margin = servo.get("cw_compliance_margin" if cw else "ccw_compliance_margin")
        slope = max(1, servo.get("cw_compliance_slope" if cw else "ccw_compliance_slope"))
        past = max(0.0, abs(error_ticks) - margin) / slope
        return -_clip(past) if cw else _clip(past)
    return 0.0


def estimate(servo: ServoState, *, torque_on: bool, velocity: float, error_ticks: float,
             duty: float | None) -> Effort:
    """The motor state of the kinematic emulator: torque on or off, ``velocity``
    [ticks/s], the position error it holds against [ticks], the commanded duty in PWM /
    wheel modes (else None)."""
    free = velocity / servo.speed_tps if servo.speed_tps else 0.0
    if not torque_on:
        d = 0.0
    elif duty is not None:
        d = _clip(duty)
    elif velocity:
        d = _clip(free)
    else:
        d = holding_duty(servo, error_ticks)
    torque = _clip(d - free) if torque_on else 0.0
    stall = STALL_CURRENT_A.get(servo.model.name)
    return Effort(d, torque, None if stall is None else abs(torque) * stall)


def write_effort(servo: ServoState, effort: Effort) -> None:
    """Store ``effort`` in the read-back registers the servo's table has."""
    t = servo.table
    if servo.family == "dynamixel_x":
        if "present_pwm" in t:
            servo.set_raw("present_pwm", round(effort.duty * X_PWM_FULL))
        if "present_current" in t and effort.current_a is not None:
            sign = -1 if effort.torque < 0 else 1
            servo.set_raw("present_current", sign * round(effort.current_a / X_CURRENT_UNIT_A))
        elif "present_load" in t:
            servo.set_raw("present_load", round(effort.torque / LOAD_UNIT))
    elif kin(servo.family) == "feetech_sts":
        servo.set_raw("present_load", to_sign_magnitude(
            round(effort.duty / LOAD_UNIT), STS_LOAD_SIGN_BIT))
        if "present_current" in t and effort.current_a is not None:
            servo.set_raw("present_current", round(effort.current_a / STS_CURRENT_UNIT_A))
    elif "present_load" in t:
        magnitude = min(P1_LOAD_FULL, round(abs(effort.torque) * P1_LOAD_FULL))
        servo.set_raw("present_load", magnitude | (1 << P1_LOAD_CW_BIT if effort.torque < 0
                                                   else 0))
