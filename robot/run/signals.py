"""SIGINT/SIGTERM for commands that stream: first → safe stop, second → emergency stop.

Exit codes (README, docs/hardware.md): 0 completed, 1 safety stop (a fault), 2 usage or
config error, 128 + signal number when a signal stopped the run (130 SIGINT, 143 SIGTERM).
"""

from __future__ import annotations

import logging
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, Protocol

from robot.loop.telemetry import LoopStats

SIGNALS = (signal.SIGINT, signal.SIGTERM)

log = logging.getLogger(__name__)


class Stoppable(Protocol):
    def request_stop(self, reason: str = ...) -> None: ...

    def emergency_stop(self, reason: str = ...) -> None: ...


class SignalLatch:
    """Remembers the first stopping signal; routes signals to a ``Stoppable``."""

    def __init__(self) -> None:
        self.first: int | None = None
        self.count = 0

    def handle(self, target: Stoppable, signum: int) -> None:
        name = signal.Signals(signum).name
        self.count += 1
        if self.first is None:
            self.first = signum
            # Said once handled: a second signal sent before this line is one the kernel
            # may merge with the first (same number), so senders wait for it.
            log.warning("signal %s: stopping (a second signal stops at once)", name)
            target.request_stop(f"signal {name}")
        else:
            target.emergency_stop(f"emergency stop (second signal, {name})")

    def exit_code(self, stats: LoopStats | None) -> int:
        """1 for a fault, 128 + the first signal's number, else 0."""
        if stats is not None and stats.fault:
            return 1
        return 128 + self.first if self.first is not None else 0


@contextmanager
def stop_on_signals(target: Stoppable, latch: SignalLatch) -> Iterator[SignalLatch]:
    """Route SIGINT/SIGTERM to ``target`` inside the block; restore the old handlers."""
    def handler(signum: int, _frame: Any) -> None:
        latch.handle(target, signum)

    old = {s: signal.signal(s, handler) for s in SIGNALS}
    try:
        yield latch
    finally:
        for s, h in old.items():
            signal.signal(s, h)
