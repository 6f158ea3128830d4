"""Dynamixel Protocol 2.0 on the servo side: framing, CRC, byte stuffing, instructions.

Reference: ROBOTIS e-Manual "DYNAMIXEL Protocol 2.0" and dynamixel_sdk's
``protocol2_packet_handler`` (what the host actually sends and how it parses replies).

Packet: ``FF FF FD 00 | id | len_l len_h | instruction | params | crc_l crc_h`` where
``len`` counts instruction + params + CRC after stuffing, and the CRC-16 (polynomial 0x8005,
ROBOTIS table) covers every byte before it, as sent (stuffed).
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulated_servo import EmulatedServo, WriteError, decode_value
from sim.wire import FrameParser, Handled, Reply, chain_replies, sync_write

HEADER = b"\xff\xff\xfd\x00"
STUFF_PATTERN = b"\xff\xff\xfd"
STUFF_BYTE = 0xFD
BROADCAST_ID = 0xFE
PREFIX_LEN = 7                   # FF FF FD 00 id len_l len_h
MIN_LEN = 3                      # instruction + CRC
CRC_POLY = 0x8005
FAMILY = "dynamixel_x"

INST_PING = 0x01
INST_READ = 0x02
INST_WRITE = 0x03
INST_REBOOT = 0x08
INST_STATUS = 0x55
INST_SYNC_READ = 0x82
INST_SYNC_WRITE = 0x83
INST_FAST_SYNC_READ = 0x8A
INST_BULK_READ = 0x92
INST_BULK_WRITE = 0x93
INST_FAST_BULK_READ = 0x9A
NAMES: dict[int, str] = {
    INST_PING: "ping", INST_READ: "read", INST_WRITE: "write", INST_REBOOT: "reboot",
    INST_SYNC_READ: "sync_read", INST_SYNC_WRITE: "sync_write",
    INST_FAST_SYNC_READ: "fast_sync_read", INST_BULK_READ: "bulk_read",
    INST_BULK_WRITE: "bulk_write", INST_FAST_BULK_READ: "fast_bulk_read",
}

# Status-packet error byte: a number in bits 0-6, bit 7 = hardware alert.
ERR_RESULT_FAIL = 1
ERR_INSTRUCTION = 2
ERR_CRC = 3
ERR_DATA_RANGE = 4
ERR_DATA_LENGTH = 5
ERR_DATA_LIMIT = 6
ERR_ACCESS = 7
ERR_ALERT = 0x80
WRITE_ERRORS: dict[WriteError, int] = {
    WriteError.NONE: 0, WriteError.ACCESS: ERR_ACCESS, WriteError.RANGE: ERR_DATA_RANGE,
    WriteError.LIMIT: ERR_DATA_LIMIT, WriteError.LENGTH: ERR_DATA_LENGTH,
}

# Status return level: 0 ping only, 1 ping + reads, 2 everything.
LEVEL_READ = 1
LEVEL_ALL = 2


def _crc_table() -> list[int]:
    table = []
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = ((crc << 1) ^ CRC_POLY) if crc & 0x8000 else crc << 1
        table.append(crc & 0xFFFF)
    return table


CRC_TABLE = _crc_table()


def crc16(data: bytes | bytearray, crc: int = 0) -> int:
    """ROBOTIS CRC-16 (IBM polynomial 0x8005, no reflection, initial 0)."""
    for b in data:
        crc = ((crc << 8) ^ CRC_TABLE[((crc >> 8) ^ b) & 0xFF]) & 0xFFFF
    return crc


def stuff(body: bytes) -> bytes:
    """Insert FD after every FF FF FD in ``body`` (instruction/error + params)."""
    out = bytearray()
    for i, b in enumerate(body):
        out.append(b)
        if i >= 2 and body[i - 2:i + 1] == STUFF_PATTERN:
            out.append(STUFF_BYTE)
    return bytes(out)


def unstuff(body: bytes) -> bytes:
    """Remove the FD that follows every FF FF FD."""
    out = bytearray()
    i = 0
    while i < len(body):
        out.append(body[i])
        if out[-3:] == STUFF_PATTERN and i + 1 < len(body) and body[i + 1] == STUFF_BYTE:
            i += 1
        i += 1
    return bytes(out)


def frame(servo_id: int, body: bytes) -> bytes:
    """A whole packet around ``body`` (instruction + params, unstuffed)."""
    stuffed = stuff(body)
    head = HEADER + bytes([servo_id]) + (len(stuffed) + 2).to_bytes(2, "little") + stuffed
    return head + crc16(head).to_bytes(2, "little")


def status(servo_id: int, error: int, params: bytes = b"") -> bytes:
    return frame(servo_id, bytes([INST_STATUS, error]) + params)


class Parser(FrameParser):
    """Instruction packets: length from the header, CRC checked, params unstuffed."""

    header = HEADER
    prefix_len = PREFIX_LEN

    def total_length(self, prefix: bytes) -> int | None:
        length = int.from_bytes(prefix[5:7], "little")
        return PREFIX_LEN + length if length >= MIN_LEN else None

    def decode(self, packet: bytes) -> tuple[int, int, bytes] | None:
        if crc16(packet[:-2]) != int.from_bytes(packet[-2:], "little"):
            return None
        body = unstuff(packet[PREFIX_LEN:-2])
        return packet[4], body[0], body[1:]


def _alert(servo: EmulatedServo) -> int:
    return ERR_ALERT if servo.error_bits else 0


def _read_status(servo: EmulatedServo, address: int, length: int) -> bytes:
    data = servo.read(address, length)
    err = _alert(servo) | (0 if data is not None else ERR_ACCESS)
    # An access error still carries ``length`` zero bytes so the SDK can index the data.
    return status(servo.servo_id, err, data if data is not None else bytes(length))


def _fast_reply(hearing: Mapping[int, EmulatedServo],
                items: list[tuple[int, int, int]]) -> list[Reply]:
    """One packet from id 0xFE: per servo ERR ID DATA CRC; stops where a servo is missing."""
    length = 1 + sum(n + 4 for _, _, n in items)
    packet = bytearray(HEADER + bytes([BROADCAST_ID]) + length.to_bytes(2, "little")
                       + bytes([INST_STATUS]))
    delay = 0.0
    for sid, address, n in items:
        servo = hearing.get(sid)
        if servo is None:
            break  # the chain stops here: the host sees a truncated packet
        data = servo.read(address, n)
        err = _alert(servo) | (0 if data is not None else ERR_ACCESS)
        packet += bytes([err, sid]) + (data if data is not None else bytes(n))
        packet += crc16(packet).to_bytes(2, "little")
        delay += servo.return_delay_s
    if len(packet) == PREFIX_LEN + 1:
        return []
    return [Reply(BROADCAST_ID, bytes(packet), delay)]


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
    word = int.from_bytes

    def reply(s: EmulatedServo, packet: bytes, level: int) -> None:
        if servo_id != BROADCAST_ID and s.status_return_level >= level:
            replies.append(Reply(s.servo_id, packet, s.return_delay_s))

    if inst == INST_PING:
        targets = sorted(hearing.items()) if servo_id == BROADCAST_ID else (
            [(servo_id, servo)] if servo else [])
        for sid, s in targets:
            params_out = s.get("model_number").to_bytes(2, "little") + bytes(
                [s.get("firmware_version")])
            replies.append(Reply(sid, status(sid, _alert(s), params_out), s.return_delay_s))
    elif inst == INST_READ and len(params) == 4:
        address, length = word(params[0:2], "little"), word(params[2:4], "little")
        if servo is not None:
            reply(servo, _read_status(servo, address, length), LEVEL_READ)
    elif inst == INST_WRITE and len(params) > 2:
        address, data = word(params[0:2], "little"), params[2:]
        length = len(data)
        values[servo_id] = decode_value(FAMILY, address, data)
        targets_w = list(hearing.values()) if servo_id == BROADCAST_ID else (
            [servo] if servo else [])
        for s in targets_w:
            sid = s.servo_id     # a new id takes effect after the reply (sent as the old id)
            err = WRITE_ERRORS[s.write(address, data)]
            reply(s, status(sid, err | _alert(s)), LEVEL_ALL)
    elif inst == INST_REBOOT:
        if servo is not None:   # the status goes out first, then the servo restarts
            reply(servo, status(servo_id, _alert(servo)), LEVEL_ALL)
            servo.reboot()
    elif inst in (INST_SYNC_READ, INST_FAST_SYNC_READ) and len(params) >= 4:
        address, length = word(params[0:2], "little"), word(params[2:4], "little")
        ids = tuple(params[4:])
        items = [(sid, address, length) for sid in ids]
        replies = (_fast_reply(hearing, items) if inst == INST_FAST_SYNC_READ
                   else chain_replies(hearing, items, _read_status))
    elif inst == INST_SYNC_WRITE and len(params) >= 4:
        address, length = word(params[0:2], "little"), word(params[2:4], "little")
        values = sync_write(FAMILY, address, length, params[4:], hearing)
        ids = tuple(values)
    elif inst in (INST_BULK_READ, INST_FAST_BULK_READ):
        items = [(params[i], word(params[i + 1:i + 3], "little"),
                  word(params[i + 3:i + 5], "little")) for i in range(0, len(params) - 4, 5)]
        ids = tuple(sid for sid, _, _ in items)
        values = {sid: a for sid, a, _ in items}   # per-id start address
        replies = (_fast_reply(hearing, items) if inst == INST_FAST_BULK_READ
                   else chain_replies(hearing, items, _read_status))
    elif inst == INST_BULK_WRITE:
        i = 0
        while i + 5 <= len(params):
            sid, a, n = params[i], word(params[i + 1:i + 3], "little"), word(
                params[i + 3:i + 5], "little")
            data = params[i + 5:i + 5 + n]
            values[sid] = decode_value(FAMILY, a, data)
            if sid in hearing:
                hearing[sid].write(a, data)
            i += 5 + n
        ids = tuple(values)
    elif servo is not None:
        reply(servo, status(servo_id, ERR_INSTRUCTION | _alert(servo)), LEVEL_READ)
    return Handled(name, ids, address, values, length, replies)
