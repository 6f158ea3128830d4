"""SIGINT/SIGTERM for the command line: one latch per command, installed by ``robot.cli``
before anything else runs and kept until the process exits, so no command is ever killed
by a stopping signal.

What a signal does depends on where the command is (the latch's innermost region):

- routed (``stop_on_signals(target)``: a loop is streaming): the first signal asks the
  target to stop (``request_stop``: ramp out, rest), every later one is an emergency stop
  (``emergency_stop``: torque off at once). Never raises.
- shielded (``shield()``: closing the bus, a multi-write EEPROM step): only recorded; when
  the region ends, a signal that arrived in it takes effect there (an exception after the
  cleanup, never inside it).
- anywhere else: the first signal raises ``Interrupted`` (a ``KeyboardInterrupt``) where
  unwinding is safe (a prompt, a computation, opening a port), so the command's
  ``finally`` blocks run; later signals are only recorded (cleanup is never interrupted).

``latch.emergency``: two or more signals (a second Ctrl-C: torque off). Exit codes
(README, docs/hardware.md): 0 completed, 1 safety stop (a fault), 2 usage or config
error, 128 + the first signal's number when a signal stopped the command (130 SIGINT,
143 SIGTERM).
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from types import FrameType
from typing import NoReturn, Protocol

from robot.loop.telemetry import LoopStats

SIGNALS = (signal.SIGINT, signal.SIGTERM)

log = logging.getLogger(__name__)


class Stoppable(Protocol):
    def request_stop(self, reason: str = ...) -> None: ...

    def emergency_stop(self, reason: str = ...) -> None: ...


class Interrupted(KeyboardInterrupt):
    """A stopping signal unwinding a command; ``signum``: which (SIGINT or SIGTERM)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


