"""Clocks for the fixed-rate loop: absolute deadlines, never relative sleeps.

A clock has ``now()`` [s] and ``sleep_until(deadline)``. The wall clock uses
``time.monotonic``; the MuJoCo bus provides a clock whose ``sleep_until`` advances the
physics to the deadline, so the same loop runs faster than real time in simulation.
"""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    def now(self) -> float:
        """Current time [s] on this clock."""
        ...

    def sleep_until(self, deadline: float) -> None:
        """Return once ``now() >= deadline`` (immediately if it already is)."""
        ...


class MonotonicClock:
    """Wall clock on ``time.monotonic``; sleeps coarse then spins the last ``spin_s``."""

    def __init__(self, *, spin_s: float = 0.0005) -> None:
        self.spin_s = spin_s

    def now(self) -> float:
        return time.monotonic()

    def sleep_until(self, deadline: float) -> None:
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return
            if remaining > self.spin_s:
                time.sleep(remaining - self.spin_s)


class Pacer:
    """Absolute deadlines ``dt`` [s] apart on ``clock``: ``wait`` sleeps until the next one;
    a deadline missed by whole slots is counted and skipped (realigned), never a burst of
    ticks to catch up."""

    def __init__(self, clock: Clock, dt: float) -> None:
        self.clock = clock
        self.dt = dt
        self.next = 0.0

    def start(self) -> None:
        """The first deadline is one ``dt`` from now."""
        self.next = self.clock.now()

    def wait(self) -> tuple[float, float, int]:
        """Sleep until the next deadline; (now [s], lateness [s], whole slots missed)."""
        self.next += self.dt
        self.clock.sleep_until(self.next)
        now = self.clock.now()
        late = now - self.next
        missed = int(late // self.dt) if late > self.dt else 0
        self.next += missed * self.dt
        return now, late, missed
