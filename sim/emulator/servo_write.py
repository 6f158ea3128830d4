"""How an emulated servo checks and applies a host write (after indirect translation).

``plan`` decides, without changing anything, whether the bytes land in whole writable
registers and every value is allowed; ``apply`` stores the values and does what the write
sets off. The errors follow the manuals:

- Dynamixel X, Protocol 2.0 status errors (e-Manual "Protocol 2.0", Status Packet): Access
  7 for a read-only or undefined address, or EEPROM / Indirect Address while Torque Enable
  is 1; Data Range 4 for a value outside the register's range (an Operating Mode the model
  lacks, an extended-mode goal past +-1,048,575); Data Limit 6 for a value past its limit
  register (Goal Position outside Min/Max Position Limit in position mode, Goal Velocity
  past Velocity Limit(44), Goal PWM past PWM Limit(36)); Data Length 5 for part of a
  register.
- Protocol 1.0 (AX) has no access code: a read-only or undefined address and a value out
  of range get the Range Error bit, a goal outside the angle limits the Angle Limit bit
  (``dxl1_protocol``).
- Feetech STS answers no write with an error: it ignores a refused one.

What a write sets off (the manuals' behaviour): STS Torque Enable = 128 re-centres (the
offset that makes the present position read 2048 goes to register 31 and the EEPROM;
``servo_frame.centre_offset``); an STS goal in position mode is clamped to the angle limits
and turns torque on (the STS3215 moves on a goal with Torque Enable 0, which Feetech's own
examples rely on), as does a speed in wheel mode or a duty in PWM mode (Feetech's
``WheelMode`` + ``WriteSpe`` example sends no torque enable); an STS goal in step mode
moves that many steps from where the horn is; a change of operating mode holds the horn
where it is (entering position mode, within one turn).
"""

from __future__ import annotations

from sim.emulator import servo_frame, servo_modes
from sim.emulator.control_tables import BAUD_CODES, INDIRECT_TARGET_RANGE, Entry
from sim.emulator.servo_modes import Mode
from sim.emulator.servo_state import PROTOCOL_2, ServoState, WriteError, decode_value, kin

#: Allowed raw values of a few registers [inclusive range]; others accept any value.
VALID_RANGE: dict[str, tuple[int, int]] = {
    "torque_enable": (0, 1),
    "led": (0, 1),
    "status_return_level": (0, 2),
    "return_delay_time": (0, 254),
    "id": (0, 252),
}
#: STS memory table, Torque switch(40): 0 off, 1 on, 128 "current position correction to
#: 2048".
STS_CENTRE_COMMAND = 128
#: Registers that take a set of values rather than a range, per family.
VALID_VALUES: dict[str, dict[str, frozenset[int]]] = {
    "feetech_sts": {"torque_enable": frozenset({0, 1, STS_CENTRE_COMMAND})},
    # e-Manual XL-320 LED(25): 0-7, three colour bits.
    "dynamixel_xl320": {"led": frozenset(range(8))},
}
#: X: limit registers a goal must stay within (value, its limit register) and the mode.
X_LIMITS: dict[str, tuple[str, Mode]] = {
    "goal_velocity": ("velocity_limit", Mode.VELOCITY), "goal_pwm": ("pwm_limit", Mode.PWM),
}
X_EXTENDED_GOAL = 1_048_575      # e-Manual: Goal Position range in extended position mode
#: STS registers whose write energises the servo, and in which modes.
STS_ENERGISING: dict[str, frozenset[Mode]] = {
    "goal_position": frozenset({Mode.POSITION, Mode.STEP}),
    "goal_speed": frozenset({Mode.VELOCITY}), "goal_time": frozenset({Mode.PWM}),
}
STS_STEP_SIGN_BIT = 15
#: A dual-axis case's settings both axes hold as one (sim/emulator/dual_axis.py).
CASE_SHARED = frozenset({"baud_rate", "protocol_type"})


