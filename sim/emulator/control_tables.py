"""The emulated servos' control tables, transcribed from the vendors' manuals.

Independent of ``robot.bus.tables`` on purpose (the driver's tables are checked against
these in ``tests/test_emulator_tables.py``). Each entry: name -> ``Entry(address, size,
access, initial)``; ``access`` is "R" or "RW" as printed; ``initial`` is the manual's
initial (factory) value, None where it prints "-" (the emulator then fills in a model value
or 0). EEPROM is every address below ``EEPROM_END`` (saved over power-off), RAM the rest.

- Dynamixel X: ROBOTIS e-Manual, XL430-W250 control table
  (https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/#control-table). The XL430 has no
  current sensing (no Current Limit / Goal Current / Present Current; Present Load(126)).
- Dynamixel Protocol 1.0: ROBOTIS e-Manual, AX-12A control table
  (https://emanual.robotis.com/docs/en/dxl/ax/ax-12a/#control-table); Baud Rate(4) is
  2000000 / (value + 1) bps.
- MX-28 on Protocol 1.0 firmware: ROBOTIS e-Manual, MX-28 control table
  (https://emanual.robotis.com/docs/en/dxl/mx/mx-28/#control-table): the AX layout with
  D/I/P Gain at 26/27/28 where the AX has compliance margins and slopes.
- Feetech STS: Feetech "STS series memory table" (FT-SMS-STS-emanual, STS3215 column);
  Torque switch(40) takes 0, 1 and 128 ("arbitrary current position correction to 2048").
"""

from __future__ import annotations

from typing import NamedTuple

from sim.emulator.control_tables_more import (
    BAUD_CODES_MORE,
    EEPROM_END_MORE,
    OWN_TABLES,
    UNPRINTED_MORE,
    VARIANTS,
)


class Entry(NamedTuple):
    """One control-table row: address, size [bytes], "R"/"RW", initial value (or None)."""

    address: int
    size: int
    access: str
    initial: int | None


INDIRECT_COUNT = 56           # XL430: Indirect Address/Data 1..28 and 29..56
INDIRECT_BLOCKS = ((168, 224, 28), (578, 634, 28))   # (first address, first data, count)
INDIRECT_TARGET_RANGE = (64, 661)   # Indirect Address range printed in the manual


def _indirect() -> dict[str, Entry]:
    rows: dict[str, Entry] = {}
    n = 0
    for addr0, data0, count in INDIRECT_BLOCKS:
        for k in range(count):
            n += 1
            # Initial value: each Indirect Address points at its own Indirect Data byte.
            rows[f"indirect_address_{n}"] = Entry(addr0 + 2 * k, 2, "RW", data0 + k)
            rows[f"indirect_data_{n}"] = Entry(data0 + k, 1, "RW", 0)
    return rows


DYNAMIXEL_X: dict[str, Entry] = {
    # EEPROM (0-63): writable only while Torque Enable(64) is 0.
    "model_number": Entry(0, 2, "R", None),          # 1060 on the XL430-W250
    "model_information": Entry(2, 4, "R", None),
    "firmware_version": Entry(6, 1, "R", None),
    "id": Entry(7, 1, "RW", 1),
    "baud_rate": Entry(8, 1, "RW", 1),               # 1 = 57600 bps
    "return_delay_time": Entry(9, 1, "RW", 250),     # 2 us per step: 500 us
    "drive_mode": Entry(10, 1, "RW", 0),
    "operating_mode": Entry(11, 1, "RW", 3),         # 3 = position control
    "secondary_id": Entry(12, 1, "RW", 255),
    "protocol_type": Entry(13, 1, "RW", 2),
    "homing_offset": Entry(20, 4, "RW", 0),
    "moving_threshold": Entry(24, 4, "RW", 10),
    "temperature_limit": Entry(31, 1, "RW", 72),
    "max_voltage_limit": Entry(32, 2, "RW", 140),
    "min_voltage_limit": Entry(34, 2, "RW", 60),
    "pwm_limit": Entry(36, 2, "RW", 885),
    "velocity_limit": Entry(44, 4, "RW", 265),
    "max_position_limit": Entry(48, 4, "RW", 4095),
    "min_position_limit": Entry(52, 4, "RW", 0),
    "startup_configuration": Entry(60, 1, "RW", 0),
    "shutdown": Entry(63, 1, "RW", 52),
    # RAM (64-)
    "torque_enable": Entry(64, 1, "RW", 0),
    "led": Entry(65, 1, "RW", 0),
    "status_return_level": Entry(68, 1, "RW", 2),
    "registered_instruction": Entry(69, 1, "R", 0),
    "hardware_error_status": Entry(70, 1, "R", 0),
    "velocity_i_gain": Entry(76, 2, "RW", 1000),
    "velocity_p_gain": Entry(78, 2, "RW", 100),
    "position_d_gain": Entry(80, 2, "RW", 4000),
    "position_i_gain": Entry(82, 2, "RW", 0),
    "position_p_gain": Entry(84, 2, "RW", 640),
    "feedforward_2nd_gain": Entry(88, 2, "RW", 0),
    "feedforward_1st_gain": Entry(90, 2, "RW", 0),
    "bus_watchdog": Entry(98, 1, "RW", 0),
    "goal_pwm": Entry(100, 2, "RW", None),
    "goal_velocity": Entry(104, 4, "RW", None),
    "profile_acceleration": Entry(108, 4, "RW", 0),
    "profile_velocity": Entry(112, 4, "RW", 0),
    "goal_position": Entry(116, 4, "RW", None),
    "realtime_tick": Entry(120, 2, "R", None),
    "moving": Entry(122, 1, "R", 0),
    "moving_status": Entry(123, 1, "R", 0),
    "present_pwm": Entry(124, 2, "R", None),
    "present_load": Entry(126, 2, "R", None),
    "present_velocity": Entry(128, 4, "R", None),
    "present_position": Entry(132, 4, "R", None),
    "velocity_trajectory": Entry(136, 4, "R", None),
    "position_trajectory": Entry(140, 4, "R", None),
    "present_input_voltage": Entry(144, 2, "R", None),
    "present_temperature": Entry(146, 1, "R", None),
    "backup_ready": Entry(147, 1, "R", None),
    **_indirect(),
}

