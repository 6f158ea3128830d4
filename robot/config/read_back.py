"""How often a run reads its servos back: the bound on ``read_every`` wherever it can be set
(``--read-every``, a take's header), so that no input switches the watchdog off
(robot.loop.watchdog: over-temperature, hardware error flags, a jammed servo).

A read-back period of ``MAX_READ_PERIOD_S`` at most: the jam check judges the last second
of read-backs (robot.loop.following), so a jam or a hot servo is seen within about a
second. The bundled default, every 10th tick at 200 Hz, is 50 ms.
"""

from __future__ import annotations

import math

from robot.config.toml_io import show
from robot.errors import ConfigError

#: Longest time between two read-backs [s].
MAX_READ_PERIOD_S = 0.5


def max_read_every(rate_hz: float) -> int:
    """Most ticks between read-backs at ``rate_hz`` [Hz]: ``MAX_READ_PERIOD_S`` of them
    (at least 1)."""
    return max(1, math.floor(MAX_READ_PERIOD_S * rate_hz + 1e-9))


def check_read_every(read_every: object, rate_hz: float, *, where: str) -> int:
    """``read_every`` [ticks] if it is an integer and the read-back period it gives at
    ``rate_hz`` [Hz] is at most ``MAX_READ_PERIOD_S``; else ConfigError naming ``where``,
    the bound and why."""
    most = max_read_every(rate_hz)
    if isinstance(read_every, bool) or not isinstance(read_every, int) or \
            not 1 <= read_every <= most:
        raise ConfigError(f"{where}: expected an integer in [1, {most}] at {rate_hz:g} Hz "
                          f"(a read-back at least every {MAX_READ_PERIOD_S:g} s: the watchdog "
                          f"must see heat, errors and jams), got {show(read_every)}")
    return read_every
