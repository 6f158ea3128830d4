"""Control tables as data. No address literal lives anywhere else (servo models and baud
codes: robot/servo/models.py).

Each table maps a register name to ``Register(address, size)``. Sizes are in bytes.

- Dynamixel X series (Protocol 2.0): ROBOTIS e-Manual, "XL430-W250" control table
  (https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/), shared by the X family.
- Dynamixel Protocol 1.0 (AX-12A, AX-18A, MX-28 on Protocol 1.0 firmware): ROBOTIS e-Manual,
  "AX-12A" control table (https://emanual.robotis.com/docs/en/dxl/ax/ax-12a/); the MX-28
  (https://emanual.robotis.com/docs/en/dxl/mx/mx-28/) keeps these addresses.
- Feetech STS/SMS (little-endian, Protocol-1 style): Feetech "STS/SMS series memory table"
  (FT-SMS-STS-emanual), as used by feetech-servo-sdk's ``SMS_STS`` definitions.
- ROBOTIS XL-320 and Feetech SCS: robot/bus/tables_more.py (registered here).

The Dynamixel Protocol 1.0 table also serves the MX-64 and MX-106 on 1.0 firmware: their
e-Manual tables keep the MX-28's addresses for every register named here (and add Current
68, Torque Control Mode 70, Goal Torque 71; the MX-106 Drive Mode 10). The X table serves
every X model and the MX series on 2.0 firmware; on the current-sensing models (XM, XH,
XL330, XC330, MX-64/106(2.0)) register 126 is Present Current, not Present Load.
"""

from __future__ import annotations

from typing import Literal, NamedTuple

from robot.bus.register import Register
from robot.bus.tables_more import (
    DYNAMIXEL_XL320,
    DYNAMIXEL_XL320_ERROR_BITS,
    FEETECH_SCS,
    FEETECH_SCS_ERROR_BITS,
    GAIN_REGISTERS_MORE,
)

__all__ = ["Register", "TABLES"]

# ROBOTIS e-Manual, X series control table (XL430-W250, XM430, XC430, ...).
DYNAMIXEL_X: dict[str, Register] = {
    "model_number": Register(0, 2),
    "firmware_version": Register(6, 1),
    "id": Register(7, 1),
    "baud_rate": Register(8, 1),
    "return_delay_time": Register(9, 1),
    "drive_mode": Register(10, 1),
    "operating_mode": Register(11, 1),
    "homing_offset": Register(20, 4),
    "temperature_limit": Register(31, 1),
    "max_voltage_limit": Register(32, 2),
    "min_voltage_limit": Register(34, 2),
    "velocity_limit": Register(44, 4),
    "max_position_limit": Register(48, 4),
    "min_position_limit": Register(52, 4),
    "torque_enable": Register(64, 1),
    "led": Register(65, 1),
    "status_return_level": Register(68, 1),
    "hardware_error_status": Register(70, 1),
    "position_d_gain": Register(80, 2),
    "position_i_gain": Register(82, 2),
    "position_p_gain": Register(84, 2),
    "bus_watchdog": Register(98, 1),
    "profile_acceleration": Register(108, 4),
    "profile_velocity": Register(112, 4),
    "goal_position": Register(116, 4),
    "moving": Register(122, 1),
    "present_load": Register(126, 2),
    "present_velocity": Register(128, 4),
    "present_position": Register(132, 4),
    "present_input_voltage": Register(144, 2),
    "present_temperature": Register(146, 1),
}

# ROBOTIS e-Manual, AX-12A control table (Protocol 1.0; AX-18A and MX-28 share these
# addresses). EEPROM 0-23, RAM 24-49. 10-bit positions (AX): 0..1023 over 0..300 deg.
DYNAMIXEL_P1: dict[str, Register] = {
    "model_number": Register(0, 2),
    "firmware_version": Register(2, 1),
    "id": Register(3, 1),
    "baud_rate": Register(4, 1),
    "return_delay_time": Register(5, 1),
    "cw_angle_limit": Register(6, 2),
    "ccw_angle_limit": Register(8, 2),
    "temperature_limit": Register(11, 1),
    "min_voltage_limit": Register(12, 1),
    "max_voltage_limit": Register(13, 1),
    "max_torque": Register(14, 2),
    "status_return_level": Register(16, 1),
    "alarm_led": Register(17, 1),
    "shutdown": Register(18, 1),
    "torque_enable": Register(24, 1),
    "led": Register(25, 1),
    "cw_compliance_margin": Register(26, 1),     # AX only (MX: DYNAMIXEL_MX1_GAINS)
    "ccw_compliance_margin": Register(27, 1),
    "cw_compliance_slope": Register(28, 1),
    "ccw_compliance_slope": Register(29, 1),
    "goal_position": Register(30, 2),
    "moving_speed": Register(32, 2),
    "torque_limit": Register(34, 2),
    "present_position": Register(36, 2),
    "present_speed": Register(38, 2),
    "present_load": Register(40, 2),
    "present_voltage": Register(42, 1),
    "present_temperature": Register(43, 1),
    "registered": Register(44, 1),
    "moving": Register(46, 1),
    "lock": Register(47, 1),
    "punch": Register(48, 2),
}

