"""Where the horn is and what the servo says it is: the homing offset between the two.

The emulator keeps the horn's actual position in encoder ticks (a float, several turns
when a multi-turn mode spins it); the position registers are that position seen through
the servo's offset, as each manual defines it:

- Dynamixel X (e-Manual XL430-W250, "Homing Offset(20)"): Present Position = Actual
  Position + Homing Offset (two's complement). Goal Position is in the same frame, so the
  horn goes to Goal - Offset.
- Feetech STS (memory table "Position correction(31)": BIT11 the direction bit, 0-2047
  steps; LeRobot's ``FeetechMotorsBus._get_half_turn_homings``: Present = Actual - Offset):
  Present Position = (raw - Offset) mod 4096 in position mode (single-turn feedback, phase
  BIT4 = 0); feetech-cli's ``set_zero`` gives the same relation measured on an STS3215.
  Goal Position is in the same frame: the horn goes to Goal + Offset.
- Dynamixel Protocol 1.0 (AX, MX-28 on 1.0 firmware): no offset register; present = actual.

Writing 128 to the STS Torque Enable (40) makes the present position read 2048 ("Write
128: arbitrary current position correction to 2048", STS memory table; Feetech's own
``SMS_STS::CalibrationOfs`` is exactly that write): :func:`centre_offset` is the offset
that does it (raw - 2048, i.e. Present = raw - Offset = 2048), stored in register 31.
"""

from __future__ import annotations

from sim.emulator.servo_state import ServoState

#: STS "Position correction(31)": sign in bit 11, magnitude 0..2047 steps.
STS_OFFSET_SIGN_BIT = 11
STS_OFFSET_MAX = (1 << STS_OFFSET_SIGN_BIT) - 1
#: What STS Torque Enable = 128 makes the present position read.
STS_CENTRE = 2048


def sign_magnitude(raw: int, sign_bit: int) -> int:
    """A Feetech sign-magnitude register value as a signed int."""
    magnitude = raw & ((1 << sign_bit) - 1)
    return -magnitude if raw >> sign_bit & 1 else magnitude


def to_sign_magnitude(value: int, sign_bit: int) -> int:
    """A signed int as a Feetech sign-magnitude register value (magnitude clipped)."""
    magnitude = min(abs(value), (1 << sign_bit) - 1)
    return magnitude | (1 << sign_bit if value < 0 else 0)


def offset(servo: ServoState) -> int:
    """The offset [ticks] in the register's own sign convention (X: +, STS: -)."""
    if "homing_offset" not in servo.table:
        return 0
    value = servo.get("homing_offset")
    if servo.family == "feetech_sts":
        return sign_magnitude(value, STS_OFFSET_SIGN_BIT)
    return value


def present(servo: ServoState, actual: float, *, single_turn: bool) -> int:
    """The Present Position register for the horn at ``actual`` [ticks]."""
    ticks = round(actual)
    if servo.family == "feetech_sts":
        ticks -= offset(servo)
        return ticks % servo.model.resolution if single_turn else ticks
    return ticks + offset(servo)


def actual_goal(servo: ServoState, goal: int) -> int:
    """Where the horn goes [ticks] for a Goal Position register value ``goal``."""
    if servo.family == "feetech_sts":
        return goal + offset(servo)
    return goal - offset(servo)


def goal_for(servo: ServoState, actual: float) -> int:
    """The Goal Position register value that holds the horn at ``actual`` [ticks]."""
    ticks = round(actual)
    if servo.family == "feetech_sts":
        return (ticks - offset(servo)) % servo.model.resolution
    return ticks + offset(servo)


def within_turn(servo: ServoState, ticks: float) -> float:
    """``ticks`` [actual] brought into the encoder's one turn (the AX's 1024 steps span 300
    of its 360 degrees)."""
    return ticks % (servo.model.resolution * 360.0 / servo.model.span_deg)


def centre_offset(servo: ServoState, actual: float) -> int:
    """STS Torque Enable = 128: the register-31 value that makes the horn at ``actual``
    read :data:`STS_CENTRE` (raw - 2048 of the raw encoder reading within the turn)."""
    raw = round(actual) % servo.model.resolution
    return to_sign_magnitude(raw - STS_CENTRE, STS_OFFSET_SIGN_BIT)
