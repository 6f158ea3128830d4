"""The loop's read-back: every ``read_every`` ticks the servos' present state goes into
the telemetry and past the watchdog (robot.loop.watchdog), which may raise SafetyStop."""

from __future__ import annotations

from robot.bus.base import Bus
from robot.bus.servo_map import ServoMap
from robot.errors import BusError
from robot.loop.clock import Clock
from robot.loop.source import JointVector
from robot.loop.telemetry import Telemetry
from robot.loop.watchdog import Watchdog


def read_state(bus: Bus, servo_map: ServoMap, watchdog: Watchdog, tel: Telemetry,
               q_goal: JointVector, *, clock: Clock) -> bool:
    """Read every servo's state into ``tel`` (``servo``, ``q_present`` [rad], ``fresh``,
    ``t_read``: when the reply was in, on the loop's ``clock``) and check it against the
    goal just written, ``q_goal`` [rad]; False if the bus failed (counted by the
    watchdog, which stops the run after a streak)."""
    try:
        states = bus.read_state(servo_map.ids)
    except BusError as e:
        watchdog.bus_failed("read", e)
        return False
    watchdog.bus_ok("read")
    tel.t_read = clock.now()
    tel.servo = states
    present = servo_map.from_positions({i: s.position for i, s in states.items()})
    tel.q_present = present.tolist()
    tel.fresh = True
    watchdog.check(states, q_goal, present=present)
    return True
