"""How an emulated servo checks and applies a host write (after indirect translation).

``plan`` decides, without changing anything, whether the bytes land in whole writable
registers and every value is allowed; ``apply`` stores the values. The errors follow the
manuals: X Protocol 2.0 status errors (Access 7: read-only, undefined, or EEPROM / Indirect
Address while Torque Enable is 1; Data Range 4; Data Limit 6: goal outside the position
limits in position mode; Data Length 5: part of a register). Feetech STS clamps a goal to
its angle limits and, on a goal write in position mode, turns torque on (the STS3215 moves
on a goal with Torque Enable 0, which Feetech's own examples rely on).
"""

from __future__ import annotations

from sim.emulator.control_tables import BAUD_CODES, INDIRECT_TARGET_RANGE, Entry
from sim.emulator.servo_state import ServoState, WriteError, decode_value

#: Allowed raw values of a few registers [inclusive range]; others accept any value.
VALID_RANGE: dict[str, tuple[int, int]] = {
    "torque_enable": (0, 1),
    "led": (0, 1),
    "status_return_level": (0, 2),
    "return_delay_time": (0, 254),
    "id": (0, 252),
}
POSITION_MODE = {"dynamixel_x": 3, "feetech_sts": 0}


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
    dxl = servo.family == "dynamixel_x"
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
        if name == "goal_position" and servo.family == "feetech_sts":
            values[name] = min(max(values[name], servo.get("min_angle_limit")),
                               servo.get("max_angle_limit"))
    return WriteError.NONE, values


def check(servo: ServoState, name: str, value: int) -> WriteError:
    lo_hi = VALID_RANGE.get(name)
    if name.startswith("indirect_address"):
        lo_hi = INDIRECT_TARGET_RANGE
    if lo_hi and not lo_hi[0] <= value <= lo_hi[1]:
        return WriteError.RANGE
    if name == "baud_rate" and value not in BAUD_CODES[servo.family]:
        return WriteError.RANGE
    wd = servo.watchdog
    if wd is not None and name == wd.register and not wd.accepts(value):
        return WriteError.RANGE
    if name == "goal_position" and servo.watchdog_tripped:
        return WriteError.RANGE     # goals are read-only until the watchdog is cleared
    if (name == "goal_position" and servo.family == "dynamixel_x"
            and servo.get("operating_mode") == POSITION_MODE["dynamixel_x"]
            and not servo.get("min_position_limit") <= value <= servo.get("max_position_limit")):
        return WriteError.LIMIT
    if (name == "goal_position" and servo.family == "dynamixel_p1"
            and not servo.get("cw_angle_limit") <= value <= servo.get("ccw_angle_limit")):
        return WriteError.LIMIT     # AX: Angle Limit Error, the goal is not taken
    return WriteError.NONE


def apply(servo: ServoState, values: dict[str, int]) -> None:
    """Store planned values (torque stays off while an X servo is in shutdown; registers in
    ``servo.frozen`` keep their value)."""
    shutdown = servo.family == "dynamixel_x" and servo.get("hardware_error_status") != 0
    for name, v in values.items():
        if name == "torque_enable" and shutdown:
            continue  # refused while in shutdown; the status carries the alert bit
        if name in servo.frozen:
            continue  # injected fault: acknowledged, not stored (a read-back shows it)
        servo.set(name, v)
    if (servo.family == "feetech_sts" and "goal_position" in values
            and "torque_enable" not in values
            and servo.get("operating_mode") == POSITION_MODE["feetech_sts"]):
        servo.set("torque_enable", 1)
