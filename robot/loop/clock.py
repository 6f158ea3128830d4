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
