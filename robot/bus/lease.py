"""One owner of a bus at a time, and an emergency-stop latch at the bus edge.

Whatever moves servos (a walk, a take, a pose move, a limb release, a keyframe capture)
holds a :class:`Session` from ``BusLease.acquire(owner)``: a ``Bus`` whose every wire
transaction runs under the lease's one lock. A second ``acquire`` while a session is held
raises :class:`BusBusy` naming the holder (the check and the taking are one step under a
lock: no window between them).

``BusLease.emergency_stop()`` is the latch. Under the same lock every write holds, it ends
the current generation; from then on a goal or a torque-on from any session acquired
before it raises :class:`Preempted` instead of reaching the wire (so a loop that is
mid-tick, or a request that was already on its way, cannot move anything after the e-stop
has answered), and torque goes off on every servo. Only a session acquired afterwards (a
new start) writes again. Reads, torque off and the servos' own watchdog registers always
pass: they never move anything.

``torque`` records, per servo id, the torque state last written successfully through the
lease (what the wire was told, for the panel's state and its exit message).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from types import TracebackType
from typing import Any

from robot.bus.base import Bus, ServoInfo, ServoState
from robot.errors import BipedError, BusError, SafetyStop

log = logging.getLogger(__name__)


class BusBusy(BipedError):
    """Another owner holds the bus; ``owner`` names it."""

    def __init__(self, owner: str) -> None:
        super().__init__(f"{owner} is running; stop it first")
        self.owner = owner


class Preempted(SafetyStop):
    """A write refused at the bus edge: an emergency stop (or a new owner) came after the
    session that tried it was acquired."""


class BusLease:
    """The one way to the wire for ``bus`` (already built; opened by its first session or
    ``open()``). ``ids``: every servo the e-stop turns off."""

    def __init__(self, bus: Bus, ids: Sequence[int]) -> None:
        self.bus = bus
        self.ids = tuple(ids)
        self.io = threading.RLock()          # held by every wire transaction
        self._claim = threading.Lock()       # acquire / end
        self._session: Session | None = None
        self._generation = 0
        self.estop_reason: str | None = None
        self.torque: dict[int, bool] = {}

    @property
    def owner(self) -> str | None:
        s = self._session
        return s.owner if s is not None else None

    @property
    def generation(self) -> int:
        return self._generation

    def acquire(self, owner: str) -> Session:
        """A session for ``owner``; BusBusy naming the holder if one is held."""
        with self._claim:
            if self._session is not None:
                raise BusBusy(self._session.owner)
            self._session = Session(self, owner, self._generation)
            return self._session

    def _end(self, session: Session) -> None:
        with self._claim:
            if self._session is session:
                self._session = None

    def open(self) -> None:
        with self.io:
            self.bus.open()

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        """A read outside any session (it moves nothing)."""
        with self.io:
            return self.bus.read_state(ids)

    def emergency_stop(self, reason: str = "emergency stop", *,
                       confirm: bool = True) -> list[str]:
        """Latch (every earlier session's goals and torque-on are refused from now on),
        then torque off on every servo: one packet, then (``confirm``) confirmed servo by
        servo; a run that is ending confirms it itself. Returns the failures (one line
        each; empty when the bus took them)."""
        with self.io:
            self._generation += 1
            self.estop_reason = reason
            if not self.bus.is_open:
                return []
            return self.torque_off(self.ids, confirm=confirm)

    def torque_off(self, ids: Sequence[int], *, confirm: bool = True) -> list[str]:
        """Torque off on ``ids`` (one packet, then confirmed), whoever holds the bus; the
        failures as lines."""
        failed = []
        steps: list[tuple[str, Callable[[list[int]], None]]] = [
            ("disable torque", self.bus.release)]
        if confirm:
            steps.append(("confirm torque off", lambda i: self.bus.set_torque(i, enabled=False)))
        with self.io:
            for what, step in steps:
                try:
                    step(list(ids))
                    self.torque.update(dict.fromkeys(ids, False))
                except BusError as e:
                    failed.append(f"could not {what}: {e}")
        for line in failed:
            log.error("%s", line)
        return failed

    def close(self, *, torque_off: bool) -> list[str]:
        """Close the bus, torque off first unless holding is wanted (servo by servo unless
        every one has already confirmed it; the bus's own close sends one more packet);
        the failures."""
        failed = []
        if torque_off and self.bus.is_open and \
                not all(self.torque.get(i) is False for i in self.ids):
            failed = self.torque_off(self.ids)
        with self.io:
            self.bus.close(torque_off=torque_off)
        return failed


class _LockedClock:
    """A bus's own clock (the simulated bus steps its physics in ``sleep_until``), each
    step under the lease's lock so an e-stop from another thread never lands mid-step."""

    def __init__(self, clock: Any, io: threading.RLock) -> None:
        self._clock, self._io = clock, io

    def now(self) -> float:
        return float(self._clock.now())

    def sleep_until(self, t: float) -> None:
        with self._io:
            self._clock.sleep_until(t)


class Session(Bus):
    """The bus as one owner sees it (see the module docstring). ``end()`` (or leaving a
    ``with`` block) gives the bus back; it never closes the bus itself."""

    def __init__(self, lease: BusLease, owner: str, generation: int) -> None:
        self.lease = lease
        self.owner = owner
        self._generation = generation
        self.kind = lease.bus.kind

    def __getattr__(self, name: str) -> Any:  # the bus's own extras (sim: clock, pose, ...)
        value = getattr(self.lease.bus, name)
        return _LockedClock(value, self.lease.io) if name == "clock" else value

    @property
    def raw(self) -> Bus:
        """The bus itself, for what the session's owner does under ``lease.io``."""
        return self.lease.bus

    def _check(self, what: str) -> None:
        lease = self.lease
        if self._generation != lease.generation:
            raise Preempted(f"{lease.estop_reason or 'emergency stop'}: {what} refused for "
                            f"{self.owner}; nothing moves until a new start")
        if lease._session is not self:
            raise Preempted(f"{self.owner} no longer owns the bus: {what} refused")

    @property
    def live(self) -> bool:
        """No e-stop since this session began and it still owns the bus."""
        return self._generation == self.lease.generation and self.lease._session is self

    def end(self) -> None:
        self.lease._end(self)

    def __enter__(self) -> Session:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.end()

    # -- Bus -----------------------------------------------------------------------------
    def open(self) -> None:
        self.lease.open()

    def close(self, *, torque_off: bool = True) -> None:
        """Ends the session (the lease's holder closes the bus); torque off first if asked."""
        if torque_off:
            self.lease.torque_off(self.lease.ids)
        self.end()

    @property
    def is_open(self) -> bool:
        return self.lease.bus.is_open

    @property
    def retry_span_s(self) -> float:
        return self.lease.bus.retry_span_s

    def max_rate_hz(self, *, read_every: int) -> float | None:
        return self.lease.bus.max_rate_hz(read_every=read_every)

    def check_rate(self, rate_hz: float, *, read_every: int) -> None:
        self.lease.bus.check_rate(rate_hz, read_every=read_every)

    def ping(self, servo_id: int) -> int | None:
        with self.lease.io:
            return self.lease.bus.ping(servo_id)

    def scan(self, ids: Iterable[int]) -> list[ServoInfo]:
        with self.lease.io:
            return self.lease.bus.scan(ids)

    def set_torque(self, ids: Iterable[int], *, enabled: bool) -> None:
        ids = list(ids)
        with self.lease.io:
            if enabled:
                self._check("torque on")
            self.lease.bus.set_torque(ids, enabled=enabled)
            self.lease.torque.update(dict.fromkeys(ids, enabled))

    def write_goals(self, goals: Mapping[int, int]) -> None:
        with self.lease.io:
            self._check("goal")
            self.lease.bus.write_goals(goals)

    def read_state(self, ids: Iterable[int]) -> dict[int, ServoState]:
        return self.lease.read_state(ids)

    def arm_failsafe(self, ids: Iterable[int], *, timeout_s: float) -> float | None:
        with self.lease.io:
            return self.lease.bus.arm_failsafe(ids, timeout_s=timeout_s)

    def failsafe_tripped(self, ids: Iterable[int]) -> list[int]:
        with self.lease.io:
            return self.lease.bus.failsafe_tripped(ids)

    def disarm_failsafe(self, ids: Iterable[int]) -> None:
        with self.lease.io:
            self.lease.bus.disarm_failsafe(ids)

    def release(self, ids: Iterable[int]) -> None:
        ids = list(ids)
        with self.lease.io:
            self.lease.bus.release(ids)
            self.lease.torque.update(dict.fromkeys(ids, False))


@contextmanager
def holding(lease: BusLease, owner: str) -> Iterator[Session]:
    """``with holding(lease, owner) as bus:`` a session ended however the block ends."""
    session = lease.acquire(owner)
    try:
        yield session
    finally:
        session.end()
