"""Before a run: can a vendor bus's wire carry the loop's rate? (robot/bus/wire_time.py
does the arithmetic; ``SdkBus.check_rate`` calls this, and the Streamer calls that before
anything moves.)"""

from __future__ import annotations

import logging
from dataclasses import replace

from robot.bus.base import Bus
from robot.errors import ConfigError

log = logging.getLogger(__name__)


def check_rate(bus: Bus, rate_hz: float, read_every: int) -> None:
    """Before a run on an open ``bus``: ConfigError (one line: the baud and the highest
    rate) when its wire cannot carry ``rate_hz`` even with every return delay at 0 (it
    never can: refusing breaks nothing that worked); a logged health warning when only the
    servos' measured return delay makes it overrun (``--fix-return-delay`` mends that).
    Buses without a wire (the simulation) pass."""
    wire = bus.tick_wire(read_every)
    if wire is None:
        return
    if rate_hz > wire.max_rate_hz:
        raise ConfigError(
            f"--rate {rate_hz:g}: {wire.servos} servos on {bus.kind} at {wire.baud} baud "
            f"carry at most {wire.max_rate_hz:.0f} Hz (a tick's goal write is "
            f"{wire.write_bytes} bytes = {wire.write_s * 1e3:.2f} ms, a state read every "
            f"{wire.read_every} ticks {wire.read_bytes} bytes = {wire.read_s * 1e3:.2f} ms, "
            f"at 10 bits a byte); use --rate {int(wire.max_rate_hz)} or less, a higher baud "
            "(bus.baud / --baud) or a larger --read-every")
    delay = bus.return_delay_s
    slow = replace(wire, read_delay_s=wire.servos * delay)
    if rate_hz > slow.max_rate_hz:
        log.warning("at %g Hz the loop will overrun: with a return delay of %.0f µs per servo "
                    "the wire at %d baud carries %.0f Hz; set it to 0 with `biped scan "
                    "--fix-return-delay`", rate_hz, delay * 1e6, wire.baud, slow.max_rate_hz)
