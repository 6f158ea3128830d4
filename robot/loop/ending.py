"""How a run arms its start and ends on the bus: the servos' own watchdog, and torque off
(one packet first, then confirmed servo by servo) or hold (robot.loop.streamer)."""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence

from robot.bus.base import Bus
from robot.errors import BusError
from robot.loop.watchdog import FAILSAFE_MARGIN

log = logging.getLogger(__name__)


def arm_failsafe(bus: Bus, ids: Sequence[int], failsafe_s: float | None, *,
                 dt: float) -> None:
    """Arm the servos' bus watchdog where they have one: ``failsafe_s`` [s] (0 or None: not
    at all), at least ``FAILSAFE_MARGIN`` x the bus's retry span plus two ticks of ``dt`` [s]."""
    if failsafe_s:
        timeout = max(failsafe_s, FAILSAFE_MARGIN * bus.retry_span_s + 2 * dt)
        armed = bus.arm_failsafe(ids, timeout_s=timeout)
        if armed is not None:
            log.info("servo bus watchdog armed: %.2f s", armed)


def finish(bus: Bus, ids: Sequence[int], *, torque_off: bool, bus_dead: bool,
           failsafe: bool) -> None:
    """Torque off (one packet first, then confirmed servo by servo) or hold; disarm the
    servos' watchdog (``failsafe``: it was armed). On a dead bus only the one packet is
    tried. A failed step is logged, never raised: the others still run."""
    ids = list(ids)
    steps: list[tuple[str, Callable[[], None]]] = []
    if torque_off:
        steps.append(("disable torque", lambda: bus.release(ids)))
    if not bus_dead:
        if failsafe:
            steps.append(("disarm the servos' bus watchdog", lambda: bus.disarm_failsafe(ids)))
        if torque_off:
            steps.append(("confirm torque off", lambda: bus.set_torque(ids, enabled=False)))
    for what, step in steps:
        try:
            step()
        except BusError as e:
            log.error("could not %s: %s", what, e)
    if not torque_off:
        log.info("holding the last pose with torque on (hold_at_end)")
