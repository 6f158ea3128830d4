"""SMPTE timecode as numbers: the frame rates a show runs at, a timecode's frame count and
its time, drop-frame counting.

Rates (SMPTE ST 12-1): 24, 25 and 30 frames a second count every frame; 29.97 drop-frame
runs at 30000/1001 frames a second and labels them as 30 fps does, skipping the labels
:00 and :01 at the start of every minute except every tenth minute (so 00:01:00;02 is
frame 1800 and 00:10:00;00 is frame 17982), which keeps the label within 2.6 frames of
the wall clock over a day. A timecode is written HH:MM:SS:FF (drop-frame: HH:MM:SS;FF,
either separator is read).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from robot.errors import ConfigError


@dataclass(frozen=True)
class Rate:
    """name: as on the command line; base: frames a labelled second (24, 25, 30); fps:
    frames a second of time; drop: drop-frame labels."""

    name: str
    base: int
    fps: float
    drop: bool = False

    @property
    def frame_s(self) -> float:
        """One frame [s]."""
        return 1.0 / self.fps


RATES = {r.name: r for r in (Rate("24", 24, 24.0), Rate("25", 25, 25.0),
                             Rate("29.97df", 30, 30000 / 1001, drop=True),
                             Rate("30", 30, 30.0))}
_TC = re.compile(r"^(\d{1,2}):(\d{2}):(\d{2})[:;.](\d{2})$")


def rate_named(name: str, *, where: str = "--chase-fps") -> Rate:
    rate = RATES.get(name.lower().removesuffix("fps"))
    if rate is None:
        raise ConfigError(f"{where} {name}: unknown frame rate; valid: {', '.join(RATES)}")
    return rate


def frame_number(h: int, m: int, s: int, f: int, rate: Rate) -> int:
    """Frames since 00:00:00:00 of the label h:m:s:f (drop-frame: the labels skipped are
    not counted)."""
    n = ((h * 60 + m) * 60 + s) * rate.base + f
    if rate.drop:
        minutes = h * 60 + m
        n -= 2 * (minutes - minutes // 10)
    return n


def label(n: int, rate: Rate) -> tuple[int, int, int, int]:
    """(h, m, s, f): the label of frame ``n`` (the inverse of ``frame_number``)."""
    if rate.drop:             # put the skipped labels back: 17982 frames a ten minutes
        tens, rest = divmod(n, 17982)
        n += 18 * tens + (2 * ((rest - 2) // 1798) if rest > 1 else 0)
    f = n % rate.base
    s = n // rate.base
    return (s // 3600) % 24, (s // 60) % 60, s % 60, f


def parse_timecode(text: str, rate: Rate, *, where: str = "--chase-start") -> int:
    """The frame number of ``text`` (HH:MM:SS:FF); ConfigError naming ``where``."""
    m = _TC.match(text.strip())
    if m is None:
        raise ConfigError(f"{where} {text!r}: expected HH:MM:SS:FF (e.g. 01:00:00:00)")
    h, mi, s, f = (int(g) for g in m.groups())
    if h > 23 or mi > 59 or s > 59 or f >= rate.base:
        raise ConfigError(f"{where} {text}: out of range at {rate.name} fps (hours 0-23, "
                          f"minutes and seconds 0-59, frames 0-{rate.base - 1})")
    if rate.drop and f < 2 and s == 0 and mi % 10:
        raise ConfigError(f"{where} {text}: no such drop-frame label (:00 and :01 are "
                          "skipped at the start of each minute but every tenth)")
    return frame_number(h, mi, s, f, rate)


def text(n: int, rate: Rate) -> str:
    h, m, s, f = label(n, rate)
    return f"{h:02d}:{m:02d}:{s:02d}{';' if rate.drop else ':'}{f:02d}"
