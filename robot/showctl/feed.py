"""Where show-control input meets the robot, at the loop's rate.

Any number of senders (OSC, MIDI) ``put`` actions as they arrive; a flood never reaches
the control loop as a flood. Parameter changes are merged (the last value of each wins)
and handed to the target at most once per control tick; other commands wait in a short
queue (a repeat of the one before it is the same command, except GO: each fires the next
cue) and go one per tick, in the
order they came, after the parameter changes that came before them. The e-stop never
waits in that queue: ``estop`` wakes a thread of its own, which asks the target at once
(an e-stop asked while one is being handled is the same e-stop).

Every action carries its arrival time (``received`` [s, time.monotonic]): the target
decides the order against an e-stop by it, as the panel does for its HTTP requests.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

from robot.showctl.actions import Command, Named, SetParam
from robot.showctl.once import OnceLog

log = logging.getLogger(__name__)

GO = Command("go")   # each GO fires the next cue: never merged with the one before
#: Commands waiting at most (a flood of commands beyond it is dropped and counted).
QUEUE = 64


class Target(Protocol):
    """What the feed drives (the panel's routes, a play's run)."""

    def params(self, changes: Mapping[str, float], received: float) -> None: ...

    def act(self, action: Command | Named, received: float) -> None: ...

    def estop(self, received: float) -> None: ...


@dataclass
class FeedStats:
    """Counts since the feed started: actions put, parameter updates and commands handed
    to the target, e-stops handled, commands dropped (queue full)."""

    put: int = 0
    param_updates: int = 0
    commands: int = 0
    estops: int = 0
    dropped: int = 0

    def as_dict(self) -> dict[str, int]:
        return dataclasses.asdict(self)


class Feed:
    """See the module docstring. ``rate_hz``: the control loop's rate [Hz]; ``once``: where
    problems are logged once per kind (shared with the senders). No thread before
    ``start``."""

    def __init__(self, target: Target, *, rate_hz: float, once: OnceLog | None = None) -> None:
        self.target = target
        self.period = 1.0 / rate_hz
        self.once = once or OnceLog(log)
        self.stats = FeedStats()
        self._cond = threading.Condition()
        self._params: dict[str, float] = {}
        self._params_at = 0.0
        self._queue: deque[tuple[Command | Named, float, dict[str, float]]] = deque()
        self._estop_at: float | None = None
        self._estop_cond = threading.Condition()
        self._closed = False
        self._threads = [threading.Thread(target=self._work, name="showctl-feed", daemon=True),
                         threading.Thread(target=self._estops, name="showctl-estop",
                                          daemon=True)]

    def report(self) -> dict[str, object]:
        """The counts (FeedStats) and the problems ignored, by kind."""
        return {**self.stats.as_dict(), "ignored": self.once.summary()}

    def start(self) -> None:
        for t in self._threads:
            t.start()

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        with self._estop_cond:
            self._estop_cond.notify_all()
        for t in self._threads:
            if t.is_alive():
                t.join(5.0)

    # -- senders -------------------------------------------------------------------------
    def estop(self, received: float) -> None:
        """The e-stop: handled on its own thread now, never behind the queue."""
        with self._estop_cond:
            self._estop_at = received if self._estop_at is None else max(self._estop_at,
                                                                        received)
            self._estop_cond.notify()

    def put(self, action: SetParam | Command | Named, received: float) -> None:
        if isinstance(action, Command) and action.what == "estop":
            self.estop(received)
            return
        with self._cond:
            self.stats.put += 1
            if isinstance(action, SetParam):
                self._params[action.name] = action.value
                self._params_at = received
            elif (self._queue and self._queue[-1][0] == action and not self._params
                  and action != GO):
                pass                               # the same command again: one command
            elif len(self._queue) >= QUEUE:
                self.stats.dropped += 1
                self.once.note("queue", f"show control: more than {QUEUE} commands waiting; "
                               "dropping the newest")
                return
            else:
                self._queue.append((action, received, self._params))
                self._params = {}                  # those go first, with this command
            self._cond.notify()

    # -- the threads ---------------------------------------------------------------------
    def _estops(self) -> None:
        while True:
            with self._estop_cond:
                while self._estop_at is None and not self._closed:
                    self._estop_cond.wait()
                if self._closed:
                    return
                received, self._estop_at = self._estop_at, None
            assert received is not None
            self.stats.estops += 1
            try:
                self.target.estop(received)
            except Exception as e:
                log.error("show control: the e-stop failed: %s: %s", type(e).__name__, e)

    def _work(self) -> None:
        next_at = time.monotonic()
        while True:
            with self._cond:
                while not (self._params or self._queue) and not self._closed:
                    self._cond.wait()
                if self._closed:
                    return
                wait = next_at - time.monotonic()
                if wait > 0:                       # at most one step per control tick
                    self._cond.wait(wait)
                    continue
                if self._queue:
                    action, received, before = self._queue.popleft()
                    params, params_at = before, received
                else:
                    action, params, params_at = None, self._params, self._params_at
                    self._params = {}
            next_at = max(next_at + self.period, time.monotonic())
            self._step(params, params_at, action, received if action is not None else 0.0)

    def _step(self, params: dict[str, float], params_at: float,
              action: Command | Named | None, received: float) -> None:
        if params:
            self.stats.param_updates += 1
            self._call(lambda: self.target.params(params, params_at))
        if action is not None:
            self.stats.commands += 1
            self._call(lambda: self.target.act(action, received))

    def _call(self, job: Callable[[], None]) -> None:
        try:
            job()
        except Exception as e:                     # a bug in a target: keep serving
            log.error("show control: %s: %s", type(e).__name__, e)