class SignalLatch:
    """Remembers the stopping signals of one command and acts on them by region."""

    def __init__(self) -> None:
        self.first: int | None = None
        self.last: int | None = None
        self.count = 0
        self._routes: list[tuple[Stoppable, SignalLatch | None]] = []
        self._shields = 0
        self._raised = False
        self._pending = False        # arrived while shielded, not acted on yet
        self._ended: int | None = None
        self._at_end: list[Callable[[], str | None]] = []

    @property
    def emergency(self) -> bool:
        """Two or more signals: the operator wants torque off now."""
        return self.count >= 2

    # -- the handler (main thread, between two bytecodes of whatever runs) --------------
    def handle(self, signum: int, _frame: FrameType | None = None) -> None:
        if self._ended is not None:             # the command is over: leave now, same code
            os._exit(self._ended)
        self.record(signum)
        if self._routes:
            target, mirror = self._routes[-1]
            if mirror is not None:
                mirror.record(signum, quiet=True)
            self._route(target, signum)
        elif self._shields:
            self._pending = True
        else:
            self._interrupt()

    def record(self, signum: int, *, quiet: bool = False) -> None:
        """Count ``signum`` (``quiet``: without saying so: another latch did)."""
        name = signal.Signals(signum).name
        self.count += 1
        self.last = signum
        if quiet:
            self.first = self.first or signum
        elif self.first is None:
            self.first = signum
            # Said once handled: a second signal sent before this line is one the kernel
            # may merge with the first (same number), so senders wait for it.
            log.warning("signal %s: stopping (a second signal stops at once)", name)
        else:
            log.warning("signal %s again: emergency stop, torque off", name)

    def _route(self, target: Stoppable, signum: int) -> None:
        name = signal.Signals(signum).name
        if self.count == 1:
            target.request_stop(f"signal {name}")
        else:
            target.emergency_stop(f"emergency stop (second signal, {name})")

    def _interrupt(self) -> None:
        """Raise once, for the first signal; later ones only count."""
        if self.first is not None and not self._raised:
            self._raised = True
            self._pending = False
            raise Interrupted(self.first)

    # -- regions ---------------------------------------------------------------------------
    @contextmanager
    def routed(self, target: Stoppable, *, mirror: SignalLatch | None = None
               ) -> Iterator[None]:
        """Signals go to ``target`` inside the block (and are counted in ``mirror`` too).
        A signal that came before the block (shielded) stops it before it starts."""
        if self._pending:
            self._interrupt()
        self._routes.append((target, mirror))
        try:
            yield
        finally:
            self._routes.pop()

    @contextmanager
    def shielded(self) -> Iterator[None]:
        """Signals only count inside the block; one that came takes effect at its end."""
        self._shields += 1
        try:
            yield
        finally:
            self._shields -= 1
        if self._pending and not self._shields and not self._routes:
            self._interrupt()

    def if_emergency_at_end(self, fn: Callable[[], str | None]) -> None:
        """Call ``fn`` when the command ends (``end``) if two or more signals have come by
        then: a run that closed holding, with its bus, before the second signal arrived
        (the command was still printing) turns torque off after all. ``fn`` returns a
        line for the command's output, or None; it is called with the signals blocked."""
        self._at_end.append(fn)

    def exit_code(self, stats: LoopStats | None) -> int:
        """1 for a fault, 128 + the first signal's number, else 0."""
        if stats is not None and stats.fault:
            return 1
        return 128 + self.first if self.first is not None else 0

    # -- installing ------------------------------------------------------------------------
    def install(self) -> Callable[[], None]:
        """Handle SIGINT/SIGTERM (main thread); returns what restores the old handlers."""
        old = {s: signal.signal(s, self.handle) for s in SIGNALS}

        def restore() -> None:
            for s, h in old.items():
                signal.signal(s, h)
        return restore

    def settle(self) -> list[str]:
        """Block the stopping signals in this thread (for good: the process is ending),
        count any that came meanwhile, and if two or more have come run what
        ``if_emergency_at_end`` registered; the lines they return. A signal delivered
        through another thread meanwhile is only counted (shielded for good)."""
        self._shields += 1
        signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
        for signum in sorted(signal.sigpending() & set(SIGNALS)):
            self.record(signum)
        lines: list[str] = []
        if self.emergency:
            for fn in self._at_end:
                try:
                    line = fn()
                except Exception:   # noqa: BLE001 - the exit goes on; the log says what
                    log.exception("after a second signal, at the end")
                    continue
                if line:
                    lines.append(line)
        return lines

    def end(self, code: int) -> NoReturn:
        """The command is over and this process ends with ``code``, now: stdout and stderr
        are flushed and the process exits without the interpreter's shutdown, during
        which the handlers are gone (a signal there would kill it: exit -15, not 143).
        Every ``finally`` of the command has run. First ``settle``: a second signal that
        came at any time before now still turns torque off (``if_emergency_at_end``);
        from then on the stopping signals are blocked and go with the process (or, seen
        through another thread, exit at once with the same code)."""
        lines = self.settle()
        self._ended = code
        for line in lines:
            sys.stdout.write(line + "\n")
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)


def installed() -> SignalLatch | None:
    """The latch handling SIGINT now (the command's), or None (no command: in-process use)."""
    owner = getattr(signal.getsignal(signal.SIGINT), "__self__", None)
    return owner if isinstance(owner, SignalLatch) and owner._ended is None else None


@contextmanager
def stop_on_signals(target: Stoppable, latch: SignalLatch | None = None
                    ) -> Iterator[SignalLatch]:
    """Route SIGINT/SIGTERM to ``target`` inside the block. Under a command (``installed``)
    its latch routes them (and counts them in ``latch`` too); otherwise ``latch`` (or a
    new one) handles them for the block and the old handlers come back after it."""
    outer = installed()
    if outer is not None:
        with outer.routed(target, mirror=None if latch is outer else latch):
            yield latch or outer
        return
    own = latch or SignalLatch()
    restore = own.install()
    try:
        with own.routed(target):
            yield own
    finally:
        restore()


@contextmanager
def shield() -> Iterator[None]:
    """The command's latch's ``shielded`` region (nothing when there is no command, or
    in another thread: signals run in the main thread and never interrupt another)."""
    latch = installed()
    if latch is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    with latch.shielded():
        yield
