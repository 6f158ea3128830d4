"""More emulated control tables, transcribed from the manuals (registered in
``sim.emulator.control_tables``): the XL-320 and Feetech SCS tables of their own, and the
X / MX tables that differ from the XL430's or the MX-28's by a few rows ("variants").

Rows are ``(address, size, access, initial)`` as printed (initial None where the manual
prints "-"); ``control_tables`` makes them ``Entry`` rows. Independent of the driver's
``robot.bus.tables*`` on purpose (``tests/test_emulator_tables.py`` compares the two).

- XL-320: ROBOTIS e-Manual (ROBOTIS-GIT/emanual docs/en/dxl/x/xl320.md). EEPROM 0-18.
- Feetech SCS (SCSCL): EEPROM 0-39 as the SCS15 manual v1.02 prints it (its table as
  transcribed in chat.stackexchange.com message 55671235 and qiita.com Ninagawa123
  "SCS内部メモリテーブル"); the SRAM as Feetech's SCSCL.h and LeRobot's
  SCS_SERIES_CONTROL_TABLE list it (Lock at 48; 64 the REG WRITE flag, 65 the status).
  Two-byte registers are big-endian.
- Variants, each from its e-Manual page: 2XL430-W250 (the XL430 without Startup
  Configuration(60) and Backup Ready(147)); MX-28(2.0) (that plus Acceleration Limit(40));
  the current-sensing X table of the XM430-W350 / MX-64(2.0) pages (that plus Current
  Limit(38), Goal Current(102), Present Current(126) where the others have Present
  Load); the XL330-M288 page (the XL430 plus Current Limit, PWM Slope(62), Goal and
  Present Current, 20 indirect entries at 168/208); the MX-64 and MX-106 on Protocol 1.0
  (the MX-28's plus Current(68), Torque Control Mode Enable(70), Goal Torque(71); the
  MX-106 also Drive Mode(10)).
"""

from __future__ import annotations

from typing import NamedTuple

Row = tuple[int, int, str, int | None]

DYNAMIXEL_XL320: dict[str, Row] = {
    # EEPROM (0-18)
    "model_number": (0, 2, "R", 350),
    "firmware_version": (2, 1, "R", None),
    "id": (3, 1, "RW", 1),
    "baud_rate": (4, 1, "RW", 3),                  # 3 = 1 Mbps
    "return_delay_time": (5, 1, "RW", 250),
    "cw_angle_limit": (6, 2, "RW", 0),
    "ccw_angle_limit": (8, 2, "RW", 1023),
    "control_mode": (11, 1, "RW", 2),              # 1 wheel, 2 joint
    "temperature_limit": (12, 1, "RW", 65),
    "min_voltage_limit": (13, 1, "RW", 60),
    "max_voltage_limit": (14, 1, "RW", 90),
    "max_torque": (15, 2, "RW", 1023),
    "status_return_level": (17, 1, "RW", 2),
    "shutdown": (18, 1, "RW", 3),
    # RAM (24-52)
    "torque_enable": (24, 1, "RW", 0),
    "led": (25, 1, "RW", 0),
    "d_gain": (27, 1, "RW", 0),
    "i_gain": (28, 1, "RW", 0),
    "p_gain": (29, 1, "RW", 32),
    "goal_position": (30, 2, "RW", None),
    "moving_speed": (32, 2, "RW", None),
    "torque_limit": (35, 2, "RW", None),
    "present_position": (37, 2, "R", None),
    "present_speed": (39, 2, "R", None),
    "present_load": (41, 2, "R", None),
    "present_voltage": (45, 1, "R", None),
    "present_temperature": (46, 1, "R", None),
    "registered": (47, 1, "R", 0),
    "moving": (49, 1, "R", 0),
    "hardware_error_status": (50, 1, "R", 0),
    "punch": (51, 2, "RW", 32),
}

FEETECH_SCS: dict[str, Row] = {
    # EEPROM (0-39): saved only while Lock(48) is 0.
    "firmware_major": (0, 1, "R", None),
    "firmware_minor": (1, 1, "R", None),
    "end": (2, 1, "R", 1),                          # 1: big-endian
    "model_number": (3, 2, "R", None),              # "software version (H/L)" in v1.02
    "id": (5, 1, "RW", 1),                          # factory id 1 (Feetech)
    "baud_rate": (6, 1, "RW", 0),                   # 0 = 1 Mbps
    "return_delay_time": (7, 1, "RW", 0),
    "status_return_level": (8, 1, "RW", 1),
    "min_angle_limit": (9, 2, "RW", 0),
    "max_angle_limit": (11, 2, "RW", 1023),
    "max_temperature_limit": (13, 1, "RW", 80),
    "max_voltage_limit": (14, 1, "RW", 250),
    "min_voltage_limit": (15, 1, "RW", 50),
    "max_torque_limit": (16, 2, "RW", 1023),
    "high_voltage_flag": (18, 1, "RW", 0),
    "unloading_condition": (19, 1, "RW", 37),
    "led_alarm_condition": (20, 1, "RW", 37),
    "p_coefficient": (21, 1, "RW", 15),
    "d_coefficient": (22, 1, "RW", 0),
    "i_coefficient": (23, 1, "RW", 0),
    "minimum_startup_force": (24, 2, "RW", 0),      # "minimum PWM"
    "cw_dead_zone": (26, 1, "RW", 2),
    "ccw_dead_zone": (27, 1, "RW", 2),
    # SRAM (40-)
    "torque_enable": (40, 1, "RW", 0),
    "goal_position": (42, 2, "RW", None),
    "goal_time": (44, 2, "RW", 0),
    "goal_speed": (46, 2, "RW", 0),
    "lock": (48, 1, "RW", 1),
    "present_position": (56, 2, "R", None),
    "present_speed": (58, 2, "R", None),
    "present_load": (60, 2, "R", None),
    "present_voltage": (62, 1, "R", None),
    "present_temperature": (63, 1, "R", None),
    "async_write_flag": (64, 1, "R", 0),            # 1 while a REG WRITE waits
    "status": (65, 1, "R", 0),
    "moving": (66, 1, "R", 0),
    "present_current": (69, 2, "R", None),
}

