"""Operating modes: what a servo does with its goal registers, as data per control table.

Each layout names the register that selects the mode and what its values mean; a new
table (another X model, the SCS series) gets the behaviour by adding a row here.

- Dynamixel X (e-Manual XL430-W250, "Operating Mode(11)"): 1 velocity control (Goal
  Velocity(104), 0.229 rev/min, signed, within Velocity Limit(44)), 3 position control
  (default: Goal Position(116) within Min/Max Position Limit(52/48), one turn), 4 extended
  position (multi-turn, Goal Position within +-1,048,575), 16 PWM (Goal PWM(100) within PWM
  Limit(36), 885 = 100 %). The XL430 has no current sensing, so no 0 (current) or 5
  (current-based position): writing them is a Data Range Error.
- Feetech STS (memory table "Operation mode(33)"): 0 position servo, 1 constant speed
  (Goal Speed(46) [step/s], BIT15 the direction), 2 PWM open loop (Goal Time(44) 0-1000 of
  full duty, BIT10 the direction), 3 step servo (Goal Position(42) is a relative number of
  steps, BIT15 the direction).
- Dynamixel AX (e-Manual AX-12A, "CW/CCW Angle Limit(6/8)"): both 0 is wheel mode: Moving
  Speed(32) bits 0-9 are the output (0-1023 of full), bit 10 the direction (1 = CW).
  Otherwise joint mode (Goal Position within the limits).
"""

from __future__ import annotations

import enum
from typing import NamedTuple

from sim.emulator.servo_frame import sign_magnitude
from sim.emulator.servo_state import ServoState, kin


class Mode(enum.Enum):
    POSITION = "position"     # one turn, goal within the position limits
    EXTENDED = "extended"     # multi-turn position
    STEP = "step"             # multi-turn, each goal write a relative move (STS mode 3)
    VELOCITY = "velocity"     # a speed command [ticks/s]
    PWM = "pwm"               # an open-loop duty [-1..1]


class ModeSelect(NamedTuple):
    """register: the mode register (None: the table has none); modes: value -> Mode."""

    register: str | None
    modes: dict[int, Mode]


MODE_SELECT: dict[str, ModeSelect] = {
    "dynamixel_x": ModeSelect("operating_mode", {1: Mode.VELOCITY, 3: Mode.POSITION,
                                                 4: Mode.EXTENDED, 16: Mode.PWM}),
    "feetech_sts": ModeSelect("operating_mode", {0: Mode.POSITION, 1: Mode.VELOCITY,
                                                 2: Mode.PWM, 3: Mode.STEP}),
    "dynamixel_p1": ModeSelect(None, {}),     # wheel by angle limits (see module doc)
    # e-Manual XL-320 "Control Mode(11)": 1 wheel mode (Moving Speed(32) the output, bit 10
    # the direction, as the AX's wheel), 2 joint mode.
    "dynamixel_xl320": ModeSelect("control_mode", {1: Mode.PWM, 2: Mode.POSITION}),
    # Feetech SCS15 manual: both angle limits 0 is motor (wheel) mode; SCSCL.h's PWMMode
    # sets them so and WritePWM drives Goal Time(44), BIT10 the direction, as the STS's
    # PWM mode.
    "feetech_scs": ModeSelect(None, {}),
}
#: The two angle limits that, both 0, mean wheel mode, for tables without a mode register.
WHEEL_BY_LIMITS: dict[str, tuple[str, str]] = {
    "dynamixel_p1": ("cw_angle_limit", "ccw_angle_limit"),
    "feetech_scs": ("min_angle_limit", "max_angle_limit"),
}
# Keyed by family: every table of a family selects its mode the same way (the MX-28 on
# Protocol 1.0 as the AX; its both-4095 multi-turn setting is not modelled).
#: Modes whose present position counts turns (X, AX).
MULTI_TURN = frozenset({Mode.EXTENDED, Mode.STEP, Mode.VELOCITY, Mode.PWM})
#: STS Phase(18) BIT4 "angle feedback mode": 0 single-turn angle (whatever the mode),
#: 1 the full angle (what multi-turn use needs, memory table "Angle resolution(30)").
STS_FULL_ANGLE_BIT = 0x10
#: e-Manual: X Present/Goal Velocity unit [rev/min].
X_VELOCITY_UNIT_RPM = 0.229
#: e-Manual: X Goal PWM / PWM Limit full scale.
X_PWM_FULL = 885
#: STS memory table: Goal Time(44) full duty in PWM mode, BIT10 the direction.
STS_PWM_FULL = 1000
STS_PWM_SIGN_BIT = 10
STS_SPEED_SIGN_BIT = 15
#: AX Moving Speed in wheel mode: 0-1023 of full output, bit 10 = CW (negative).
P1_WHEEL_FULL = 1023
P1_WHEEL_CW_BIT = 10


def mode(servo: ServoState) -> Mode:
    """The servo's operating mode now (an unknown value behaves as position control)."""
    sel = MODE_SELECT[servo.family]
    if sel.register is None:
        low, high = WHEEL_BY_LIMITS[servo.family]
        wheel = servo.get(low) == 0 and servo.get(high) == 0
        return Mode.PWM if wheel else Mode.POSITION
    return sel.modes.get(servo.get(sel.register), Mode.POSITION)


def single_turn(servo: ServoState, mode: Mode) -> bool:
    """Whether Present Position reads within one turn now."""
    if servo.family == "feetech_sts":
        return not servo.get("phase") & STS_FULL_ANGLE_BIT
    return mode not in MULTI_TURN


def valid_modes(servo: ServoState) -> frozenset[int]:
    """Values the mode register accepts (empty: no mode register)."""
    return frozenset(MODE_SELECT[servo.family].modes)


def x_velocity_unit_ticks_s(resolution: int) -> float:
    """One X velocity unit (0.229 rev/min) in ticks/s."""
    return X_VELOCITY_UNIT_RPM * resolution / 60.0


def velocity_command(servo: ServoState) -> float:
    """Velocity mode: the commanded horn speed [ticks/s, signed]."""
    if servo.family == "dynamixel_x":
        return servo.get("goal_velocity") * x_velocity_unit_ticks_s(servo.model.resolution)
    return float(sign_magnitude(servo.get("goal_speed"), STS_SPEED_SIGN_BIT))


def duty_command(servo: ServoState) -> float:
    """PWM / wheel mode: the commanded duty [-1..1]."""
    if servo.family == "dynamixel_x":
        return servo.get("goal_pwm") / X_PWM_FULL
    if kin(servo.family) == "feetech_sts":
        return sign_magnitude(servo.get("goal_time"), STS_PWM_SIGN_BIT) / STS_PWM_FULL
    raw = servo.get("moving_speed")
    magnitude = (raw & ((1 << P1_WHEEL_CW_BIT) - 1)) / P1_WHEEL_FULL
    return -magnitude if raw >> P1_WHEEL_CW_BIT & 1 else magnitude
