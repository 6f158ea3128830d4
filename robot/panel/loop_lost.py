"""When the panel's control-loop process dies (SIGKILL, the OOM killer, a crash in C code):
the panel's own process opens the port and turns torque off.

The loop held the bus; once its process is gone nobody writes to the servos, and a servo
keeps its last goal with torque on (a Dynamixel X whose Bus Watchdog the loop armed stops
where it is within the watchdog's timeout, torque still on; the others do not stop at
all). The dead process's port closes with it, so the web side can open the same port,
send torque off and confirm it servo by servo (``robot.loop.ending.finish``), without the
health checks of a normal start (a servo in a hardware error still gets torque off).

In the simulation the simulated robot ended with the loop's process: nothing to turn off.
Either way the panel exits non-zero: its loop crashed.
"""

from __future__ import annotations

import logging
from typing import Any

from robot.config.robot import RobotConfig
from robot.errors import BipedError
from robot.loop.ending import finish
from robot.panel.options import BusSpec

log = logging.getLogger(__name__)


def take_over(robot: RobotConfig, bus: BusSpec, *, why: str) -> dict[str, Any]:
    """Turn torque off on ``robot``'s servos through a bus of our own after the loop
    process ended (``why``: how it ended, one line). Returns the shutdown report the panel
    prints its last line from: ``lost`` (``why``), ``sim`` (nothing to turn off),
    ``torque`` {id: still on or unknown}, ``failed`` lines."""
    report: dict[str, Any] = {"lost": why, "holding": False, "failed": [], "torque": {}}
    if bus.kind == "sim":
        report["sim"] = True
        return report
    ids = list(robot.ids)
    log.warning("%s: opening %s to turn torque off", why, bus.port or robot.bus.port)
    try:
        own = BusSpec(bus.kind, bus.port, bus.baud,
                      {**bus.options, "check_health": False}).build(robot)
        own.open()
    except BipedError as e:
        report["failed"] = [f"could not open the port after the loop ended: {e}"]
        report["torque"] = dict.fromkeys(ids, True)
        return report
    try:
        torque = finish(own, ids, torque_off=True, bus_dead=False, failsafe=True)
    finally:
        own.close(torque_off=False)
    if torque != "off":
        said = "sent, not confirmed" if torque == "sent" else "not sent"
        report["failed"] = [f"torque off {said} after the loop ended"]
    report["torque"] = dict.fromkeys(ids, torque != "off")
    return report
