"""Dynamixel Protocol 1.0 (AX-12A, AX-18A, MX-28) on the servo side.

Reference: ROBOTIS e-Manual, "Protocol 1.0" (Instruction Packet, Status Packet,
instructions Ping 0x01, Read 0x02, Write 0x03, Reg Write 0x04, Action 0x05, Reset 0x06,
Sync Write 0x83; the AX series has no Sync Read and no Reboot).

Packet: ``FF FF | id | len | instruction/error | params | checksum`` where ``len`` counts
params + 2 and ``checksum = ~(id + len + instruction + sum(params)) & 0xFF``; words are
little-endian. (Feetech's STS framing is a clone of this one, so the frame parser and the
status builder are shared with ``sim.emulator.sts_protocol``.) The status packet's error byte:
bit 0 input voltage, 1 angle limit, 2 overheating, 3 range, 4 checksum, 5 overload,
6 instruction. Status Return Level(16): 0 = ping only, 1 = ping and read, 2 = all.
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulator import dispatch
from sim.emulator.servo import EmulatedServo
from sim.emulator.servo_state import WriteError
from sim.emulator.sts_protocol import HEADER, Parser, checksum, status
from sim.emulator.wire import Handled

__all__ = ["HEADER", "NAMES", "PROTOCOL", "Parser", "checksum", "handle", "status"]

BROADCAST_ID = 0xFE
FAMILY = "dynamixel_p1"
ERR_ANGLE_LIMIT = 1 << 1
ERR_RANGE = 1 << 3
ERR_INSTRUCTION = 1 << 6

NAMES = dispatch.NAMES
INSTRUCTIONS = frozenset({dispatch.PING, dispatch.READ, dispatch.WRITE, dispatch.REG_WRITE,
                          dispatch.ACTION, dispatch.FACTORY_RESET, dispatch.SYNC_WRITE})


def _error_bits(servo: EmulatedServo) -> int:
    return servo.error_bits


# Protocol 1.0 has no access error code: a write to a read-only or undefined address, or a
# value out of range, is answered with the Range Error bit; a goal outside CW/CCW Angle
# Limit with the Angle Limit Error bit.
PROTOCOL = dispatch.Protocol(
    family=FAMILY, instructions=INSTRUCTIONS, broadcast_id=BROADCAST_ID, addr_width=1,
    level_read=1, level_all=2, status=status, alert=_error_bits,
    ping_params=lambda servo: b"",
    write_errors={WriteError.ACCESS: ERR_RANGE, WriteError.RANGE: ERR_RANGE,
                  WriteError.LENGTH: ERR_RANGE, WriteError.LIMIT: ERR_ANGLE_LIMIT},
    access_error=ERR_RANGE, instruction_error=ERR_INSTRUCTION)


def handle(servo_id: int, inst: int, params: bytes,
           hearing: Mapping[int, EmulatedServo]) -> Handled:
    """Execute one instruction on the servos that hear it (see ``sim.emulator.dispatch``)."""
    return dispatch.handle(PROTOCOL, servo_id, inst, params, hearing)