DYNAMIXEL_AX: dict[str, Entry] = {
    # EEPROM (0-23)
    "model_number": Entry(0, 2, "R", None),          # 12 on the AX-12A
    "firmware_version": Entry(2, 1, "R", None),
    "id": Entry(3, 1, "RW", 1),
    "baud_rate": Entry(4, 1, "RW", 1),               # 1 = 1 Mbps
    "return_delay_time": Entry(5, 1, "RW", 250),     # 2 us per step: 500 us
    "cw_angle_limit": Entry(6, 2, "RW", 0),
    "ccw_angle_limit": Entry(8, 2, "RW", 1023),
    "temperature_limit": Entry(11, 1, "RW", 70),
    "min_voltage_limit": Entry(12, 1, "RW", 60),
    "max_voltage_limit": Entry(13, 1, "RW", 140),
    "max_torque": Entry(14, 2, "RW", 1023),
    "status_return_level": Entry(16, 1, "RW", 2),
    "alarm_led": Entry(17, 1, "RW", 36),
    "shutdown": Entry(18, 1, "RW", 36),
    # RAM (24-49)
    "torque_enable": Entry(24, 1, "RW", 0),
    "led": Entry(25, 1, "RW", 0),
    "cw_compliance_margin": Entry(26, 1, "RW", 1),
    "ccw_compliance_margin": Entry(27, 1, "RW", 1),
    "cw_compliance_slope": Entry(28, 1, "RW", 32),
    "ccw_compliance_slope": Entry(29, 1, "RW", 32),
    "goal_position": Entry(30, 2, "RW", None),
    "moving_speed": Entry(32, 2, "RW", None),
    "torque_limit": Entry(34, 2, "RW", None),        # loaded from Max Torque(14)
    "present_position": Entry(36, 2, "R", None),
    "present_speed": Entry(38, 2, "R", None),
    "present_load": Entry(40, 2, "R", None),
    "present_voltage": Entry(42, 1, "R", None),      # 0.1 V
    "present_temperature": Entry(43, 1, "R", None),
    "registered": Entry(44, 1, "R", 0),
    "moving": Entry(46, 1, "R", 0),
    "lock": Entry(47, 1, "RW", 0),
    "punch": Entry(48, 2, "RW", 32),
}

_AX_GAINS = ("cw_compliance_margin", "ccw_compliance_margin", "cw_compliance_slope",
             "ccw_compliance_slope")
