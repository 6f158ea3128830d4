"""Dynamixel Protocol 2.0 on the servo side: framing, CRC, byte stuffing, instructions.

Reference: ROBOTIS e-Manual "DYNAMIXEL Protocol 2.0" and dynamixel_sdk's
``protocol2_packet_handler`` (what the host actually sends and how it parses replies).

Packet: ``FF FF FD 00 | id | len_l len_h | instruction | params | crc_l crc_h`` where
``len`` counts instruction + params + CRC after stuffing, and the CRC-16 (polynomial 0x8005,
ROBOTIS table) covers every byte before it, as sent (stuffed).
"""

from __future__ import annotations

from collections.abc import Mapping

from sim.emulator import dispatch
from sim.emulator.servo import EmulatedServo
from sim.emulator.servo_state import WriteError
from sim.emulator.wire import FrameParser, Handled, Reply

HEADER = b"\xff\xff\xfd\x00"
STUFF_PATTERN = b"\xff\xff\xfd"
STUFF_BYTE = 0xFD
BROADCAST_ID = 0xFE
PREFIX_LEN = 7                   # FF FF FD 00 id len_l len_h
MIN_LEN = 3                      # instruction + CRC
CRC_POLY = 0x8005
FAMILY = "dynamixel_x"

NAMES = dispatch.NAMES
INST_STATUS = 0x55
INST_PING = dispatch.PING

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


def _ping_params(servo: EmulatedServo) -> bytes:
    return servo.get("model_number").to_bytes(2, "little") + bytes([servo.get("firmware_version")])


# Status return level: 0 ping only, 1 ping + reads, 2 everything (X manual, address 68).
PROTOCOL = dispatch.Protocol(
    family=FAMILY, instructions=frozenset(dispatch.NAMES), broadcast_id=BROADCAST_ID,
    addr_width=2, level_read=1, level_all=2, status=status, alert=_alert,
    ping_params=_ping_params, write_errors=WRITE_ERRORS, access_error=ERR_ACCESS,
    instruction_error=ERR_INSTRUCTION, fast_reply=_fast_reply)


def handle(servo_id: int, inst: int, params: bytes,
           hearing: Mapping[int, EmulatedServo]) -> Handled:
    """Execute one instruction on the servos that hear it (see ``sim.emulator.dispatch``)."""
    return dispatch.handle(PROTOCOL, servo_id, inst, params, hearing)
