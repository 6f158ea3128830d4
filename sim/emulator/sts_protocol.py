"""Feetech STS/SMS protocol (Protocol-1 style) on the servo side.

Reference: Feetech "SMS/STS communication protocol" and scservo_sdk's
``protocol_packet_handler`` (what the host sends, what it accepts back).

Packet: ``FF FF | id | len | instruction/error | params | checksum`` where ``len`` counts
params + 2 and ``checksum = ~(id + len + instruction + sum(params)) & 0xFF``. Words are
little-endian (scservo_sdk ``PacketHandler(0)``). The status byte of a reply carries the
servo's "status" register (voltage, angle sensor, overheat, overcurrent, overload bits);
there is no instruction/range error code: a refused write is not applied and its status
carries only the Status register, and an out-of-limit goal is clamped to the angle limits.
Broadcast ping is answered by every servo (LeRobot's scan relies on it); Reg Write (0x04)
and Action (0x05) are modelled (Async Write Flag, 64).
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulator import dispatch
from sim.emulator.servo import EmulatedServo
from sim.emulator.wire import FrameParser, Handled

HEADER = b"\xff\xff"
HEADER_BYTE = 0xFF
BROADCAST_ID = 0xFE
PREFIX_LEN = 4                   # FF FF id len
MIN_LEN = 2                      # instruction/error + checksum
FAMILY = "feetech_sts"

NAMES = dispatch.NAMES
INSTRUCTIONS = frozenset({dispatch.PING, dispatch.READ, dispatch.WRITE, dispatch.REG_WRITE,
                          dispatch.ACTION, dispatch.SYNC_READ, dispatch.SYNC_WRITE})


def checksum(body: bytes | bytearray) -> int:
    """``~sum & 0xFF`` over id, length, instruction and params."""
    return ~sum(body) & 0xFF


def status(servo_id: int, error: int, params: bytes = b"") -> bytes:
    body = bytes([servo_id, len(params) + MIN_LEN, error]) + params
    return HEADER + body + bytes([checksum(body)])


class Parser(FrameParser):
    """Instruction packets: FF FF id len instruction params checksum."""

    header = HEADER
    prefix_len = PREFIX_LEN

    def total_length(self, prefix: bytes) -> int | None:
        if prefix[2] == HEADER_BYTE or prefix[3] < MIN_LEN:   # FF FF FF: header one later
            return None
        return PREFIX_LEN + prefix[3]

    def decode(self, packet: bytes) -> tuple[int, int, bytes] | None:
        if checksum(packet[2:-1]) != packet[-1]:
            return None
        return packet[2], packet[4], packet[5:-1]


def _error_bits(servo: EmulatedServo) -> int:
    return servo.error_bits


# Status return level (8): 0 = reply to ping and read only, 1 = to every instruction.
# The status byte is the Status register (65); STS has no code for a refused write or an
# unknown instruction (the servo ignores them), so those are 0 / no reply.
PROTOCOL = dispatch.Protocol(
    family=FAMILY, instructions=INSTRUCTIONS, broadcast_id=BROADCAST_ID, addr_width=1,
    level_read=0, level_all=1, status=status, alert=_error_bits,
    ping_params=lambda servo: b"", write_errors={}, access_error=0, instruction_error=None)


def handle(servo_id: int, inst: int, params: bytes,
           hearing: Mapping[int, EmulatedServo]) -> Handled:
    """Execute one instruction on the servos that hear it (see ``sim.emulator.dispatch``)."""
    return dispatch.handle(PROTOCOL, servo_id, inst, params, hearing)
