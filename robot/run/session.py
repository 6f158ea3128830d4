"""A bus opened by a command that does not stream a run (capture, calibrate, monitor,
setup-motors, torque): closed however the command ends, the close shielded from signals
(robot.run.signals), torque off when asked or after a second signal."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

from robot.bus.base import Bus
from robot.run.signals import installed, shield


@contextmanager
def bus_session(bus: Bus, *, torque_off: bool, closed: Callable[[], None] | None = None
                ) -> Iterator[Bus]:
    """Open ``bus`` for the block; close it after, whatever ended the block: with torque
    off if ``torque_off`` or if a second signal came (the operator's "torque off now");
    then call ``closed`` (e.g. to tell the operator)."""
    bus.open()
    try:
        yield bus
    finally:
        with shield():
            latch = installed()
            bus.close(torque_off=torque_off or (latch is not None and latch.emergency))
            if closed is not None:
                closed()
