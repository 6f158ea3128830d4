"""An OSC server on UDP (python-osc parses the packets): every datagram from an allowed
source becomes actions for the feed (robot.showctl.feed), at once, on one thread.

The e-stop is found before anything else is done with a datagram: any message at
``/biped/estop`` (alone or in a bundle, whatever its arguments) goes straight to the feed's
e-stop path; parsing, validation and the merge of parameter changes come after, and they
are cheap (a few microseconds), so this thread keeps up with a flood and the kernel's
buffer does not overflow (and drop an e-stop with the flood). A bundle's time tag is not
waited for: its messages act on arrival.
"""

from __future__ import annotations

import logging
import socket
import threading
import time

from pythonosc.osc_packet import OscPacket, ParseError

from robot.errors import ConfigError
from robot.showctl.actions import ESTOP, Ignored, parse
from robot.showctl.feed import Feed
from robot.showctl.sources import Sources

log = logging.getLogger(__name__)

ESTOP_BYTES = b"/biped/estop\x00"
BUNDLE = b"#bundle\x00"
#: Receive buffer asked for [bytes] (the kernel caps it at net.core.rmem_max).
RCVBUF = 4 << 20


class OscListener:
    """Listens on ``host``:``port`` (0: a free port; ``port`` tells which after ``open``)
    for datagrams from ``sources``. No socket before ``open``."""

    def __init__(self, feed: Feed, *, port: int, host: str = "127.0.0.1",
                 sources: Sources | None = None) -> None:
        self.feed = feed
        self.host = host
        self._port = port
        self.sources = sources or Sources.parse(None, host=host)
        self._sock: socket.socket | None = None
        self._thread = threading.Thread(target=self._read, name="osc-in", daemon=True)
        self._closed = False
        self.received = 0

    @property
    def port(self) -> int:
        return self._sock.getsockname()[1] if self._sock is not None else self._port

    def open(self) -> None:
        family = socket.AF_INET6 if ":" in self.host else socket.AF_INET
        sock = socket.socket(family, socket.SOCK_DGRAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RCVBUF)
            sock.bind((self.host, self._port))
        except OSError as e:
            sock.close()
            raise ConfigError(f"--osc {self._port}: cannot listen on {self.host}: "
                              f"{e.strerror or e}") from None
        self._sock = sock
        self._thread.start()
        log.info("OSC: listening on %s:%d", self.host, self.port)

    def close(self) -> None:
        self._closed = True
        sock = self._sock
        if sock is not None:
            try:
                sock.shutdown(socket.SHUT_RDWR)   # wakes the reader
            except OSError:
                pass
            if self._thread.is_alive():
                self._thread.join(2.0)
            sock.close()

    def _read(self) -> None:
        sock = self._sock
        assert sock is not None
        once = self.feed.once
        while not self._closed:
            try:
                data, source = sock.recvfrom(65536)
            except OSError:
                break
            received = time.monotonic()
            if not data:
                if self._closed:
                    break
                continue
            self.received += 1
            if not self.sources.allows(str(source[0])):
                once.note("source", f"OSC from {source[0]}: not an allowed source "
                          "(--osc-allow)")
                continue
            if data.startswith(ESTOP_BYTES) or (data.startswith(BUNDLE)
                                                and ESTOP_BYTES in data):
                self.feed.estop(received)
            self.handle(data, received)

    def handle(self, data: bytes, received: float) -> None:
        """One datagram's messages to the feed (an e-stop in it was already sent)."""
        once = self.feed.once
        try:
            messages = OscPacket(data).messages
        except ParseError as e:
            once.note("malformed", f"OSC: a datagram that is not OSC: {e}")
            return
        for timed in messages:
            msg = timed.message
            action = parse(msg.address, msg.params)
            if isinstance(action, Ignored):
                if not action.quiet:
                    once.note(action.kind, f"OSC: {action.why}")
            elif action != ESTOP:
                self.feed.put(action, received)
