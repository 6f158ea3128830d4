"""The read-back pose the panel shows while no run is active: read on request, rate-limited.

Only reads (``Bus.read_state``), never writes, so it changes nothing on the robot: a limp
robot moved by hand shows on the stick figure; one holding after a run shows where it
holds. Reads happen only when a client asks for the state, at most ``rate_hz`` times a
second however many clients poll; in between the last read is served again.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterable
from typing import Protocol

from robot.bus.base import ServoState
from robot.bus.servo_map import ServoMap
from robot.errors import BipedError

log = logging.getLogger(__name__)

#: Idle read-back rate [Hz]: enough for a figure that follows a hand, light on the bus.
IDLE_RATE_HZ = 5.0


class StateReader(Protocol):
    """What the idle pose reads through (a bus, or the bus lease outside any session)."""

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]: ...


class IdlePose:
    """``poll()`` → ``(q_present [rad] in joint order, {servo_id: ServoState})`` or None
    (the last read failed). Not thread-safe: the caller holds its own lock."""

    def __init__(self, bus: StateReader, servo_map: ServoMap, *, rate_hz: float = IDLE_RATE_HZ,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.bus = bus
        self.map = servo_map
        self.period_s = 1.0 / rate_hz
        self.clock = clock
        self.reads = 0
        self._at: float | None = None
        self._last: tuple[list[float], dict[int, ServoState]] | None = None
        self._failed: str | None = None

    def forget(self) -> None:
        """Drop the cached pose (a run started: its telemetry takes over)."""
        self._at, self._last = None, None

    def poll(self) -> tuple[list[float], dict[int, ServoState]] | None:
        now = self.clock()
        if self._at is not None and now - self._at < self.period_s:
            return self._last
        self._at = now
        self.reads += 1
        try:
            states = self.bus.read_state(self.map.ids)
        except BipedError as e:
            if str(e) != self._failed:  # once per distinct failure, not 5 times a second
                log.warning("idle read-back failed: %s", e)
            self._failed, self._last = str(e), None
            return None
        self._failed = None
        q = self.map.from_positions({sid: s.position for sid, s in states.items()})
        self._last = (q.tolist(), states)
        return self._last
