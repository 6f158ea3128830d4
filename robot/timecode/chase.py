"""Chasing an external timecode: the show time the robot plays, from timecode readings
(robot/timecode/ltc.py, mtc.py: when each arrived, where the timecode was).

Show time 0 is the start timecode (``--chase-start``). Between readings the show time runs
on the loop's clock; each reading pulls it halfway to where the reading says (a phase
lock: arrival jitter is halved, a steady error shrinks to nothing within a few frames).
A reading more than ``jump_frames`` away (2 for a file, 8 for a live source) is a jump
(the operator relocated the cue): the show time is set to it at once, and the show ramps
there (robot/timecode/chased.py). No reading for longer than ``gap_frames`` (the source's usual spacing and a
half) is a dropout: the clock freewheels on; one for longer than ``freewheel`` frames is
lost: the show stops the way Stop does.

``max_error_frames``: the largest distance of a reading from the show time it met (a jump
not counted), in frames; what a steady lock is judged by.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robot.timecode.frames import Rate, frame_number

#: A reading this many frames from the show time is a jump, not jitter: a file's timecode
#: (exact), a live source's (a loaded host hears a MIDI message or an audio buffer tens of
#: ms late; a relocation by an operator is seconds).
JUMP_FRAMES, LIVE_JUMP_FRAMES = 2.0, 8.0
#: Share of a reading's error taken at once.
GAIN = 0.5


@dataclass
class ChaseStats:
    """What the chase saw: the rate (None before the first reading), the largest lock
    error [frames], dropouts and jumps counted, each jump's (show time from, to) [s]."""

    rate: Rate | None = None
    max_error_frames: float = 0.0
    errors: list[float] = field(default_factory=list)
    dropouts: int = 0
    jumps: int = 0
    jumped: list[tuple[float, float]] = field(default_factory=list)
    readings: int = 0

    def error_frames(self, percent: float) -> float:
        """A percentile of the readings' lock errors [frames] (0 before any)."""
        return float(np.percentile(self.errors, percent)) if self.errors else 0.0


class ChaseClock:
    """``start_label``: (h, m, s, f) of show time 0, placed on the timecode's rate when it
    is known; ``freewheel``: frames without timecode before it is lost; ``gap_frames``:
    the source's reading spacing before a silence counts as a dropout [frames]."""

    def __init__(self, start_label: tuple[int, int, int, int], *, freewheel: int,
                 gap_frames: float = 1.5, jump_frames: float = JUMP_FRAMES) -> None:
        self.start_label = start_label
        self.jump_frames = jump_frames
        self.freewheel = freewheel
        self.gap_frames = gap_frames
        self.stats = ChaseStats()
        self._start_frame: int | None = None
        self._ref_t = 0.0          # loop time [s] of the reference
        self._ref_show: float | None = None   # show time [s] then
        self._last_at: float | None = None
        self._in_dropout = False

    def reading(self, at: float, frame: float, rate: Rate) -> None:
        """A reading: at loop time ``at`` [s] the timecode stood at ``frame`` [frames]."""
        st = self.stats
        if st.rate is None or st.rate != rate or self._start_frame is None:
            st.rate = rate
            h, m, s, f = self.start_label
            self._start_frame = frame_number(h, m, s, min(f, rate.base - 1), rate)
        value = (frame - self._start_frame) / rate.fps
        st.readings += 1
        if self._in_dropout:
            self._in_dropout = False
        self._last_at = at
        if self._ref_show is None:
            self._ref_t, self._ref_show = at, value
            return
        predicted = self._ref_show + (at - self._ref_t)
        error = value - predicted
        if abs(error) * rate.fps > self.jump_frames:
            st.jumps += 1
            st.jumped.append((predicted, value))
            self._ref_t, self._ref_show = at, value
            return
        st.max_error_frames = max(st.max_error_frames, abs(error) * rate.fps)
        st.errors.append(abs(error) * rate.fps)
        self._ref_t, self._ref_show = at, predicted + GAIN * error

    def show_time(self, now: float) -> float | None:
        """The show time [s] at loop time ``now``; None before the first reading."""
        if self._ref_show is None:
            return None
        return self._ref_show + (now - self._ref_t)

    def check(self, now: float) -> bool:
        """Count a dropout as it begins; True while the timecode is not lost."""
        rate = self.stats.rate
        if self._last_at is None or rate is None:
            return True
        silent = (now - self._last_at) * rate.fps
        if silent > self.gap_frames and not self._in_dropout:
            self._in_dropout = True
            self.stats.dropouts += 1
        return silent <= self.freewheel

    @property
    def jumps(self) -> int:
        return self.stats.jumps
