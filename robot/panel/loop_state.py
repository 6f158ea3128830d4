"""The loop's own report, asked once however many callers want it; a stuck loop is told
at once.

A frozen loop process (stopped, swapped out, stuck in a driver call) answers nothing.
Asking it afresh for every caller cost each caller the whole timeout, and the live view's
one frame reads the state several times (the state, the parameters in effect, the driver,
the studio): one frame then took several timeouts, and the page went on showing the last
"walking" long after the loop had stopped answering. Here at most one "state" request is
in flight. While it is unanswered, every caller gets the fault at once, saying for how
long the loop has been silent; once the late answer has come, the next caller asks again.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

from robot.errors import BipedError
from robot.panel.loop_process import LoopProcess, LoopUnavailable, Pending


class LoopStateReader:
    """``read(loop, max_age)``: the loop's last report at most ``max_age`` old [s], or,
    when the loop does not answer within ``timeout_s`` [s], that report with ``running``
    false, a ``fault`` line and the state "fault". Thread-safe."""

    def __init__(self, timeout_s: float) -> None:
        self.timeout_s = timeout_s
        self._state: dict[str, Any] = {"running": False, "tel": {"state": "idle"}, "runs": 0}
        self._at = -math.inf                  # when ``_state`` was answered [s, monotonic]
        self._asked: Pending | None = None    # the request still unanswered, if any
        self._asked_at = -math.inf
        self._lock = threading.Lock()

    def expire(self) -> None:
        """The next read asks the loop (something was just sent that changes its state)."""
        with self._lock:
            self._at = -math.inf

    def read(self, loop: LoopProcess, max_age: float) -> dict[str, Any]:
        with self._lock:
            now = time.monotonic()
            if now - self._at <= max_age:
                return self._state
            if self._asked is None or self._asked.answered:
                self._asked, self._asked_at = loop.send("state"), now  # a late answer: stale
                wait = self.timeout_s
            else:
                wait = 0.0                    # still silent: no caller waits again
            try:
                state = self._asked.wait(wait)
            except LoopUnavailable:
                silent = time.monotonic() - self._asked_at
                return self._fault(f"the control loop did not answer for {silent:.1f} s")
            except BipedError as e:           # gone
                self._asked = None
                return self._fault(str(e))
            self._asked = None
            self._state, self._at = state, time.monotonic()
            return state

    def _fault(self, why: str) -> dict[str, Any]:
        return {**self._state, "running": False, "fault": why,
                "tel": {**self._state.get("tel", {}), "state": "fault"}}
