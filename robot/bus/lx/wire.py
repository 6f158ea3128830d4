"""What the LX wire can carry: the LX protocol has no sync write, so one control tick is N
MOVE_TIME_WRITE packets (10 bytes each), and a state read is one request and one answer
per servo and value. At 115200 baud (10 bits a byte) that bounds the control rate.

Budget of one tick for ``n`` servos, read back every ``read_every`` ticks:

- writes: n x 10 bytes = n x 0.868 ms (18 servos: 15.6 ms; at most 64 Hz write-only);
- a read-back (``LxBus.read_state``): n position reads (6-byte request + 8-byte answer
  each, plus the servo's turnaround ``TURNAROUND_S``) and one more value of one servo in
  turn (temperature, voltage or load state): 18 servos about 24 ms.

``max_rate_hz`` is the rate at which writes plus the read-backs spread over their ticks
fill the wire; ``check_rate`` refuses a faster ``--rate`` (ConfigError, before anything
moves) and says which rate fits.
"""

from __future__ import annotations

from robot.bus.lx.packet import BITS_PER_BYTE, packet_bytes
from robot.bus.lx.tables import LX_BAUD, LX_COMMANDS
from robot.errors import ConfigError

#: The servo's time from the end of a request to the start of its answer [s]. The manual
#: gives none; HiWonder's own examples wait 5 ms before reading the answer, and its
#: ``SERVO_POS_READ`` round trip is quoted by users at about 1-2 ms over a USB adapter.
#: 0.5 ms is an assumption for the budget, not a measurement.
TURNAROUND_S = 0.0005


def byte_s(baud: int = LX_BAUD) -> float:
    """Wire time of one byte [s]."""
    return BITS_PER_BYTE / baud


def write_s(n: int, *, baud: int = LX_BAUD) -> float:
    """Wire time of one tick's goals: ``n`` MOVE_TIME_WRITE packets [s]."""
    return n * packet_bytes(LX_COMMANDS["move_time_write"]) * byte_s(baud)


def read_s(n: int, *, baud: int = LX_BAUD) -> float:
    """Wire time of one ``read_state`` of ``n`` servos [s]: n position reads plus one
    round-robin value (the longest, a 2-byte one)."""
    pos = LX_COMMANDS["pos_read"]
    one = (packet_bytes(pos) + packet_bytes(pos, reply=True)) * byte_s(baud) + TURNAROUND_S
    return (n + 1) * one


def max_rate_hz(n: int, *, read_every: int, baud: int = LX_BAUD) -> float:
    """The fastest control rate whose ticks the wire carries on average [Hz]."""
    per_tick = write_s(n, baud=baud) + read_s(n, baud=baud) / max(1, read_every)
    return 1.0 / per_tick


def check_rate(rate_hz: float, n: int, *, read_every: int, baud: int = LX_BAUD) -> None:
    """ConfigError when ``rate_hz`` asks more of the wire than it carries."""
    top = max_rate_hz(n, read_every=read_every, baud=baud)
    if rate_hz > top:
        raise ConfigError(
            f"--rate {rate_hz:g}: {n} LX servos at {baud} baud take "
            f"{write_s(n, baud=baud) * 1e3:.1f} ms of wire per tick (no sync write: one "
            f"10-byte move command each) plus {read_s(n, baud=baud) * 1e3:.1f} ms every "
            f"{read_every} ticks for the read-back; the wire carries at most {top:.0f} Hz: "
            f"use --rate {int(top)} or lower")


def read_tick_late(rate_hz: float, n: int, *, baud: int = LX_BAUD) -> bool:
    """Whether the tick that reads back overruns its slot (writes + read > one period)."""
    return write_s(n, baud=baud) + read_s(n, baud=baud) > 1.0 / rate_hz
