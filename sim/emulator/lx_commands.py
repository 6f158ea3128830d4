"""The emulator's own transcription of the LX bus servo commands (HiWonder/LewanSoul "Bus
Servo Communication Protocol": 4. Command list, Table 2; Table 4, the read commands and
the length of their answers). Written from the manual, not from the driver's
``robot.bus.lx.tables.LX_COMMANDS`` (``tests/test_lx_tables.py`` compares the two).

Each entry: command number -> (name, length byte of the host's packet, length byte of the
servo's answer or None: write commands are never answered). The length byte counts
itself, the command and the checksum, so it is the parameter count + 3.
"""

from __future__ import annotations

HEADER = b"\x55\x55"
BROADCAST_ID = 0xFE     # every servo executes it; none answers, except ID read
BAUD = 115200           # the only rate (manual, 2. UART interface)

# number: (name, request length, answer length)
COMMANDS: dict[int, tuple[str, int, int | None]] = {
    1: ("SERVO_MOVE_TIME_WRITE", 7, None),
    2: ("SERVO_MOVE_TIME_READ", 3, 7),
    7: ("SERVO_MOVE_TIME_WAIT_WRITE", 7, None),
    8: ("SERVO_MOVE_TIME_WAIT_READ", 3, 7),
    11: ("SERVO_MOVE_START", 3, None),
    12: ("SERVO_MOVE_STOP", 3, None),
    13: ("SERVO_ID_WRITE", 4, None),
    14: ("SERVO_ID_READ", 3, 4),
    17: ("SERVO_ANGLE_OFFSET_ADJUST", 4, None),
    18: ("SERVO_ANGLE_OFFSET_WRITE", 3, None),
    19: ("SERVO_ANGLE_OFFSET_READ", 3, 4),
    20: ("SERVO_ANGLE_LIMIT_WRITE", 7, None),
    21: ("SERVO_ANGLE_LIMIT_READ", 3, 7),
    22: ("SERVO_VIN_LIMIT_WRITE", 7, None),
    23: ("SERVO_VIN_LIMIT_READ", 3, 7),
    24: ("SERVO_TEMP_MAX_LIMIT_WRITE", 4, None),
    25: ("SERVO_TEMP_MAX_LIMIT_READ", 3, 4),
    26: ("SERVO_TEMP_READ", 3, 4),
    27: ("SERVO_VIN_READ", 3, 5),
    28: ("SERVO_POS_READ", 3, 5),
    29: ("SERVO_OR_MOTOR_MODE_WRITE", 7, None),
    30: ("SERVO_OR_MOTOR_MODE_READ", 3, 7),
    31: ("SERVO_LOAD_OR_UNLOAD_WRITE", 4, None),
    32: ("SERVO_LOAD_OR_UNLOAD_READ", 3, 4),
    33: ("SERVO_LED_CTRL_WRITE", 4, None),
    34: ("SERVO_LED_CTRL_READ", 3, 4),
    35: ("SERVO_LED_ERROR_WRITE", 4, None),
    36: ("SERVO_LED_ERROR_READ", 3, 4),
}
#: Log names: the manual's command name without "SERVO_", lower case.
NAMES: dict[int, str] = {n: name.removeprefix("SERVO_").lower() for n, (name, _, _) in
                         COMMANDS.items()}

# Ranges and factory values the manual prints.
POSITION_MAX = 1000          # 0..1000 = 0..240 deg
MOVE_TIME_MAX_MS = 30000
OFFSET_RANGE = (-125, 125)   # = -30..30 deg
VIN_RANGE_MV = (4500, 12000)
TEMP_LIMIT_RANGE = (50, 100)
TEMP_LIMIT_FACTORY = 85
MOTOR_SPEED_RANGE = (-1000, 1000)
#: Table 3: LED alarm bits.
ALARM_BITS: dict[int, str] = {0: "overheating", 1: "voltage", 2: "overload"}
