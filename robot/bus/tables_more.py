"""The control tables of two families that speak a protocol of another's (their registry
is ``robot.bus.tables``): the ROBOTIS XL-320 (Protocol 2.0, a table of its own) and the
Feetech SCS series (the STS protocol, a big-endian table of its own). Names match the X
and STS tables where the register means the same thing.

- ROBOTIS e-Manual, XL-320 (https://emanual.robotis.com/docs/en/dxl/x/xl320/, source:
  ROBOTIS-GIT/emanual docs/en/dxl/x/xl320.md): EEPROM 0-18, RAM 24-52; 0..1023 over
  0..300 deg; the Shutdown(18) and Hardware Error Status(50) bits.
- Feetech SCSCL memory table (the SCS0009 / SCS15 / SCS40 potentiometer servos): addresses
  0-27 and the SRAM as Feetech's SCSCL.h (SCServo library) and the SCS15 manual v1.02
  list them (Lock at 48 where the STS has it at 55; no offset, mode or acceleration);
  ``END`` (2) reads 1: two-byte registers are big-endian (high byte first).
"""

from __future__ import annotations

from robot.bus.register import Register

DYNAMIXEL_XL320: dict[str, Register] = {
    "model_number": Register(0, 2),
    "firmware_version": Register(2, 1),
    "id": Register(3, 1),
    "baud_rate": Register(4, 1),
    "return_delay_time": Register(5, 1),
    "cw_angle_limit": Register(6, 2),
    "ccw_angle_limit": Register(8, 2),
    "control_mode": Register(11, 1),          # 1 wheel, 2 joint
    "temperature_limit": Register(12, 1),
    "min_voltage_limit": Register(13, 1),
    "max_voltage_limit": Register(14, 1),
    "max_torque": Register(15, 2),
    "status_return_level": Register(17, 1),
    "shutdown": Register(18, 1),
    "torque_enable": Register(24, 1),
    "led": Register(25, 1),
    "d_gain": Register(27, 1),
    "i_gain": Register(28, 1),
    "p_gain": Register(29, 1),
    "goal_position": Register(30, 2),
    "moving_speed": Register(32, 2),
    "torque_limit": Register(35, 2),
    "present_position": Register(37, 2),
    "present_speed": Register(39, 2),
    "present_load": Register(41, 2),
    "present_voltage": Register(45, 1),
    "present_temperature": Register(46, 1),
    "registered": Register(47, 1),
    "moving": Register(49, 1),
    "hardware_error_status": Register(50, 1),
    "punch": Register(51, 2),
}

FEETECH_SCS: dict[str, Register] = {
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
    "minimum_startup_force": Register(24, 2),
    "cw_dead_zone": Register(26, 1),
    "ccw_dead_zone": Register(27, 1),
    "torque_enable": Register(40, 1),
    "goal_position": Register(42, 2),
    "goal_time": Register(44, 2),
    "goal_speed": Register(46, 2),
    "lock": Register(48, 1),
    "present_position": Register(56, 2),
    "present_speed": Register(58, 2),
    "present_load": Register(60, 2),
    "present_voltage": Register(62, 1),
    "present_temperature": Register(63, 1),
    "async_write_flag": Register(64, 1),
    "status": Register(65, 1),
    "moving": Register(66, 1),
    "present_current": Register(69, 2),
}

# Hardware-error bits -> normalised fault names.
#: XL-320 Hardware Error Status(50) holds the Shutdown(18) bits: 0 overload, 1 overheating,
#: 2 input voltage (the page's voltage-limit text borrows the X series' 0x10; its Shutdown
#: table is the one that names XL-320 bits).
DYNAMIXEL_XL320_ERROR_BITS: dict[int, str] = {0: "overload", 1: "overheating", 2: "voltage"}
#: SCSCL "Servo Status"(65): BIT0 voltage, BIT2 temperature, BIT5 load (the SCSCL memory
#: table, 3.2; the SCS15 manual's "Current status byte" has the same three).
FEETECH_SCS_ERROR_BITS: dict[int, str] = {0: "voltage", 2: "overheating", 5: "overload"}

#: The gain registers of the two families' gain sets (robot/servo/gains.py).
GAIN_REGISTERS_MORE: dict[str, dict[str, Register]] = {
    "dynamixel_xl320": {n: DYNAMIXEL_XL320[n] for n in ("d_gain", "i_gain", "p_gain")},
    "feetech_scs": {n: FEETECH_SCS[n] for n in ("p_coefficient", "d_coefficient",
                                                 "i_coefficient")},
}
