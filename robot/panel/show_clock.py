"""A show take's clock as the panel's loop process reports it: the show's time at each tick
that plays it, stamped with the wall clock of that tick (so the page that plays the
audio compares the two at one instant, however late the report reaches it), the rate at
which show time runs against the wall clock (below 1 when the loop falls behind), how far
the show is and which cue comes next.

Written by the loop thread every tick (two floats and a deque append), read by the
command thread; the caller (robot.panel.loop_watch) holds the lock.
"""

from __future__ import annotations

import bisect
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from robot.panel.runs import ShowTake

#: Wall time [s] over which the show's rate is measured.
RATE_WINDOW_S = 1.0


class ShowClock:
    """The clock of one show run: ``show`` (what plays), ``show_time()`` the engine's time
    [s] (0 at the first tick after the ramp in)."""

    def __init__(self, show: ShowTake, show_time: Callable[[], float], *,
                 wall: Callable[[], float] = time.time) -> None:
        self.show = show
        self._show_time = show_time
        self._wall = wall
        self._cue_times = [c.t for c in show.cues]
        self._marks: deque[tuple[float, float]] = deque()
        self.playing = False

    def tick(self, state: str) -> None:
        """A tick of the run in loop state ``state`` ("walking": the show plays)."""
        self.playing = state == "walking"
        if not self.playing:
            return
        at, t = self._wall(), self._show_time()
        marks = self._marks
        marks.append((at, t))
        while marks[0][0] < at - RATE_WINDOW_S:
            marks.popleft()

    def rate(self) -> float:
        """Show seconds per wall second over the last ``RATE_WINDOW_S`` (1 until known)."""
        m = self._marks
        if len(m) < 2 or m[-1][0] - m[0][0] < 0.1 * RATE_WINDOW_S:
            return 1.0
        return (m[-1][1] - m[0][1]) / (m[-1][0] - m[0][0])

    def progress(self) -> dict[str, Any]:
        """take, t [s] at wall time at [s] (None before it plays), rate, duration [s],
        next_cue ({t, name} or None), playing."""
        at, t = self._marks[-1] if self._marks else (None, 0.0)
        k = bisect.bisect_right(self._cue_times, t)
        cue = self.show.cues[k] if k < len(self.show.cues) else None
        return {"take": self.show.take, "t": t, "at": at, "rate": self.rate(),
                "duration": self.show.sequence.duration, "playing": self.playing,
                "next_cue": {"t": cue.t, "name": cue.name} if cue else None}
