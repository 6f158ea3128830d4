"""Waiting in tests: for a condition (a poll with a deadline) or for a moment on the
monotonic clock, never for a fixed time that stands in for either.

``time.monotonic()`` is system-wide on Linux, so a moment taken from the emulator's log
(``Packet.t``) can be waited for here.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from robot.loop.clock import MonotonicClock

#: Deadline for a condition that takes well under a second on an idle machine [s]:
#: generous, because a loaded 2-core machine stalls processes for seconds.
PATIENCE_S = 20.0


def wait_for(pred: Callable[[], bool], *, timeout_s: float = PATIENCE_S, every_s: float = 0.02,
             stop: Callable[[], bool] | None = None) -> bool:
    """Poll ``pred`` every ``every_s`` [s] until it holds (True) or ``timeout_s`` [s] have
    passed or ``stop()`` holds (False; ``pred`` is asked once more first)."""
    end = time.monotonic() + timeout_s
    while True:
        if pred():
            return True
        if time.monotonic() >= end or (stop is not None and stop()):
            return bool(pred())
        sleep_until(min(end, time.monotonic() + every_s))


def sleep_until(t: float) -> None:
    """Return once the monotonic clock reads at least ``t`` [s] (the loop's own clock)."""
    MonotonicClock().sleep_until(t)