DYNAMIXEL_MX1: dict[str, Entry] = {
    **{n: e for n, e in DYNAMIXEL_AX.items() if n not in _AX_GAINS},
    # e-Manual MX-28 where it differs from the AX-12A: EEPROM
    "baud_rate": Entry(4, 1, "RW", 34),              # 34 = 57600 bps
    "ccw_angle_limit": Entry(8, 2, "RW", 4095),
    "temperature_limit": Entry(11, 1, "RW", 80),
    "max_voltage_limit": Entry(13, 1, "RW", 160),
    "multi_turn_offset": Entry(20, 2, "RW", 0),
    "resolution_divider": Entry(22, 1, "RW", 1),
    # RAM: PID Gains (26, 27, 28): 0 ~ 254; Kd = D * 4 / 1000, Ki = I * 1000 / 2048, Kp = P / 8
    "d_gain": Entry(26, 1, "RW", 0),
    "i_gain": Entry(27, 1, "RW", 0),
    "p_gain": Entry(28, 1, "RW", 32),
    "punch": Entry(48, 2, "RW", 0),
    "realtime_tick": Entry(50, 2, "R", 0),
    "goal_acceleration": Entry(73, 1, "RW", 0),
}

FEETECH_STS: dict[str, Entry] = {
    # EEPROM (0-39): saved only while Lock(55) is 0.
    "firmware_major": Entry(0, 1, "R", None),
    "firmware_minor": Entry(1, 1, "R", None),
    "model_number": Entry(3, 2, "R", None),         # servo major/minor version: 777 = STS3215
    "id": Entry(5, 1, "RW", 1),
    "baud_rate": Entry(6, 1, "RW", 0),              # 0 = 1 Mbps
    "return_delay_time": Entry(7, 1, "RW", 0),
    "status_return_level": Entry(8, 1, "RW", 1),
    "min_angle_limit": Entry(9, 2, "RW", 0),
    "max_angle_limit": Entry(11, 2, "RW", 4095),
    "max_temperature_limit": Entry(13, 1, "RW", 70),
    "max_voltage_limit": Entry(14, 1, "RW", None),
    "min_voltage_limit": Entry(15, 1, "RW", 40),
    "max_torque_limit": Entry(16, 2, "RW", 1000),
    "phase": Entry(18, 1, "RW", None),
    "unloading_condition": Entry(19, 1, "RW", None),
    "led_alarm_condition": Entry(20, 1, "RW", None),
    "p_coefficient": Entry(21, 1, "RW", None),
    "d_coefficient": Entry(22, 1, "RW", None),
    "i_coefficient": Entry(23, 1, "RW", 0),
    "minimum_startup_force": Entry(24, 1, "RW", None),
    "integral_limit": Entry(25, 1, "RW", 0),
    "cw_dead_zone": Entry(26, 1, "RW", 1),
    "ccw_dead_zone": Entry(27, 1, "RW", 1),
    "protection_current": Entry(28, 2, "RW", 511),
    "angular_resolution": Entry(30, 1, "RW", 1),
    "homing_offset": Entry(31, 2, "RW", 0),
    "operating_mode": Entry(33, 1, "RW", 0),
    "protective_torque": Entry(34, 1, "RW", 20),
    "protection_time": Entry(35, 1, "RW", 200),
    "overload_torque": Entry(36, 1, "RW", 80),
    "speed_p_coefficient": Entry(37, 1, "RW", None),
    "over_current_protection_time": Entry(38, 1, "RW", 200),
    "velocity_i_coefficient": Entry(39, 1, "RW", None),
    # SRAM (40-)
    "torque_enable": Entry(40, 1, "RW", 0),
    "acceleration": Entry(41, 1, "RW", 0),
    "goal_position": Entry(42, 2, "RW", None),     # table: 0; the servo starts at present
    "goal_time": Entry(44, 2, "RW", 0),
    "goal_speed": Entry(46, 2, "RW", 0),
    "torque_limit": Entry(48, 2, "RW", 1000),        # loaded from Max Torque(16)
    "lock": Entry(55, 1, "RW", 1),
    "present_position": Entry(56, 2, "R", None),
    "present_speed": Entry(58, 2, "R", None),
    "present_load": Entry(60, 2, "R", None),
    "present_voltage": Entry(62, 1, "R", None),
    "present_temperature": Entry(63, 1, "R", None),
    "async_write_flag": Entry(64, 1, "R", 0),        # 1 while a Reg Write waits for Action
    "status": Entry(65, 1, "R", 0),
    "moving": Entry(66, 1, "R", 0),
    "present_current": Entry(69, 2, "R", None),
    # Factory parameters (memory table section 2.5; addresses and names as LeRobot's
    # STS_SMS_SERIES_CONTROL_TABLE lists them): no initial values printed in a
    # transcription we could read, so the emulator serves 0 until written. RAM here.
    "moving_velocity_threshold": Entry(80, 1, "RW", None),
    "dts": Entry(81, 1, "RW", None),                  # [ms]
    "velocity_unit_factor": Entry(82, 1, "RW", None),
    "hts": Entry(83, 1, "RW", None),                  # [ns], firmware >= 2.54
    "maximum_velocity_limit": Entry(84, 1, "RW", None),
    "maximum_acceleration": Entry(85, 1, "RW", None),
    "acceleration_multiplier": Entry(86, 1, "RW", None),   # in effect when Acceleration is 0
}

