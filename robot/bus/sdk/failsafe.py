"""The servos' own communication watchdog, armed and disarmed through a vendor-SDK bus.

What each family offers is data (``tables.COMM_WATCHDOG``): Dynamixel X has the Bus
Watchdog register, Feetech STS has nothing (``SdkBus.arm_failsafe`` then returns None and
writes nothing). Arming clears an earlier trip, writes the setting and reads it back.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING

from robot.bus.tables import CommWatchdog
from robot.errors import BusError, ConfigError

if TYPE_CHECKING:
    from robot.bus.sdk.registers import SdkRegisters

#: Slack for timeouts that are whole steps in decimal but not in binary (0.1 / 0.02) [steps].
_EPS = 1e-9


def watchdog_steps(wd: CommWatchdog, timeout_s: float, kind: str) -> int:
    """Register steps for ``timeout_s`` [s], rounded up (never shorter than asked).

    Raises ConfigError naming the valid range when the servo cannot arm that timeout.
    """
    lo, hi = wd.range_s
    if not lo * (1 - _EPS) <= timeout_s <= hi * (1 + _EPS):
        raise ConfigError(f"failsafe timeout {timeout_s!r} s is outside the {kind} "
                          f"{wd.register} range {lo:g} to {hi:g} s (steps of "
                          f"{wd.unit_s * 1e3:g} ms); choose a timeout in that range")
    return min(wd.steps[1], max(wd.steps[0], math.ceil(timeout_s / wd.unit_s - _EPS)))


def arm(bus: SdkRegisters, wd: CommWatchdog, ids: Iterable[int], timeout_s: float) -> float:
    """Arm ``wd`` on every id with ``timeout_s`` [s]; return the armed timeout [s]."""
    steps = watchdog_steps(wd, timeout_s, bus.kind)

    def one(sid: int) -> None:
        bus.write_register(sid, wd.register, wd.off)    # clears an earlier trip first
        bus.write_register(sid, wd.register, steps)
        got = bus.read_register(sid, wd.register)
        if got != steps:
            raise BusError(
                f"{bus.kind} {bus.port_name}: {bus.who(sid)}: {wd.register} reads {got} after "
                f"arming it with {steps}; it needs firmware v{wd.min_firmware} or later: "
                "update the servo's firmware or run without the failsafe")
        bus.failsafe_armed.add(sid)

    bus.each(ids, one)
    return steps * wd.unit_s


def tripped(bus: SdkRegisters, wd: CommWatchdog, ids: Iterable[int]) -> list[int]:
    """The ids among ``ids`` we armed whose ``wd`` register reads its tripped value (a
    signed value: the register reads unsigned, -1 is 255 in one byte)."""
    raw = wd.tripped % (1 << 8 * bus.table[wd.register].size)
    return [sid for sid in sorted(set(ids) & bus.failsafe_armed)
            if bus.read_register(sid, wd.register) == raw]


def disarm(bus: SdkRegisters, wd: CommWatchdog, ids: Iterable[int]) -> None:
    """Write ``wd.off`` on every id: disarms the watchdog and clears a trip."""
    def one(sid: int) -> None:
        bus.write_register(sid, wd.register, wd.off)
        bus.failsafe_armed.discard(sid)

    bus.each(ids, one)
