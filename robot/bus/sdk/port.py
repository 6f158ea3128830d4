"""Small pieces under the vendor-SDK buses: the port timing mixin, the exceptions a dying
port raises, and the value codecs (sign-magnitude, error bits)."""

from __future__ import annotations

import time
from typing import Any

from robot.bus.tables import ERROR_BITS

try:
    import termios

    #: What a dying port raises inside the SDK (pyserial's SerialException is an OSError;
    #: tcflush on a hung-up pty raises termios.error).
    PORT_ERRORS: tuple[type[Exception], ...] = (OSError, termios.error)
except ImportError:  # not POSIX
    PORT_ERRORS = (OSError,)


#: pyserial read timeout [s]: the SDKs poll ``read`` in a loop; with timeout 0 that loop
#: spins a whole CPU core while waiting for a reply (starving a 2-core machine), with a
#: short blocking read it sleeps in select() until the bytes it asked for arrive.
READ_BLOCK_S = 0.001


class TimedPort:
    """Mixin for an SDK ``PortHandler``: a configurable reply timeout [ms] instead of the
    SDK's fixed 34 ms, a monotonic clock instead of ``time.time()``, blocking reads instead
    of a busy loop (READ_BLOCK_S), and an input flush before every packet (the Feetech
    SDK's ``clearPort`` only drains *output*, so a late reply would be parsed as the answer
    to the next request).
    """

    timeout_ms: float = 20.0
    ser: Any
    tx_time_per_byte: float
    packet_start_time: float
    packet_timeout: float

    def getCurrentTime(self) -> float:
        """Now [ms] on the monotonic clock."""
        return time.monotonic() * 1000.0

    def setPacketTimeout(self, packet_length: int) -> None:
        """Reply deadline: wire time of ``packet_length`` bytes plus ``timeout_ms``."""
        self.packet_start_time = self.getCurrentTime()
        self.packet_timeout = self.tx_time_per_byte * packet_length + self.timeout_ms

    def setupPort(self, cflag_baud: int) -> bool:
        ok = bool(super().setupPort(cflag_baud))  # type: ignore[misc]
        self.ser.timeout = READ_BLOCK_S
        return ok

    def clearPort(self) -> None:
        self.ser.reset_input_buffer()


def error_names(family: str, bits: int) -> frozenset[str]:
    """Hardware-error register bits → normalised names (tables.ERROR_BITS)."""
    return frozenset(name for bit, name in ERROR_BITS[family].items() if bits >> bit & 1)


def sign_magnitude(value: int, sign_bit: int) -> int:
    """Feetech-style sign-magnitude integer (sign in ``sign_bit``) → int."""
    magnitude = value & ((1 << sign_bit) - 1)
    return -magnitude if value >> sign_bit & 1 else magnitude


def twos_complement(value: int, bits: int) -> int:
    """Unsigned ``bits``-wide value → signed int (Dynamixel)."""
    return value - (1 << bits) if value >> (bits - 1) & 1 else value
