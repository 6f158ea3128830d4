"""A loop that misses its rate is a fault the panel shows, then a stop: never a silent
"walking".

Fed every tick with the loop's own clock and overrun count (robot.loop.telemetry), it
reports an alarm while, over the last ``window_s``, more than ``late_share`` of the tick
slots were missed, and asks for a safe stop once that has lasted ``late_stop_s``, or
``stop_after_s`` while more than ``stop_share`` were (the loop at under half its rate: the
gait and the balance feedback no longer run as tuned). One gap between ticks longer than
``stall_s`` is worse: the servos' own bus watchdog (armed with that timeout while
streaming) has tripped and they no longer take goals, so it asks for a stop at once.
The streamer's own watchdog still stops a loop that overruns ``overrun_streak`` ticks in
a row; this catches a loop that is late often but not in an unbroken streak (e.g.
starved by another thread: issue 19).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from robot.bus.base import Bus
from robot.loop.watchdog import FAILSAFE_MARGIN, WatchdogConfig


@dataclass(frozen=True)
class Verdict:
    """alarm: what is wrong (None: on time); stop: end the run now (a safe stop);
    at_once: the servos are no longer listening (torque off, no ramp)."""

    alarm: str | None = None
    stop: bool = False
    at_once: bool = False


ON_TIME = Verdict()


class RateGuard:
    """See the module docstring. rate_hz: the loop's rate [Hz]; window_s, stop_after_s,
    stall_s [s]; late_share in (0, 1)."""

    def __init__(self, rate_hz: float, *, window_s: float = 1.0, late_share: float = 0.1,
                 late_stop_s: float = 10.0, stop_share: float = 0.5,
                 stop_after_s: float = 2.0, stall_s: float = 0.1) -> None:
        self.dt = 1.0 / rate_hz
        self.window_s = window_s
        self.late_share, self.late_stop_s = late_share, late_stop_s
        self.stop_share, self.stop_after_s = stop_share, stop_after_s
        self.stall_s = stall_s
        self._seen: deque[tuple[float, int]] = deque()   # (t [s], overruns so far)
        self._last_t: float | None = None
        self._since: float | None = None       # alarm since [s]
        self._slow_since: float | None = None  # under stop_share since [s]
        self._last = ON_TIME
        self.alarms = 0

    def update(self, t: float, overruns: int) -> Verdict:
        """One tick at loop time ``t`` [s] with ``overruns`` missed slots so far (the same
        tick again: the verdict it had)."""
        if self._last_t is not None and t <= self._last_t:
            return self._last
        gap = None if self._last_t is None else t - self._last_t
        self._last_t = t
        if gap is not None and gap > self.stall_s:
            self.alarms += 1
            self._last = Verdict(f"the loop stalled {gap * 1e3:.0f} ms (the servos' bus "
                                 f"watchdog trips after {self.stall_s * 1e3:.0f} ms): "
                                 "stopped at once", stop=True, at_once=True)
            return self._last
        seen = self._seen
        seen.append((t, overruns))
        while seen and seen[0][0] < t - self.window_s:
            seen.popleft()
        alarm, share = None, 0.0
        span = t - seen[0][0]
        if span >= 0.5 * self.window_s:
            missed = overruns - seen[0][1]
            slots = span / self.dt
            share = missed / slots
            if share > self.late_share:
                hz = (slots - missed) / span
                alarm = (f"the loop is late: {missed} of {slots:.0f} ticks missed in the last "
                         f"{span:.1f} s ({hz:.0f} of {1 / self.dt:g} Hz)")
        self._last = self._verdict(t, alarm, share)
        return self._last

    def _verdict(self, t: float, alarm: str | None, share: float) -> Verdict:
        if alarm is None:
            self._since = self._slow_since = None
            return ON_TIME
        if self._since is None:
            self._since = t
            self.alarms += 1
        if share <= self.stop_share:
            self._slow_since = None
        elif self._slow_since is None:
            self._slow_since = t
        late_for = t - self._since
        slow_for = t - self._slow_since if self._slow_since is not None else 0.0
        if late_for >= self.late_stop_s or slow_for >= self.stop_after_s:
            return Verdict(f"{alarm}, for {late_for:.1f} s: safe stop", stop=True)
        return Verdict(alarm)


def stall_limit_s(bus: Bus, rate_hz: float) -> float:
    """The longest gap between ticks the servos' own bus watchdog survives [s]: what the
    streamer arms it with (robot.loop.ending.arm_failsafe)."""
    failsafe = WatchdogConfig().failsafe_s or 0.0
    return max(failsafe, FAILSAFE_MARGIN * bus.retry_span_s + 2.0 / rate_hz)
