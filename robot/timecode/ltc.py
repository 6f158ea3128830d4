"""Decoding SMPTE linear timecode (LTC) from audio: what QLab, a DAW or a sync generator
sends down an audio cable.

The signal (SMPTE ST 12-1): 80 bits a frame, biphase mark coded: the level flips at every
bit boundary, and once more in the middle of a 1. Bits 0-63 carry the frame's label in
BCD, least significant bit first: frame units 0-3, frame tens 8-9, the drop-frame flag
10, second units 16-19, tens 24-26, minute units 32-35, tens 40-42, hour units 48-51,
tens 56-57 (the rest: user bits and flags); bits 64-79 are the sync word 0011 1111 1111
1101, which also tells the direction. The label is that of the frame whose start is the
start of bit 0, so when the last bit has ended the next frame begins.

Decoding here: zero crossings with hysteresis (a tenth of the running peak, after the DC
is removed: a cable's hum and offset do not make edges), their times interpolated to a
fraction of a sample; the intervals between them are a whole bit (a 0) or a half (two
halves: a 1) against the bit period, which is learned from the signal and followed as it
drifts (a tape or a varispeed source); a word is taken when the sync word ends the last
80 bits and every field is in range. It reads any rate from 24 to 30 fps at any sample
rate from 8 kHz up, in chunks as they come (an audio input) or a whole file.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

SYNC = (0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 1)
#: Share of the running peak a swing must pass to count as an edge.
HYSTERESIS = 0.1
#: Intervals to learn the bit period from before decoding.
LEARN = 48


@dataclass(frozen=True)
class LtcFrame:
    """A decoded word: ``end`` [samples from the first fed] when its last bit ended (the
    next frame's start); the label; ``drop``: the drop-frame flag; ``bit_samples``: the
    bit period then [samples]."""

    end: float
    hours: int
    minutes: int
    seconds: int
    frames: int
    drop: bool
    bit_samples: float


def _bcd(bits: list[int], lo: int, n: int) -> int:
    return sum(bits[lo + k] << k for k in range(n))


def parse_word(bits: list[int]) -> tuple[int, int, int, int, bool] | None:
    """(h, m, s, f, drop) of bits 0-63, or None if a field is out of range."""
    f = _bcd(bits, 0, 4) + 10 * _bcd(bits, 8, 2)
    s = _bcd(bits, 16, 4) + 10 * _bcd(bits, 24, 3)
    m = _bcd(bits, 32, 4) + 10 * _bcd(bits, 40, 3)
    h = _bcd(bits, 48, 4) + 10 * _bcd(bits, 56, 2)
    units = (_bcd(bits, 0, 4), _bcd(bits, 16, 4), _bcd(bits, 32, 4), _bcd(bits, 48, 4))
    if max(units) > 9 or f > 29 or s > 59 or m > 59 or h > 23:
        return None
    return h, m, s, f, bool(bits[10])


class LtcDecoder:
    """Feed samples (any scale, mono) with ``feed``; it returns the words completed."""

    def __init__(self, sample_rate: float) -> None:
        self.rate = float(sample_rate)
        self._n = 0                       # samples fed so far
        self._mean = 0.0
        self._peak = 0.0
        self._level = 0                   # +1 / -1 once known
        self._last_val = 0.0              # the last sample beyond the threshold
        self._last_at = -1.0
        self._edge: float | None = None   # time of the last edge [samples]
        self._learn: list[float] = []
        self._period: float | None = None
        self._half: float | None = None
        self._bits: deque[int] = deque(maxlen=80)
        self._since_word = 0

    def feed(self, samples: npt.ArrayLike) -> list[LtcFrame]:
        x = np.asarray(samples, dtype=np.float64).ravel()
        out: list[LtcFrame] = []
        if not len(x):
            return out
        # DC: a slow running mean per chunk; peak: the chunk's, followed slowly
        self._mean = 0.99 * self._mean + 0.01 * float(x.mean()) if self._n else float(x.mean())
        x = x - self._mean
        self._peak = max(0.9 * self._peak, float(np.abs(x).max()))
        th = HYSTERESIS * self._peak
        beyond = np.flatnonzero(np.abs(x) > th)
        for i in beyond.tolist():
            v = float(x[i])
            level = 1 if v > 0 else -1
            at = float(self._n + i)
            if level != self._level and self._level != 0:
                a, va = self._last_at, self._last_val     # the last sample on the old side
                edge = a + va / (va - v) * (at - a) if va != v else at
                out += self._on_edge(edge)
            self._level, self._last_val, self._last_at = level, v, at
        self._n += len(x)
        return out

    def _on_edge(self, edge: float) -> list[LtcFrame]:
        last, self._edge = self._edge, edge
        if last is None:
            return []
        d = edge - last
        if self._period is None:           # learning: whole bits are the longest intervals
            if self._learn and d > 3.0 * float(np.median(self._learn)):
                self._learn = []            # a silence in between: learn again from here
                return []
            self._learn.append(d)
            if len(self._learn) >= LEARN:
                longest = float(np.percentile(self._learn, 90))
                full = [v for v in self._learn if 0.75 * longest < v < 1.5 * longest]
                self._period = float(np.median(full))
                self._learn = []
            return []
        t = self._period
        if d > 1.5 * t or d < 0.25 * t:       # a dropout, a glitch: start the word again
            self._half = None
            self._bits.clear()
            if d > 4 * t:                   # silence: the next signal may be another rate
                self._period, self._learn = None, []
            return []
        if d > 0.75 * t:
            self._half = None
            self._period = 0.95 * t + 0.05 * d
            return self._bit(0, edge)
        if self._half is None:
            self._half = d
            return []
        self._period = 0.95 * t + 0.05 * (self._half + d)
        self._half = None
        return self._bit(1, edge)

    def _bit(self, bit: int, edge: float) -> list[LtcFrame]:
        self._bits.append(bit)
        self._since_word += 1
        if len(self._bits) < 80 or tuple(list(self._bits)[64:]) != SYNC:
            return []
        if self._since_word < 80:
            return []
        bits = list(self._bits)
        word = parse_word(bits)
        self._since_word = 0
        if word is None:
            return []
        h, m, s, f, drop = word
        assert self._period is not None
        return [LtcFrame(edge, h, m, s, f, drop, self._period)]