# Feetech STS/SMS memory table (STS3215 and siblings), little-endian.
FEETECH_STS: dict[str, Register] = {
    "firmware_major": Register(0, 1),
    "firmware_minor": Register(1, 1),
    "model_number": Register(3, 2),
    "id": Register(5, 1),
    "baud_rate": Register(6, 1),
    "return_delay_time": Register(7, 1),
    "status_return_level": Register(8, 1),
    "min_angle_limit": Register(9, 2),
    "max_angle_limit": Register(11, 2),
    "max_temperature_limit": Register(13, 1),
    "max_voltage_limit": Register(14, 1),
    "min_voltage_limit": Register(15, 1),
    "max_torque_limit": Register(16, 2),
    "p_coefficient": Register(21, 1),
    "d_coefficient": Register(22, 1),
    "i_coefficient": Register(23, 1),
    "homing_offset": Register(31, 2),
    "operating_mode": Register(33, 1),
    "torque_enable": Register(40, 1),
    "acceleration": Register(41, 1),
    "goal_position": Register(42, 2),
    "goal_time": Register(44, 2),
    "goal_speed": Register(46, 2),
    "torque_limit": Register(48, 2),
    "lock": Register(55, 1),
    "present_position": Register(56, 2),
    "present_speed": Register(58, 2),
    "present_load": Register(60, 2),
    "present_voltage": Register(62, 1),
    "present_temperature": Register(63, 1),
    "status": Register(65, 1),
    "moving": Register(66, 1),
    "present_current": Register(69, 2),
}

TABLES: dict[str, dict[str, Register]] = {
    "dynamixel_x": DYNAMIXEL_X, "dynamixel_p1": DYNAMIXEL_P1, "feetech_sts": FEETECH_STS,
    "dynamixel_xl320": DYNAMIXEL_XL320, "feetech_scs": FEETECH_SCS,
}
#: Byte order of the two-byte and four-byte registers: little-endian everywhere but the
#: Feetech SCS (SCSCL memory table: END(2) = 1, high byte first).
BYTE_ORDER: dict[str, Literal["little", "big"]] = {
    "dynamixel_x": "little", "dynamixel_p1": "little", "feetech_sts": "little",
    "dynamixel_xl320": "little", "feetech_scs": "big",
}
#: First and last register of the block a state read fetches (position, load, voltage,
#: temperature and, where the table has one in reach, the error register).
STATE_BLOCK: dict[str, tuple[str, str]] = {
    "dynamixel_x": ("present_load", "present_temperature"),
    "dynamixel_xl320": ("present_position", "hardware_error_status"),
    "dynamixel_p1": ("present_position", "present_temperature"),
    "feetech_sts": ("present_position", "status"),
    "feetech_scs": ("present_position", "status"),
}

# ROBOTIS e-Manual, MX-28 (Protocol 1.0 firmware) RAM table: D Gain(26), I Gain(27),
# P Gain(28), where the AX-12A keeps its compliance margins and slopes.
DYNAMIXEL_MX1_GAINS: dict[str, Register] = {
    "d_gain": Register(26, 1), "i_gain": Register(27, 1), "p_gain": Register(28, 1),
}


def _pick(table: dict[str, Register], *names: str) -> dict[str, Register]:
    return {n: table[n] for n in names}


#: The gain registers of each gain set (robot/servo/gains.py: names, ranges, memory).
GAIN_REGISTERS: dict[str, dict[str, Register]] = {
    "dynamixel_x": _pick(DYNAMIXEL_X, "position_d_gain", "position_i_gain", "position_p_gain",
                         "profile_acceleration", "profile_velocity"),
    "dynamixel_ax": _pick(DYNAMIXEL_P1, "cw_compliance_margin", "ccw_compliance_margin",
                          "cw_compliance_slope", "ccw_compliance_slope"),
    "dynamixel_mx1": DYNAMIXEL_MX1_GAINS,
    "feetech_sts": _pick(FEETECH_STS, "p_coefficient", "d_coefficient", "i_coefficient"),
    **GAIN_REGISTERS_MORE,
}
#: The EEPROM write lock of a family, as (register, unlocked value, locked value): Feetech
#: STS Lock(55): 0 = EEPROM writes are saved, 1 = locked (the memory table; the factory
#: value is 1). Dynamixel needs torque off for EEPROM instead (and the AX Lock(47) locks
#: for good until power-off: never written here).
EEPROM_LOCK: dict[str, tuple[str, int, int] | None] = {
    "dynamixel_x": None, "dynamixel_p1": None, "feetech_sts": ("lock", 0, 1),
    "dynamixel_xl320": None, "feetech_scs": ("lock", 0, 1),   # SCS Lock(48), same values
}

