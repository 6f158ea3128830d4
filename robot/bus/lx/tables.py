"""The LX servos' command set as data (the LX bus has commands, not a control table; moved
here from robot/bus/tables.py, which holds the control tables, when that passed 300 lines).
"""

from __future__ import annotations

from typing import NamedTuple


# ---------------------------------------------------------------------------------------
# HiWonder / LewanSoul LX serial bus servos (LX-16A, LX-224, LX-224HV): no control table.
# The protocol is a set of commands, each a number with fixed parameters; read commands are
# answered with a packet of the same command number carrying the value, write commands are
# never answered. Source: LewanSoul "Bus Servo Communication Protocol" (the LX-16A manual's
# protocol document, 11 pages: 3. Command Packet, Table 1; 4. Command List, Table 2;
# Table 3 LED alarm codes; Table 4 the read commands and their reply lengths).
#
# Packet (both ways): 0x55 0x55 | id | length | command | parameters | checksum, where
# length = parameters + 3 (it counts itself, the command and the checksum) and checksum =
# ~(id + length + command + sum(parameters)) & 0xFF. Words are little-endian (low byte
# first). Baud 115200, 8N1, half duplex on one wire. Id 0..253; 254 is broadcast: every
# servo executes it and none answers, except ID_READ (14), which a lone servo answers
# with its id (the way to find an unknown id: the manual warns of a bus conflict with more
# than one servo attached).
class LxCommand(NamedTuple):
    """One LX command: code: the command number; params: parameter bytes the host sends;
    reply: parameter bytes of the servo's answer (None: a write, never answered)."""

    code: int
    params: int
    reply: int | None


LX_COMMANDS: dict[str, LxCommand] = {
    # position 0..1000 (0..240 deg, 0.24 deg a step) and time 0..30000 ms; moves at once at
    # a uniform speed so as to arrive after that time
    "move_time_write": LxCommand(1, 4, None),
    "move_time_read": LxCommand(2, 0, 4),
    # as move_time_write, held until MOVE_START (11)
    "move_time_wait_write": LxCommand(7, 4, None),
    "move_time_wait_read": LxCommand(8, 0, 4),
    "move_start": LxCommand(11, 0, None),
    "move_stop": LxCommand(12, 0, None),           # stops where it is, at once
    "id_write": LxCommand(13, 1, None),            # 0..253, kept over power-off; factory 1
    "id_read": LxCommand(14, 0, 1),
    # signed char -125..125 = -30..30 deg, applied at once (the horn moves), not kept
    "angle_offset_adjust": LxCommand(17, 1, None),
    "angle_offset_write": LxCommand(18, 0, None),  # keeps the adjusted offset
    "angle_offset_read": LxCommand(19, 0, 1),
    # min, max 0..1000 with min < max; kept; factory 0, 1000
    "angle_limit_write": LxCommand(20, 4, None),
    "angle_limit_read": LxCommand(21, 0, 4),
    # min, max [mV] 4500..12000 with min < max; kept. Outside them the servo unloads.
    "vin_limit_write": LxCommand(22, 4, None),
    "vin_limit_read": LxCommand(23, 0, 4),
    # 50..100 degC, kept, factory 85. Above it the servo unloads until it cools below.
    "temp_max_limit_write": LxCommand(24, 1, None),
    "temp_max_limit_read": LxCommand(25, 0, 1),
    "temp_read": LxCommand(26, 0, 1),              # degC
    "vin_read": LxCommand(27, 0, 2),               # mV
    "pos_read": LxCommand(28, 0, 2),               # signed short: may read below 0
    # mode (0 position, 1 motor), a null byte, speed -1000..1000 (motor mode); not kept
    "or_motor_mode_write": LxCommand(29, 4, None),
    "or_motor_mode_read": LxCommand(30, 0, 4),
    # 0 unload (no torque output), 1 load (torque output); power-on 0, not kept
    "load_or_unload_write": LxCommand(31, 1, None),
    "load_or_unload_read": LxCommand(32, 0, 1),
    "led_ctrl_write": LxCommand(33, 1, None),      # 0 LED on, 1 off; kept
    "led_ctrl_read": LxCommand(34, 0, 1),
    # 0..7: which faults flash the LED (Table 3, bits below); the LED is all the servo
    # shows of them: no packet reports a fault
    "led_error_write": LxCommand(35, 1, None),
    "led_error_read": LxCommand(36, 0, 1),
}
LX_HEADER = b"\x55\x55"
LX_BROADCAST_ID = 254
LX_BAUD = 115_200
#: Manual, Table 3 (LED alarm codes 0..7 are the sums of these bits): 1 over temperature,
#: 2 over voltage (outside the VIN limits), 4 locked rotor.
LX_ALARM_BITS: dict[int, str] = {0: "overheating", 1: "voltage", 2: "overload"}

