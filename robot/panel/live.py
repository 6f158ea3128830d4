"""Live telemetry over WebSockets: one snapshot, one JSON encoding, pushed to every client.

Polling costs the control process one state snapshot (locks, forward kinematics for the
stick figure, JSON) per client per poll; 50 phones polling at 10 Hz are 500 snapshots a
second competing with the control loop for the interpreter. Here one thread makes one
snapshot ``rate_hz`` times a second, whatever the number of clients, and writes the same
frame to each socket without blocking (a slow client skips frames, one that stays stuck
for ``STALL_S`` is dropped), so the loop's cost does not grow with the audience.

The WebSocket protocol itself (handshake, framing, close, ping) is the ``websockets``
library's Sans-I/O layer; this module only moves bytes. The HTTP handler that upgrades a
request has already passed it through the panel's guard (Host, Origin, token).
"""

from __future__ import annotations

import json
import logging
import socket
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from websockets.datastructures import Headers
from websockets.http11 import Request
from websockets.server import ServerProtocol

log = logging.getLogger(__name__)

#: Push rate [Hz]: the stick figure and telemetry refresh.
RATE_HZ = 20.0
#: Most clients at once (each holds one thread blocked in recv).
MAX_CLIENTS = 64
#: A client whose socket accepts nothing for this long is dropped [s].
STALL_S = 5.0


class _Client:
    def __init__(self, sock: socket.socket, protocol: ServerProtocol) -> None:
        self.sock = sock
        self.protocol = protocol
        self.lock = threading.Lock()  # the Sans-I/O protocol is not thread-safe
        self.pending = b""            # the unsent rest of the last frame
        self.stalled_since: float | None = None
        self.closed = False
        self.eof = 0                  # 1: the protocol wants EOF sent, 2: sent

    def flush(self, *, block: bool = False) -> None:
        """Send what the protocol has queued (lock held), never blocking unless asked;
        its end-of-stream marker (an empty chunk, after a close) half-closes the socket,
        which is what tells the client the closing handshake is complete."""
        for chunk in self.protocol.data_to_send():
            if chunk:
                self.pending += chunk
            elif not self.eof:
                self.eof = 1
        while self.pending:
            try:
                sent = self.sock.send(self.pending, 0 if block else socket.MSG_DONTWAIT)
            except BlockingIOError:
                return
            self.pending = self.pending[sent:]
        if self.eof == 1:
            self.eof = 2
            self.sock.shutdown(socket.SHUT_WR)


class LiveHub:
    """Pushes ``snapshot()`` (a JSON-ready dict) to every WebSocket client at ``rate_hz``."""

    def __init__(self, snapshot: Callable[[], Mapping[str, Any]], *,
                 rate_hz: float = RATE_HZ, max_clients: int = MAX_CLIENTS) -> None:
        self.snapshot = snapshot
        self.period_s = 1.0 / rate_hz
        self.max_clients = max_clients
        self._clients: list[_Client] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.frames = 0  # snapshots pushed (one per period while anyone listens)

    @property
    def clients(self) -> int:
        return len(self._clients)

    def full(self) -> bool:
        return len(self._clients) >= self.max_clients

    # -- one connection (runs in the HTTP handler's thread) ------------------------------
    def serve(self, sock: socket.socket, request_line: str,
              headers: list[tuple[str, str]]) -> None:
        """Complete the handshake on ``sock`` and serve it until the client goes away.

        The HTTP server has read the request already; it is handed to the protocol as the
        bytes it was (request line and headers), so the library parses the handshake and
        then reads frames."""
        protocol = ServerProtocol(logger=log)
        head = request_line + "\r\n" + "".join(f"{k}: {v}\r\n" for k, v in headers)
        protocol.receive_data((head + "\r\n").encode("latin-1"))
        events = protocol.events_received()
        request = events[0] if events and isinstance(events[0], Request) else None
        if request is None:
            request = Request("/", Headers())  # unparseable: accept() answers 400
        response = protocol.accept(request)
        protocol.send_response(response)
        client = _Client(sock, protocol)
        sock.settimeout(None)
        accepted = response.status_code == 101
        with client.lock:  # counted once the 101 is out, before any frame can follow it
            if accepted:
                with self._lock:
                    self._clients.append(client)
            client.flush(block=True)
        if not accepted:
            return
        self._ensure_running()
        try:
            self._read(client)
        finally:
            with self._lock:
                if client in self._clients:
                    self._clients.remove(client)
            client.closed = True

    def _read(self, client: _Client) -> None:
        """Feed what the client sends (pings, close) to the protocol until EOF."""
        while not self._stop.is_set():
            try:
                data = client.sock.recv(65536)
            except OSError:
                return
            with client.lock:
                if data:
                    client.protocol.receive_data(data)
                else:
                    client.protocol.receive_eof()
                client.protocol.events_received()  # answers to pings/close are queued
                try:
                    client.flush()
                except OSError:
                    return
                if not data or client.protocol.close_expected():
                    return

    # -- the pusher ----------------------------------------------------------------------
    def _ensure_running(self) -> None:
        with self._lock:
            if self._thread is None or not self._thread.is_alive():
                self._stop.clear()
                self._thread = threading.Thread(target=self._push_loop, name="panel-live",
                                                daemon=True)
                self._thread.start()

    def _push_loop(self) -> None:
        deadline = time.monotonic()
        while not self._stop.is_set():
            deadline += self.period_s
            now = time.monotonic()
            if deadline < now:             # fell behind (a busy machine): skip, no burst
                deadline = now + self.period_s
            self._stop.wait(max(0.0, deadline - now))
            with self._lock:
                clients = list(self._clients)
            if not clients:
                continue
            try:
                frame = json.dumps(self.snapshot())
            except Exception:              # a bug in the snapshot must not end the pushes
                log.exception("panel live: snapshot failed")
                continue
            self.frames += 1
            for c in clients:
                self._push(c, frame)

    def _push(self, client: _Client, frame: str) -> None:
        with client.lock:
            if client.closed:
                return
            try:
                if client.pending:          # still sending an older frame: skip this one
                    client.flush()
                else:
                    client.protocol.send_text(frame.encode())
                    client.flush()
            except OSError:
                self._drop(client)
                return
            now = time.monotonic()
            if client.pending:
                client.stalled_since = client.stalled_since or now
                if now - client.stalled_since > STALL_S:
                    self._drop(client)
            else:
                client.stalled_since = None

    def _drop(self, client: _Client) -> None:
        """Close a dead or stuck client's socket (its reader thread then ends)."""
        client.closed = True
        try:
            client.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def close(self) -> None:
        """Stop pushing and close every client (going away, 1001)."""
        self._stop.set()
        with self._lock:
            clients = list(self._clients)
        for c in clients:
            with c.lock:
                try:
                    c.protocol.send_close(1001, "panel shutting down")
                    c.flush()
                except Exception:
                    pass
            self._drop(c)
