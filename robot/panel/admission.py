"""Which connections the panel's web side takes, and for how long.

Each HTTP connection is served by one thread, so the number of connections is the number
of threads: at most ``max_connections`` requests are served at once, at most
``max_per_client`` of them from one address (a phone's browser opens about six); a
connection over either cap is closed as soon as it is accepted, before a thread exists for
it. The request line and headers must all arrive within ``head_timeout_s`` of the accept,
however slowly they trickle in (a client sending one byte every few seconds, slowloris,
is dropped then, with or without a token); a body within the server's read timeout after
its headers. Upgraded WebSockets leave this count for the live hub's own cap.

These bounds keep the web side's process small; the control loop runs in another process
(robot.panel.loop_process), so even a web side at its caps does not slow it.
"""

from __future__ import annotations

import io
import socket
import threading
import time
from collections import Counter

MAX_CONNECTIONS = 64
MAX_PER_CLIENT = 16
HEAD_TIMEOUT_S = 5.0  # [s]


class Admission:
    """Counts connections being served, by client address; thread-safe."""

    def __init__(self, *, max_connections: int = MAX_CONNECTIONS,
                 max_per_client: int = MAX_PER_CLIENT) -> None:
        self.max_connections = max_connections
        self.max_per_client = max_per_client
        self._lock = threading.Lock()
        self._by_client: Counter[str] = Counter()
        self.refused = 0

    @property
    def serving(self) -> int:
        return sum(self._by_client.values())

    def admit(self, client: str) -> bool:
        """Count a connection from ``client`` in, or refuse it (False) over a cap."""
        with self._lock:
            if (sum(self._by_client.values()) >= self.max_connections
                    or self._by_client[client] >= self.max_per_client):
                self.refused += 1
                return False
            self._by_client[client] += 1
            return True

    def leave(self, client: str) -> None:
        with self._lock:
            self._by_client[client] -= 1
            if self._by_client[client] <= 0:
                del self._by_client[client]


class DeadlineReader(io.RawIOBase):
    """A socket read only until ``deadline`` [s, time.monotonic]: every read waits at most
    the time left, then raises TimeoutError (the HTTP handler drops the connection)."""

    def __init__(self, sock: socket.socket, deadline: float) -> None:
        super().__init__()
        self.sock = sock
        self.deadline = deadline

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: memoryview) -> int:  # type: ignore[override]
        left = self.deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError("the client did not send its request in time")
        self.sock.settimeout(left)
        return self.sock.recv_into(buffer)
