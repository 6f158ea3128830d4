"""How a run arms its start and ends on the bus: the servos' own watchdog, and torque off
(one packet first, then confirmed servo by servo) or hold (robot.loop.streamer), and
what is known of the torque after.

A hold is kept only on servos that still answer: one last read of every servo (no
hardware fault, not too hot) and the watchdog disarmed; otherwise the end is a fault and
torque goes off (a fault always ends with torque off). An emergency stop that arrives while a hold is being
finished turns torque off after all.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence

from robot.bus.base import Bus
from robot.errors import BusError, SafetyStop
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


def explain_stop(bus: Bus, ids: Sequence[int], error: SafetyStop,
                 describe: Callable[[int], str]) -> str:
    """``error``'s message, with the cause when servos stopped following because their own
    bus watchdog tripped: the host sent them nothing for longer than its timeout (a stall:
    swap, another process, a full SD card), so they refused every goal since. ``describe``
    names a servo id. A bus that cannot tell leaves the message as it is."""
    if "stopped following" not in str(error):
        return str(error)
    try:
        tripped = bus.failsafe_tripped(ids)
    except BusError:
        return str(error)
    if not tripped:
        return str(error)
    names = ", ".join(describe(i) for i in tripped)
    return (f"the servos' own bus watchdog tripped on {names}: no packet reached them within "
            f"its timeout (the host stalled), so they refused every goal since ({error})")


#: What a run's end left the servos doing, as far as the bus told (LoopStats.torque):
#: "on": holding (every step answered); "off": torque off, confirmed servo by servo;
#: "sent": the torque-off packet went out but no servo confirmed it (the bus stopped
#: answering); "unknown": not even that packet could be sent (the port failed);
#: "untouched": the run was stopped before it started (nothing was written).
TORQUE_STATES = ("on", "off", "sent", "unknown", "untouched")


def finish(bus: Bus, ids: Sequence[int], *, torque_off: bool, bus_dead: bool,
           failsafe: bool) -> str:
    """Torque off (one packet first, then confirmed servo by servo) or hold; disarm the
    servos' watchdog (``failsafe``: it was armed). On a dead bus only the one packet is
    tried. A failed step is logged, never raised: the others still run. Returns what is
    known of the torque (``TORQUE_STATES``); holding with a step failed: "unknown"."""
    ids = list(ids)
    steps: list[tuple[str, Callable[[], None]]] = []
    if torque_off:
        steps.append(("disable torque", lambda: bus.release(ids)))
    if not bus_dead:
        if failsafe:
            steps.append(("disarm the servos' bus watchdog", lambda: bus.disarm_failsafe(ids)))
        if torque_off:
            steps.append(("confirm torque off", lambda: bus.set_torque(ids, enabled=False)))
    failed: list[str] = []
    for what, step in steps:
        try:
            step()
        except BusError as e:
            failed.append(what)
            log.error("could not %s: %s", what, e)
    if not torque_off:
        if failed:
            return "unknown"
        log.info("holding the last pose with torque on (hold_at_end)")
        return "on"
    ran = {what for what, _ in steps}
    if "confirm torque off" in ran and "confirm torque off" not in failed:
        return "off"
    return "unknown" if "disable torque" in failed else "sent"


def end(bus: Bus, ids: Sequence[int], *, hold: bool, confirm: Callable[[], None],
        estop: Callable[[], bool], bus_dead: bool, failsafe: bool) -> tuple[str, str | None]:
    """How a run leaves the servos: hold (``hold``, and ``confirm()``: one last read that
    every servo answers with no fault, else BusError / SafetyStop) or torque off
    (``finish``). An e-stop (``estop()``) while it finished holding, or a hold the bus did
    not acknowledge, turns torque off after all. Returns what is known of the torque and
    the fault to report (None: none)."""
    fault = None
    if hold:
        try:
            confirm()
        except SafetyStop as e:
            fault = f"watchdog: {e}"
        except BusError as e:              # silent: only the one packet, no more timeouts
            fault = f"watchdog: not holding torque on servos that do not answer: {e}"
            bus_dead = True
        else:
            torque = finish(bus, ids, torque_off=False, bus_dead=bus_dead, failsafe=failsafe)
            if torque == "on" and not estop():
                return torque, None
            if torque != "on":
                fault = "watchdog: the servos did not answer as the run ended holding"
    return finish(bus, ids, torque_off=True, bus_dead=bus_dead, failsafe=failsafe), fault
