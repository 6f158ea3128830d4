"""Control tables and servo models as data. No address literal lives anywhere else.

Each table maps a register name to ``Register(address, size)``. Sizes are in bytes.

- Dynamixel X series (Protocol 2.0): ROBOTIS e-Manual, "XL430-W250" control table
  (https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/), shared by the X family.
- Dynamixel Protocol 1.0 (AX-12A, AX-18A, MX-28 on Protocol 1.0 firmware): ROBOTIS e-Manual,
  "AX-12A" control table (https://emanual.robotis.com/docs/en/dxl/ax/ax-12a/); the MX-28
  (https://emanual.robotis.com/docs/en/dxl/mx/mx-28/) keeps these addresses.
- Feetech STS/SMS (little-endian, Protocol-1 style): Feetech "STS/SMS series memory table"
  (FT-SMS-STS-emanual), as used by feetech-servo-sdk's ``SMS_STS`` definitions.
"""

from __future__ import annotations

import math
from typing import NamedTuple


class Register(NamedTuple):
    """One control-table entry.

    address: byte address in the servo's control table
    size: width [bytes]
    """

    address: int
    size: int


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
}

# Baud-rate register codes.
DYNAMIXEL_X_BAUD: dict[int, int] = {
    0: 9600, 1: 57600, 2: 115200, 3: 1000000, 4: 2000000, 5: 3000000, 6: 4000000,
}
FEETECH_STS_BAUD: dict[int, int] = {
    0: 1000000, 1: 500000, 2: 250000, 3: 128000, 4: 115200, 5: 76800, 6: 57600, 7: 38400,
}
# AX-12A "Baud Rate(4)": rate = 2000000 / (code + 1); the manual's table of the usual codes
# (1 Mbps is 1, the factory value; 57600 is 34, 3.5 % off but within tolerance).
DYNAMIXEL_P1_BAUD: dict[int, int] = {
    1: 1000000, 3: 500000, 4: 400000, 7: 250000, 9: 200000, 16: 115200, 34: 57600,
    103: 19200, 207: 9600,
}
BAUD_CODES: dict[str, dict[int, int]] = {
    "dynamixel_x": DYNAMIXEL_X_BAUD,
    "dynamixel_p1": DYNAMIXEL_P1_BAUD,
    "feetech_sts": FEETECH_STS_BAUD,
}

# Unit of one "return delay" register step [s]: Dynamixel X 2 µs, Feetech STS 2 µs.
# AX-12A "Return Delay Time(5)": 2 µs per step (factory 250 = 500 µs).
RETURN_DELAY_UNIT_S: dict[str, float] = {
    "dynamixel_x": 2e-6, "dynamixel_p1": 2e-6, "feetech_sts": 2e-6,
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
}


class ServoModel(NamedTuple):
    """Datasheet facts about one servo model.

    number: model number as reported by ping / the model_number register
    family: key into TABLES
    resolution: number of positions (goal/present ticks run 0..resolution-1)
    stall_torque: stall torque at the nominal voltage [N m]
    no_load_speed: no-load speed at the nominal voltage [rad/s]
    mass: [kg]
    nominal_voltage: [V]
    """

    name: str
    number: int
    family: str
    resolution: int
    stall_torque: float
    no_load_speed: float
    mass: float
    nominal_voltage: float
    #: angle the ``resolution`` positions span [deg]: 360 for a full turn, 300 for the AX
    #: series (1024 ticks over 300 deg, i.e. an effective 1228.8 ticks per turn)
    span_deg: float = 360.0

    @property
    def ticks_per_rad(self) -> float:
        """Ticks per radian of output shaft."""
        return self.resolution / math.radians(self.span_deg)


_RPM = 2.0 * math.pi / 60.0

MODELS: dict[str, ServoModel] = {
    # ROBOTIS XL430-W250-T: 1.4 N m, 57 rpm at 11.1 V; 57.2 g.
    "XL430-W250": ServoModel("XL430-W250", 1060, "dynamixel_x", 4096, 1.4, 57 * _RPM, 0.0572, 11.1),
    # ROBOTIS XM430-W350: 4.1 N m, 46 rpm at 12 V; 82 g.
    "XM430-W350": ServoModel("XM430-W350", 1020, "dynamixel_x", 4096, 4.1, 46 * _RPM, 0.082, 12.0),
    # ROBOTIS XC430-W150: 1.6 N m (12 V stall), 70 rpm; 65 g.
    "XC430-W150": ServoModel("XC430-W150", 1070, "dynamixel_x", 4096, 1.6, 70 * _RPM, 0.065, 12.0),
    # ROBOTIS e-Manual AX-12A: 1.5 N m (12 V, 1.5 A), 59 rpm (12 V), 54.6 g; 0..300 deg in
    # 1024 steps (0.29 deg); model number 12.
    "AX-12A": ServoModel("AX-12A", 12, "dynamixel_p1", 1024, 1.5, 59 * _RPM, 0.0546, 12.0, 300.0),
    # ROBOTIS e-Manual AX-18A: 1.8 N m (12 V, 2.2 A), 97 rpm (12 V), 54.5 g; model 18.
    "AX-18A": ServoModel("AX-18A", 18, "dynamixel_p1", 1024, 1.8, 97 * _RPM, 0.0545, 12.0, 300.0),
    # ROBOTIS e-Manual MX-28 (Protocol 1.0 firmware): 2.5 N m, 55 rpm at 12 V, 72 g;
    # 4096 steps per turn; model number 29.
    "MX-28": ServoModel("MX-28", 29, "dynamixel_p1", 4096, 2.5, 55 * _RPM, 0.072, 12.0),
    # Feetech STS3215 (7.4 V): 19.5 kg cm = 1.91 N m, 0.222 s/60 deg; 55 g.
    "STS3215": ServoModel("STS3215", 777, "feetech_sts", 4096, 1.91, (math.pi / 3) / 0.222, 0.055, 7.4),
    # Feetech STS3032: 4.5 kg cm = 0.44 N m, 0.1 s/60 deg at 6 V; 17 g.
    "STS3032": ServoModel("STS3032", 1288, "feetech_sts", 4096, 0.44, (math.pi / 3) / 0.1, 0.017, 6.0),
}

MODELS_BY_NUMBER: dict[str, dict[int, ServoModel]] = {}
for _m in MODELS.values():
    MODELS_BY_NUMBER.setdefault(_m.family, {})[_m.number] = _m

BUS_FAMILIES: dict[str, str] = {
    "dynamixel": "dynamixel_x", "dynamixel1": "dynamixel_p1", "feetech": "feetech_sts",
}


def model_name(family: str, number: int) -> str:
    """Human name of a model number within a family, or ``"unknown(<number>)"``."""
    model = MODELS_BY_NUMBER.get(family, {}).get(number)
    return model.name if model else f"unknown({number})"