#: The tables of their own, by layout.
OWN_TABLES: dict[str, dict[str, Row]] = {
    "dynamixel_xl320": DYNAMIXEL_XL320, "feetech_scs": FEETECH_SCS,
}


class Variant(NamedTuple):
    """A table as another (``base``, a layout) without ``drop`` and with ``add``."""

    base: str
    drop: tuple[str, ...]
    add: dict[str, Row]


def _indirect(count: int, first_address: int, first_data: int) -> dict[str, Row]:
    rows: dict[str, Row] = {}
    for k in range(count):
        rows[f"indirect_address_{k + 1}"] = (first_address + 2 * k, 2, "RW", first_data + k)
        rows[f"indirect_data_{k + 1}"] = (first_data + k, 1, "RW", 0)
    return rows


_INDIRECT_ALL = tuple(f"indirect_{kind}_{k}" for kind in ("address", "data")
                      for k in range(1, 57))
_CURRENT: dict[str, Row] = {
    "current_limit": (38, 2, "RW", None),          # per model (XM430-W350 1,193)
    "goal_current": (102, 2, "RW", None),
    "present_current": (126, 2, "R", None),
}
#: Variants in build order (a base before the variants made from it).
VARIANTS: dict[str, Variant] = {
    "dynamixel_2xl": Variant("dynamixel_x", ("startup_configuration", "backup_ready"), {}),
    "dynamixel_mx2": Variant("dynamixel_2xl", (), {"acceleration_limit": (40, 4, "RW", 32767)}),
    "dynamixel_xm": Variant("dynamixel_mx2", ("present_load",), _CURRENT),
    "dynamixel_xl330": Variant("dynamixel_x", ("present_load", *_INDIRECT_ALL), {
        **_CURRENT, "pwm_slope": (62, 1, "RW", 140), **_indirect(20, 168, 208)}),
    "dynamixel_mx64_1": Variant("dynamixel_mx1", (), {
        "current": (68, 2, "RW", 0), "torque_ctrl_mode_enable": (70, 1, "RW", 0),
        "goal_torque": (71, 2, "RW", 0)}),
    "dynamixel_mx106_1": Variant("dynamixel_mx64_1", (), {"drive_mode": (10, 1, "RW", 0)}),
}

EEPROM_END_MORE: dict[str, int] = {
    "dynamixel_xl320": 24, "feetech_scs": 40, "dynamixel_2xl": 64, "dynamixel_mx2": 64,
    "dynamixel_xm": 64, "dynamixel_xl330": 64, "dynamixel_mx64_1": 24, "dynamixel_mx106_1": 24,
}
#: What this emulator reports where the manual prints "-".
UNPRINTED_MORE: dict[str, dict[str, int]] = {
    "dynamixel_xl320": {"firmware_version": 39, "present_voltage": 74,
                        "present_temperature": 35, "torque_limit": 1023, "moving_speed": 0},
    "feetech_scs": {"firmware_major": 1, "firmware_minor": 8, "present_voltage": 74,
                    "present_temperature": 35},
    **{k: {"firmware_version": 46, "present_input_voltage": 120, "present_temperature": 35}
       for k in ("dynamixel_2xl", "dynamixel_mx2", "dynamixel_xm", "dynamixel_xl330")},
    **{k: {"firmware_version": 41, "present_voltage": 120, "present_temperature": 35,
           "torque_limit": 1023, "moving_speed": 0}
       for k in ("dynamixel_mx64_1", "dynamixel_mx106_1")},
}
#: Baud Rate register codes [bit/s]: XL-320 "Baud Rate(4)"; SCSCL "Baud Rate(6)" (the
#: STS codes: 5 = 76800, 6 = 57600, 7 = 38400, Feetech's SCSCL.h).
BAUD_CODES_MORE: dict[str, dict[int, int]] = {
    "dynamixel_xl320": {0: 9600, 1: 57_600, 2: 115_200, 3: 1_000_000},
    "feetech_scs": {0: 1_000_000, 1: 500_000, 2: 250_000, 3: 128_000, 4: 115_200,
                    5: 76_800, 6: 57_600, 7: 38_400},
}