#: Control tables by layout: a family's own (its key), or a model's where it differs
#: ("dynamixel_mx1": servo_models.ServoModel.table).
TABLES: dict[str, dict[str, Entry]] = {
    "dynamixel_x": DYNAMIXEL_X, "dynamixel_p1": DYNAMIXEL_AX, "feetech_sts": FEETECH_STS,
    "dynamixel_mx1": DYNAMIXEL_MX1,
}
TABLES.update({layout: {n: Entry(*row) for n, row in rows.items()}
               for layout, rows in OWN_TABLES.items()})
for _layout, _v in VARIANTS.items():       # XL-320, SCS, the X / MX variants (more tables)
    TABLES[_layout] = {**{n: e for n, e in TABLES[_v.base].items() if n not in _v.drop},
                       **{n: Entry(*row) for n, row in _v.add.items()}}
EEPROM_END: dict[str, int] = {"dynamixel_x": 64, "dynamixel_p1": 24, "feetech_sts": 40,
                              "dynamixel_mx1": 24, **EEPROM_END_MORE}

#: Values where the manual prints "-" (firmware, sensors, tuning the factory sets per
#: unit): what this emulator reports. The manual's initial values are in the tables.
UNPRINTED: dict[str, dict[str, int]] = {
    "dynamixel_x": {"firmware_version": 46, "present_input_voltage": 115,
                    "present_temperature": 35},
    "dynamixel_p1": {"firmware_version": 24, "present_voltage": 120,
                     "present_temperature": 35, "torque_limit": 1023, "moving_speed": 0},
    "dynamixel_mx1": {"firmware_version": 36, "present_voltage": 120,
                      "present_temperature": 35, "torque_limit": 1023, "moving_speed": 0},
    "feetech_sts": {"firmware_major": 3, "firmware_minor": 10, "max_voltage_limit": 140,
                    "p_coefficient": 32, "d_coefficient": 32, "present_voltage": 74,
                    "present_temperature": 35},
    **UNPRINTED_MORE,
}

#: Registers the X manual gives in two's complement.
DXL_SIGNED: frozenset[str] = frozenset({
    "homing_offset", "bus_watchdog", "goal_pwm", "goal_velocity", "goal_position",
    "present_pwm", "present_load", "present_velocity", "present_position",
    "velocity_trajectory", "position_trajectory",
})
#: Feetech STS sign-magnitude registers: (name, sign bit) (bit 15 direction; load bit 10).
STS_SIGN_BIT: dict[str, int] = {
    "homing_offset": 11, "goal_position": 15, "goal_speed": 15, "present_position": 15,
    "present_speed": 15, "present_load": 10,
}

#: Baud Rate register codes [bit/s]: X manual "Baud Rate(8)"; STS memory table "Baud Rate(6)".
BAUD_CODES: dict[str, dict[int, int]] = {
    "dynamixel_x": {0: 9600, 1: 57600, 2: 115200, 3: 1_000_000, 4: 2_000_000,
                    5: 3_000_000, 6: 4_000_000, 7: 4_500_000},
    "feetech_sts": {0: 1_000_000, 1: 500_000, 2: 250_000, 3: 128_000, 4: 115_200,
                    5: 76_800, 6: 57_600, 7: 38_400},
    # AX-12A "Baud Rate(4)": 2000000 / (value + 1); the manual's table of usual values.
    "dynamixel_p1": {1: 1_000_000, 3: 500_000, 4: 400_000, 7: 250_000, 9: 200_000,
                     16: 115_200, 34: 57_600, 103: 19_200, 207: 9_600},
    **BAUD_CODES_MORE,
}

#: Profile Velocity(112) / Present Velocity(128) unit on X: 0.229 rev/min.
DXL_VELOCITY_UNIT_RPM = 0.229
#: STS3215 Goal Speed(46) / Present Speed(58) unit: 1 step/s (4096 steps/rev).
STS_SPEED_UNIT_TICKS_S = 1.0


def read_only(layout: str) -> frozenset[str]:
    """Names the manual marks "R" (``layout``: a key of TABLES)."""
    return frozenset(n for n, e in TABLES[layout].items() if e.access == "R")
