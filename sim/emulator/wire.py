"""What the protocol codecs share on the chain side: reply records, sync-read/-write over
the servos that hear a packet, and an incremental frame parser.

``sim.emulator.dxl_protocol`` and ``sim.emulator.sts_protocol`` build on these; the servo itself lives in
``sim.emulator.servo``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import NamedTuple

from sim.emulator.servo import EmulatedServo
from sim.emulator.servo_state import decode_value


class Reply(NamedTuple):
    """One status packet to send: from ``servo_id``, after ``delay_s`` [s] of return delay."""

    servo_id: int
    data: bytes
    delay_s: float


class Handled(NamedTuple):
    """What a codec made of one instruction packet: the log fields plus the replies."""

    instruction: str
    ids: tuple[int, ...]
    address: int | None
    values: dict[int, int]
    length: int | None
    replies: list[Reply]


def chain_replies(hearing: Mapping[int, EmulatedServo], items: Sequence[tuple[int, int, int]],
                  read_status: Callable[[EmulatedServo, int, int], bytes]) -> list[Reply]:
    """Status packets for (id, address, length) reads in request order (sync/bulk read).

    A missing servo is silent and, as on a real chain, silences every servo after it.
    """
    replies = []
    for sid, address, n in items:
        servo = hearing.get(sid)
        if servo is None:
            break
        replies.append(Reply(sid, read_status(servo, address, n), servo.return_delay_s))
    return replies


def sync_write(family: str, address: int, length: int, chunk: bytes,
               hearing: Mapping[int, EmulatedServo]) -> dict[int, int]:
    """Apply ``(id, data[length])*`` to the servos that hear it; return id → value written."""
    values: dict[int, int] = {}
    step = 1 + length
    for i in range(0, len(chunk) - step + 1, step):
        sid, data = chunk[i], chunk[i + 1:i + step]
        values[sid] = decode_value(hearing[sid].family if sid in hearing else family, address,
                                   data)   # the servo's byte order (an SCS: big-endian)
        if sid in hearing:
            hearing[sid].write(address, data)
    return values


class FrameParser:
    """Incremental instruction-packet parser; subclasses give the framing rules.

    ``feed`` returns every complete (servo_id, instruction, params); packets failing the
    checksum are counted in ``bad_checksum`` and skipped (resync one byte later).
    """

    header: bytes = b""
    prefix_len: int = 0

    def __init__(self) -> None:
        self.buf = bytearray()
        self.bad_checksum = 0

    def total_length(self, prefix: bytes) -> int | None:
        """Whole packet length [bytes] from its first ``prefix_len`` bytes; None: no packet."""
        raise NotImplementedError

    def decode(self, packet: bytes) -> tuple[int, int, bytes] | None:
        """(servo_id, instruction, params), or None when the checksum is wrong."""
        raise NotImplementedError

    def feed(self, data: bytes) -> list[tuple[int, int, bytes]]:
        self.buf += data
        out: list[tuple[int, int, bytes]] = []
        while True:
            start = self.buf.find(self.header)
            if start < 0:
                del self.buf[:max(0, len(self.buf) - (len(self.header) - 1))]
                return out
            del self.buf[:start]
            if len(self.buf) < self.prefix_len:
                return out
            total = self.total_length(bytes(self.buf[:self.prefix_len]))
            if total is None:
                del self.buf[:1]
                continue
            if len(self.buf) < total:
                return out
            frame = self.decode(bytes(self.buf[:total]))
            if frame is None:
                self.bad_checksum += 1
                del self.buf[:1]
                continue
            del self.buf[:total]
            out.append(frame)