# Hardware-error bits → normalised fault names.
# Dynamixel X "Hardware Error Status" (70): bit 0 input voltage, 2 overheating,
# 3 motor encoder, 4 electrical shock, 5 overload.
DYNAMIXEL_X_ERROR_BITS: dict[int, str] = {
    0: "voltage",
    2: "overheating",
    3: "encoder",
    4: "electrical_shock",
    5: "overload",
}
# Feetech STS "status" (65): bit 0 voltage, 1 angle sensor, 2 overheating, 3 overcurrent,
# 5 overload.
FEETECH_STS_ERROR_BITS: dict[int, str] = {
    0: "voltage",
    1: "encoder",
    2: "overheating",
    3: "overcurrent",
    5: "overload",
}
# Dynamixel Protocol 1.0 status packet error byte (e-Manual, "Protocol 1.0", Status
# Packet): bit 0 input voltage, 1 angle limit, 2 overheating, 3 range, 4 checksum,
# 5 overload, 6 instruction. Bits 1, 3, 4 and 6 mean the instruction was refused.
DYNAMIXEL_P1_ERROR_BITS: dict[int, str] = {
    0: "voltage",
    1: "angle_limit",
    2: "overheating",
    3: "range",
    4: "checksum",
    5: "overload",
    6: "instruction",
}
ERROR_BITS: dict[str, dict[int, str]] = {
    "dynamixel_x": DYNAMIXEL_X_ERROR_BITS,
    "dynamixel_p1": DYNAMIXEL_P1_ERROR_BITS,
    "feetech_sts": FEETECH_STS_ERROR_BITS,
    "dynamixel_xl320": DYNAMIXEL_XL320_ERROR_BITS,
    "feetech_scs": FEETECH_SCS_ERROR_BITS,
    "lx": {0: "overheating", 1: "voltage", 2: "overload"},   # lx.tables.LX_ALARM_BITS
}

# Unit of one "return delay" register step [s]: Dynamixel X 2 µs, Feetech STS 2 µs.
# AX-12A "Return Delay Time(5)": 2 µs per step (factory 250 = 500 µs).
RETURN_DELAY_UNIT_S: dict[str, float] = {
    "dynamixel_x": 2e-6, "dynamixel_p1": 2e-6, "feetech_sts": 2e-6,
    "dynamixel_xl320": 2e-6,   # e-Manual XL-320 Return Delay Time(5): the X include, 2 us
    "feetech_scs": 2e-6,       # SCS15 manual: 2 us per step, as the STS
}


class CommWatchdog(NamedTuple):
    """A servo's own communication watchdog (fail-safe when the host goes silent).

    register: name in the family's table; unit_s: one register step [s]; steps: the
    arming range [steps, inclusive]; off: the value that disarms it and clears a trip;
    tripped: the (signed) value the register reads after a trip; min_firmware: first
    firmware version that has it.
    """

    register: str
    unit_s: float
    steps: tuple[int, int]
    off: int
    tripped: int
    min_firmware: int

    @property
    def range_s(self) -> tuple[float, float]:
        """Shortest and longest timeout it can arm [s]."""
        return self.steps[0] * self.unit_s, self.steps[1] * self.unit_s


# ROBOTIS e-Manual, X series control table, "Bus Watchdog(98)" (RAM, 1 byte, RW, initial 0;
# https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/#bus-watchdog): 0 disables it and
# clears a trip, 1..127 arms it in units of 20 ms, -1 is "Bus Watchdog Error". It watches
# the gap between instruction packets while Torque Enable(64) is 1; when the gap exceeds
# the setting the servo stops, the register becomes -1 and the Goal values (PWM 100,
# Current 102, Velocity 104, Position 116) turn read-only: writing one is answered with a
# Data Range Error (Protocol 2.0 status error 4) until 0 is written. Torque stays on: the
# manual never says it is dropped (a trip is no Hardware Error Status bit, so no
# shutdown), and its example (steps 7-8) clears the error with 0 and the servo moves on
# the next goal without a new Torque Enable. Available from firmware v38.
# Feetech STS/SMS: the memory table (FT-SMS-STS-emanual; LeRobot's
# STS_SMS_SERIES_CONTROL_TABLE; feetech-servo-sdk has no table) has no communication
# watchdog: with the host gone an STS servo keeps its last goal and holds it with torque.
COMM_WATCHDOG: dict[str, CommWatchdog | None] = {
    "dynamixel_x": CommWatchdog("bus_watchdog", 0.020, (1, 127), 0, -1, 38),
    # AX-12A / MX-28 Protocol 1.0 tables have no bus watchdog either.
    "dynamixel_p1": None,
    "feetech_sts": None,
    # The XL-320 and SCS tables have no communication watchdog register either.
    "dynamixel_xl320": None,
    "feetech_scs": None,
}
