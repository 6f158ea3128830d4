"""Feetech STS/SMS protocol (Protocol-1 style) on the servo side.

Reference: Feetech "SMS/STS communication protocol" and scservo_sdk's
``protocol_packet_handler`` (what the host sends, what it accepts back).

Packet: ``FF FF | id | len | instruction/error | params | checksum`` where ``len`` counts
params + 2 and ``checksum = ~(id + len + instruction + sum(params)) & 0xFF``. Words are
little-endian (scservo_sdk ``PacketHandler(0)``). The status byte of a reply carries the
servo's "status" register (voltage, angle sensor, overheat, overcurrent, overload bits);
there is no instruction/range error code, so refused writes are silently ignored, as on
the servo, and an out-of-limit goal is clamped to the angle limits.
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulated_servo import EmulatedServo, decode_value
from sim.wire import FrameParser, Handled, Reply, chain_replies, sync_write

HEADER = b"\xff\xff"
HEADER_BYTE = 0xFF
BROADCAST_ID = 0xFE
PREFIX_LEN = 4                   # FF FF id len
MIN_LEN = 2                      # instruction/error + checksum
FAMILY = "feetech_sts"

INST_PING = 0x01
INST_READ = 0x02
INST_WRITE = 0x03
INST_SYNC_READ = 0x82
INST_SYNC_WRITE = 0x83
NAMES: dict[int, str] = {
    INST_PING: "ping", INST_READ: "read", INST_WRITE: "write",
    INST_SYNC_READ: "sync_read", INST_SYNC_WRITE: "sync_write",
}

# Status return level: 0 replies to ping and read only, 1 to everything.
LEVEL_ALL = 1


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


def _read_status(servo: EmulatedServo, address: int, length: int) -> bytes:
    data = servo.read(address, length)
    return status(servo.servo_id, servo.error_bits, data if data is not None else bytes(length))


def handle(servo_id: int, inst: int, params: bytes,
           hearing: Mapping[int, EmulatedServo]) -> Handled:
    """Execute one instruction on the servos that hear it; return log fields and replies."""
    name = NAMES.get(inst, f"unknown_0x{inst:02x}")
    servo = hearing.get(servo_id)
    replies: list[Reply] = []
    ids: tuple[int, ...] = (servo_id,)
    address: int | None = None
    length: int | None = None
    values: dict[int, int] = {}

    if inst == INST_PING:
        if servo is not None:
            replies.append(Reply(servo_id, status(servo_id, servo.error_bits),
                                 servo.return_delay_s))
    elif inst == INST_READ and len(params) == 2:
        address, length = params[0], params[1]
        if servo is not None:
            replies.append(Reply(servo_id, _read_status(servo, address, length),
                                 servo.return_delay_s))
    elif inst == INST_WRITE and len(params) > 1:
        address, data = params[0], params[1:]
        length = len(data)
        values[servo_id] = decode_value(FAMILY, address, data)
        targets = list(hearing.values()) if servo_id == BROADCAST_ID else (
            [servo] if servo else [])
        for s in targets:
            sid = s.servo_id     # a new id takes effect after the reply (sent as the old id)
            s.write(address, data)
            if servo_id != BROADCAST_ID and s.status_return_level >= LEVEL_ALL:
                replies.append(Reply(sid, status(sid, s.error_bits),
                                     s.return_delay_s))
    elif inst == INST_SYNC_READ and len(params) >= 2:
        address, length = params[0], params[1]
        ids = tuple(params[2:])
        replies = chain_replies(hearing, [(sid, address, length) for sid in ids], _read_status)
    elif inst == INST_SYNC_WRITE and len(params) >= 2:
        address, length = params[0], params[1]
        values = sync_write(FAMILY, address, length, params[2:], hearing)
        ids = tuple(values)
    return Handled(name, ids, address, values, length, replies)
