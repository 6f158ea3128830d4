"""The half-duplex serial line between the host and the emulated chain: who talks when.

A pty moves bytes at once; a real UART does not. Each byte takes 10 bit times at the baud
rate (8N1: start, 8 data bits, stop), and one device talks at a time. So:

- an instruction packet of n bytes seen at ``t`` ends on the wire at
  ``max(t, line free) + n * 10 / baud``;
- a servo starts its status packet its Return Delay Time after the line went quiet (the
  end of the instruction, or of the status before it in a sync/bulk read chain), and the
  host has all m bytes of it ``m * 10 / baud`` later.

``Line.reply`` returns that release time; ``Outbox`` holds replies until then, so the
server's loop never sleeps while the host may be sending (a client that flushes its output
buffer before each packet loses nothing a real UART would have sent). A host packet that
arrives while replies still wait means the host gave up on them: they are dropped.
"""

from __future__ import annotations

import array
import fcntl
import heapq
import itertools

#: Bits on the wire per byte: start bit, 8 data bits, stop bit (8N1).
BITS_PER_BYTE = 10
TCGETS2 = 0x802C542A         # Linux ioctl: struct termios2 (44 bytes), c_ospeed at word 10
TERMIOS2_WORDS = 11
TERMIOS2_OSPEED = 10


def pty_speed(fd: int) -> int | None:
    """The baud rate [bit/s] the host set on the pty ``fd`` (a pty carries none, but
    pyserial stores the requested speed in its termios), or None if unreadable."""
    buf = array.array("I", [0] * TERMIOS2_WORDS)
    try:
        fcntl.ioctl(fd, TCGETS2, buf)
    except OSError:
        return None
    return int(buf[TERMIOS2_OSPEED]) or None


def wire_time(n_bytes: int, baud: float) -> float:
    """Time ``n_bytes`` take on the wire at ``baud`` [s]."""
    return n_bytes * BITS_PER_BYTE / baud


class Line:
    """When the line is free again [s, time.monotonic()], and the times things take on it."""

    def __init__(self) -> None:
        self.free_at = 0.0

    def instruction(self, seen: float, n_bytes: int, baud: float) -> float:
        """The host's packet of ``n_bytes`` that reached us at ``seen`` [s]: when its last
        byte has crossed the wire [s] (it queues behind what the line still carries)."""
        self.free_at = max(seen, self.free_at) + wire_time(n_bytes, baud)
        return self.free_at

    def reply(self, delay_s: float, n_bytes: int, baud: float) -> float:
        """A status packet of ``n_bytes`` sent ``delay_s`` (the servo's return delay) after
        the line went quiet: when its last byte reaches the host [s]."""
        self.free_at = self.free_at + delay_s + wire_time(n_bytes, baud)
        return self.free_at


class Outbox:
    """Replies waiting for their release time, oldest first."""

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, bytes]] = []
        self._seq = itertools.count()

    def put(self, at: float, data: bytes) -> None:
        heapq.heappush(self._heap, (at, next(self._seq), data))

    @property
    def next_at(self) -> float | None:
        """When the next reply is due [s], or None when none waits."""
        return self._heap[0][0] if self._heap else None

    def due(self, now: float) -> list[tuple[float, bytes]]:
        """(release time [s], packet) of the replies due at ``now`` [s], in release order
        (removed)."""
        out = []
        while self._heap and self._heap[0][0] <= now:
            at, _, data = heapq.heappop(self._heap)
            out.append((at, data))
        return out

    def clear(self) -> int:
        """Drop every waiting reply; returns how many there were."""
        n = len(self._heap)
        self._heap.clear()
        return n
