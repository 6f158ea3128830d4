"""MIDI Time Code (MTC): the timecode a show controller or a DAW sends over MIDI.

Quarter-frame messages (status 0xF1, data 0nnn dddd; MIDI 1.0 Detailed Specification, MTC):
eight pieces, four a frame, carry one timecode over two frames, least significant nibble
first: 0 frame low, 1 frame high (1 bit), 2 second low, 3 second high (2 bits), 4 minute
low, 5 minute high, 6 hour low, 7 hour high: bit 0 the hour's fifth bit, bits 1-2 the
rate (0: 24, 1: 25, 2: 29.97 drop-frame, 3: 30 fps). The timecode is that of the frame
that began as piece 0 was sent, so when piece p arrives the time is that frame plus p/4
frames; after the first whole group every piece is a fresh reading (the next group's
frame is two frames on). A full-frame message (SysEx F0 7F dev 01 01 hr mn sc fr F7)
places the time at once (a locate: the controller jumped or cued).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from robot.timecode.frames import RATES, Rate, frame_number

#: Rate codes of piece 7 and of the full-frame message's hour byte.
RATE_CODES = (RATES["24"], RATES["25"], RATES["29.97df"], RATES["30"])


@dataclass(frozen=True)
class Reading:
    """A timecode reading: ``at`` when it arrived [s, the receiver's clock]; ``frame``:
    the position then [frames since 00:00:00:00, fractional]; ``rate``; ``locate``: a
    full-frame message (a jump is expected)."""

    at: float
    frame: float
    rate: Rate
    locate: bool = False


def _time(h_byte: int, m: int, s: int, f: int) -> tuple[Rate, int] | None:
    rate = RATE_CODES[(h_byte >> 5) & 0x3]
    h = h_byte & 0x1F
    if h > 23 or m > 59 or s > 59 or f >= rate.base:
        return None
    return rate, frame_number(h, m, s, f, rate)


class MtcDecoder:
    """Feed quarter frames (``quarter(piece, nibble, at)``) and SysEx data
    (``sysex(data, at)``, without F0/F7); each returns a Reading or None."""

    def __init__(self) -> None:
        self._nibbles = [0] * 8
        self._next = 0
        self._have = 0                   # pieces of this group received in order
        self._base: int | None = None    # the frame of the group in progress (once locked)
        self.rate: Rate | None = None

    def quarter(self, piece: int, nibble: int, at: float) -> Reading | None:
        if not 0 <= piece < 8 or not 0 <= nibble < 16:
            return None
        if piece != self._next:          # out of order: backwards, or a lost message
            self._have, self._next, self._base = 0, 0, None
            if piece != 0:
                return None
        self._nibbles[piece] = nibble
        self._have += 1
        self._next = (piece + 1) % 8
        reading: Reading | None = None
        if piece == 7 and self._have == 8:
            n = self._nibbles
            got = _time((n[7] << 4) | n[6], (n[5] << 4) | n[4], (n[3] << 4) | n[2],
                        (n[1] << 4) | n[0])
            self._have = 0
            if got is None:
                self._base = None
                return None
            self.rate, frame = got
            reading = Reading(at, frame + 1.75, self.rate)
            self._base = frame + 2
        elif self._base is not None and self.rate is not None:
            reading = Reading(at, self._base + piece / 4.0, self.rate)
        return reading

    def sysex(self, data: Sequence[int], at: float) -> Reading | None:
        """A full-frame message's data (7F dev 01 01 hr mn sc fr), else None."""
        d = list(data)
        if len(d) != 8 or d[0] != 0x7F or d[2:4] != [0x01, 0x01]:
            return None
        got = _time(d[4], d[5], d[6], d[7])
        if got is None:
            return None
        self.rate, frame = got
        self._have, self._next, self._base = 0, 0, None
        return Reading(at, float(frame), self.rate, locate=True)
