"""An LTC encoder for the tests, written from the SMPTE ST 12-1 bit layout alone (not the
decoder's inverse: the decoder finds edges and measures intervals; this computes a level
for each sample's instant from the half-bit it falls in, then rounds the edges with an
RC low-pass and adds hum, noise and an offset, as a cable does).

``labels``: one (h, m, s, f) per frame, or None for a frame of silence (a dropout);
consecutive labels need not follow each other (a jump).
"""

from __future__ import annotations

import wave
from pathlib import Path

import numpy as np

SYNC_WORD = 0b1011_1111_1111_1100     # bits 64..79 read as an integer, bit 64 lowest


def drop_frame_labels(first: int, count: int) -> list[tuple[int, int, int, int]]:
    """``count`` drop-frame labels from frame ``first``, by counting label by label (the
    rule: :00 and :01 skipped at each minute not a multiple of ten)."""
    h = m = s = f = 0
    out: list[tuple[int, int, int, int]] = []
    n = 0
    while len(out) < count:
        if n >= first:
            out.append((h, m, s, f))
        n += 1
        f += 1
        if f == 30:
            f, s = 0, s + 1
            if s == 60:
                s, m = 0, m + 1
                if m == 60:
                    m, h = 0, h + 1
                if m % 10:
                    f = 2
    return out


def plain_labels(first: int, count: int, fps: int) -> list[tuple[int, int, int, int]]:
    out = []
    for n in range(first, first + count):
        s, f = divmod(n, fps)
        out.append((s // 3600, (s // 60) % 60, s % 60, f))
    return out


def word(label: tuple[int, int, int, int], *, drop: bool) -> list[int]:
    """The 80 bits of one frame, bit 0 first."""
    h, m, s, f = label
    value = 0
    for start, number in ((0, f % 10), (8, f // 10), (16, s % 10), (24, s // 10),
                          (32, m % 10), (40, m // 10), (48, h % 10), (56, h // 10)):
        value |= number << start
    if drop:
        value |= 1 << 10
    value |= SYNC_WORD << 64
    return [(value >> k) & 1 for k in range(80)]


def encode(labels: list[tuple[int, int, int, int] | None], fps: float, *,
           sample_rate: int = 48_000, drop: bool = False, amplitude: float = 0.4,
           noise: float = 0.01, seed: int = 1) -> np.ndarray:
    """The audio [-1, 1] of the frames, back to back at ``fps``."""
    bits: list[int] = []
    silent: list[bool] = []
    for lab in labels:
        bits += word(lab, drop=drop) if lab is not None else [0] * 80
        silent += [lab is None] * 80
    half = 1.0 / (fps * 160.0)                         # one half bit [s]
    # flips at the start of every bit, and mid-bit for a 1
    flips = np.zeros(2 * len(bits), dtype=np.int64)
    flips[0::2] = 1
    flips[1::2] = np.array(bits)
    level = np.where(np.cumsum(flips) % 2 == 0, 1.0, -1.0)
    mute = np.repeat(np.array(silent), 2)
    n = int(len(bits) * 2 * half * sample_rate)
    t = np.arange(n) / sample_rate
    slot = np.minimum((t / half).astype(np.int64), len(level) - 1)
    x = np.where(mute[slot], 0.0, level[slot] * amplitude)
    rc = np.exp(-1.0 / (sample_rate * 25e-6))          # 25 us rise, as the standard asks
    y = np.empty_like(x)
    acc = 0.0
    for i, v in enumerate(x.tolist()):
        acc = rc * acc + (1 - rc) * v
        y[i] = acc
    rng = np.random.default_rng(seed)
    return y + 0.02 + 0.01 * np.sin(2 * np.pi * 50 * t) + noise * rng.standard_normal(n)


def write_wav(path: Path, audio: np.ndarray, sample_rate: int = 48_000) -> None:
    pcm = (np.clip(audio, -1, 1) * 32767).astype("<i2")
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(sample_rate)
        w.writeframes(pcm.tobytes())
