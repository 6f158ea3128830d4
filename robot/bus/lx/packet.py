"""LX bus packets (HiWonder/LewanSoul "Bus Servo Communication Protocol"): framing, the
checksum, and finding one servo's answer in the bytes that come back.

``0x55 0x55 | id | length | command | parameters | checksum``; length = parameters + 3;
checksum = ~(id + length + command + sum(parameters)) & 0xFF (command numbers and lengths:
``robot.bus.lx.tables.LX_COMMANDS``). Pure functions and a small parser: no I/O here.
"""

from __future__ import annotations

from typing import NamedTuple

from robot.bus.lx.tables import LX_BROADCAST_ID, LX_COMMANDS, LX_HEADER, LxCommand

#: Bytes of a packet around its parameters: header 2, id, length, command, checksum.
OVERHEAD = 6
#: Bits on the wire per byte (8N1: start + 8 data + stop).
BITS_PER_BYTE = 10


class Frame(NamedTuple):
    """One well-formed packet: sender/target id, command number, parameters."""

    servo_id: int
    code: int
    params: bytes


def checksum(body: bytes | bytearray) -> int:
    """``~sum & 0xFF`` over id, length, command and parameters."""
    return ~sum(body) & 0xFF


def encode(servo_id: int, name: str, params: bytes = b"") -> bytes:
    """The packet that sends command ``name`` (a key of LX_COMMANDS) to ``servo_id``."""
    cmd = LX_COMMANDS[name]
    if len(params) != cmd.params:
        raise ValueError(f"LX {name} takes {cmd.params} parameter bytes, got {len(params)}")
    if not 0 <= servo_id <= LX_BROADCAST_ID:
        raise ValueError(f"LX servo id must be 0..{LX_BROADCAST_ID}, got {servo_id}")
    body = bytes([servo_id, len(params) + 3, cmd.code]) + params
    return LX_HEADER + body + bytes([checksum(body)])


def packet_bytes(cmd: LxCommand, *, reply: bool = False) -> int:
    """Length on the wire of ``cmd``'s request (or, ``reply``, its answer) [bytes]."""
    n = cmd.reply if reply else cmd.params
    return OVERHEAD + (n or 0)


def word(value: int) -> bytes:
    """A 16-bit little-endian word (two's complement for negatives)."""
    return (value & 0xFFFF).to_bytes(2, "little")


def value(params: bytes, offset: int, size: int, *, signed: bool = False) -> int:
    """The little-endian integer at ``offset`` in a reply's parameters."""
    return int.from_bytes(params[offset:offset + size], "little", signed=signed)


class ReplyParser:
    """Finds well-formed frames in a byte stream fed piecewise.

    Skips noise and frames with a bad checksum (counted in ``bad_checksum``). A request
    echoed back by a one-wire adapter parses as a frame too; callers match on id, command
    and parameter count, so an echo (no parameters) is never taken for the answer.
    """

    def __init__(self) -> None:
        self.buf = bytearray()
        self.bad_checksum = 0

    def feed(self, data: bytes) -> list[Frame]:
        self.buf += data
        out: list[Frame] = []
        while True:
            start = self.buf.find(LX_HEADER)
            if start < 0:
                del self.buf[:max(0, len(self.buf) - 1)]   # keep a lone trailing 0x55
                return out
            del self.buf[:start]
            # 55 55 55 ...: the header starts one later (ids and lengths are never 0x55 twice)
            if len(self.buf) >= 3 and self.buf[2] == LX_HEADER[0]:
                del self.buf[0]
                continue
            if len(self.buf) < 4:
                return out
            length = self.buf[3]
            if length < 3:
                del self.buf[:2]
                continue
            total = length + 3
            if len(self.buf) < total:
                return out
            packet = bytes(self.buf[:total])
            if checksum(packet[2:-1]) != packet[-1]:
                self.bad_checksum += 1
                del self.buf[:2]
                continue
            del self.buf[:total]
            out.append(Frame(packet[2], packet[4], packet[5:-1]))