def plan(servo: ServoState, address: int, data: bytes) -> tuple[WriteError, dict[str, int]]:
    """(error, name -> value to store); nothing is changed."""
    end = address + len(data)
    if address < 0 or end > len(servo.mem) or not data:
        return WriteError.ACCESS, {}
    touched: list[tuple[str, Entry]] = []
    for a in range(address, end):
        owner = servo.owner[a]
        if not owner:
            return WriteError.ACCESS, {}
        name, reg = servo.regs[owner - 1]
        if not touched or touched[-1][0] != name:
            touched.append((name, reg))
    if touched[0][1].address < address or touched[-1][1].address + touched[-1][1].size > end:
        return WriteError.LENGTH, {}
    dxl = servo.family in PROTOCOL_2
    torque = bool(servo.get("torque_enable"))
    values: dict[str, int] = {}
    for name, reg in touched:
        if reg.access == "R":
            return WriteError.ACCESS, {}
        locked = reg.address < servo.eeprom_end or name.startswith("indirect_address")
        if dxl and locked and torque:
            return WriteError.ACCESS, {}
        raw = data[reg.address - address:reg.address - address + reg.size]
        values[name] = decode_value(servo.family, reg.address, raw)
        err = check(servo, name, values[name])
        if err is not WriteError.NONE:
            return err, {}
        if (name == "goal_position" and kin(servo.family) == "feetech_sts"
                and servo_modes.mode(servo) is Mode.POSITION):
            values[name] = min(max(values[name], servo.get("min_angle_limit")),
                               servo.get("max_angle_limit"))
    return WriteError.NONE, values


def check(servo: ServoState, name: str, value: int) -> WriteError:
    """Whether ``value`` may go into register ``name``."""
    allowed = VALID_VALUES.get(servo.family, {}).get(name)
    lo_hi = None if allowed is not None else VALID_RANGE.get(name)
    if name.startswith("indirect_address"):
        lo_hi = INDIRECT_TARGET_RANGE
    if lo_hi and not lo_hi[0] <= value <= lo_hi[1]:
        return WriteError.RANGE
    if allowed is not None and value not in allowed:
        return WriteError.RANGE
    if name == "operating_mode" and value not in servo_modes.valid_modes(servo):
        return WriteError.RANGE
    if name == "baud_rate" and value not in BAUD_CODES[servo.family]:
        return WriteError.RANGE
    wd = servo.watchdog
    if wd is not None and name == wd.register and not wd.accepts(value):
        return WriteError.RANGE
    partner = servo.partner
    if name == "id" and partner is not None and value == partner.get("id"):
        return WriteError.LIMIT     # 2XL430: both axes one id is a Data Limit Error
    if servo.watchdog_tripped and name in ("goal_position", "goal_velocity", "goal_pwm"):
        return WriteError.RANGE     # goals are read-only until the watchdog is cleared
    if servo.family == "dynamixel_x":
        return _check_x(servo, name, value)
    if (name == "goal_position" and kin(servo.family) == "dynamixel_p1"
            and servo_modes.mode(servo) is Mode.POSITION
            and not servo.get("cw_angle_limit") <= value <= servo.get("ccw_angle_limit")):
        return WriteError.LIMIT     # AX: Angle Limit Error, the goal is not taken
    return WriteError.NONE


def _check_x(servo: ServoState, name: str, value: int) -> WriteError:
    mode = servo_modes.mode(servo)
    if name == "goal_position" and mode is Mode.POSITION and not (
            servo.get("min_position_limit") <= value <= servo.get("max_position_limit")):
        return WriteError.LIMIT
    if name == "goal_position" and mode is Mode.EXTENDED and abs(value) > X_EXTENDED_GOAL:
        return WriteError.RANGE
    limit = X_LIMITS.get(name)
    if limit is not None and abs(value) > servo.get(limit[0]):
        return WriteError.LIMIT
    return WriteError.NONE


def apply(servo: ServoState, values: dict[str, int]) -> None:
    """Store planned values and do what they set off (module doc). Torque stays off while
    an X servo is in shutdown; registers in ``servo.frozen`` keep their value."""
    shutdown = servo.family in PROTOCOL_2 and servo.get("hardware_error_status") != 0
    sts = kin(servo.family) == "feetech_sts"
    mode_before = servo_modes.mode(servo)
    for name, v in values.items():
        if name == "torque_enable" and shutdown:
            continue  # refused while in shutdown; the status carries the alert bit
        if name in servo.frozen:
            continue  # injected fault: acknowledged, not stored (a read-back shows it)
        if sts and name == "torque_enable" and v == STS_CENTRE_COMMAND:
            servo.set_raw("homing_offset", servo_frame.centre_offset(servo, servo.horn))
            servo.hold()
            continue
        servo.set(name, v)
        if name in CASE_SHARED and servo.partner is not None:
            servo.partner.follow(name, v)     # one communication module: both axes
    mode = servo_modes.mode(servo)
    if mode is not mode_before:
        if mode is Mode.POSITION:
            servo.horn = servo_frame.within_turn(servo, servo.horn)
        servo.hold()
        return
    if sts and mode is Mode.STEP and "goal_position" in values:
        steps = servo_frame.sign_magnitude(values["goal_position"], STS_STEP_SIGN_BIT)
        servo.step_target = servo.horn + steps
    if sts and "torque_enable" not in values and any(
            mode in STS_ENERGISING.get(n, ()) for n in values):
        servo.set("torque_enable", 1)
