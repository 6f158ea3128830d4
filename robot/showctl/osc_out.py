"""Status out over OSC (``--osc-reply HOST:PORT``): what a TouchOSC layout or QLab shows,
one bundle ``hz`` times a second (default 20, the panel's live view's rate):

    /biped/state <string>         idle, walking, playing, late, stopped, estop, fault...
    /biped/fault <string>         "" when there is none
    /biped/show/t <float>         the show clock [s] (-1: no show playing)
    /biped/show/take <string>     the take playing ("" none)
    /biped/joint/<name> <float>   each joint's commanded angle [rad]

Sent from a thread of its own on absolute deadlines; a snapshot that fails is skipped
(logged once), a send that fails (nobody listening: ICMP refused) is ignored.
"""

from __future__ import annotations

import logging
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder

from robot.showctl.once import OnceLog

log = logging.getLogger(__name__)

REPLY_HZ = 20.0


@dataclass(frozen=True)
class Status:
    """What goes out: ``joints`` (name, angle [rad]) in the robot's order; ``show_t`` [s]
    (None: no show)."""

    state: str
    fault: str | None = None
    show_t: float | None = None
    take: str | None = None
    joints: tuple[tuple[str, float], ...] = ()


def _message(address: str, value: str | float) -> OscMessageBuilder:
    m = OscMessageBuilder(address)
    m.add_arg(value)
    return m


def encode(status: Status) -> bytes:
    """One OSC bundle of ``status`` (the addresses in the module docstring)."""
    b = OscBundleBuilder(IMMEDIATELY)
    for address, value in (("/biped/state", status.state),
                           ("/biped/fault", status.fault or ""),
                           ("/biped/show/t", -1.0 if status.show_t is None
                            else float(status.show_t)),
                           ("/biped/show/take", status.take or "")):
        b.add_content(_message(address, value).build())
    for name, q in status.joints:
        b.add_content(_message(f"/biped/joint/{name}", float(q)).build())
    return b.build().dgram


class StatusSender:
    """Sends ``snapshot()`` to (``host``, ``port``) ``hz`` times a second. No socket
    before ``start``."""

    def __init__(self, snapshot: Callable[[], Status], *, host: str, port: int,
                 hz: float = REPLY_HZ) -> None:
        self.snapshot = snapshot
        self.address = (host, port)
        self.period = 1.0 / hz
        self.sent = 0
        self._once = OnceLog(log)
        self._stop = threading.Event()
        self._sock: socket.socket | None = None
        self._thread = threading.Thread(target=self._run, name="osc-out", daemon=True)

    def start(self) -> None:
        family = socket.AF_INET6 if ":" in self.address[0] else socket.AF_INET
        self._sock = socket.socket(family, socket.SOCK_DGRAM)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(2.0)
        if self._sock is not None:
            self._sock.close()

    def _run(self) -> None:
        sock = self._sock
        assert sock is not None
        deadline = time.monotonic()
        while not self._stop.wait(max(0.0, deadline - time.monotonic())):
            deadline = max(deadline + self.period, time.monotonic())
            try:
                data = encode(self.snapshot())
            except Exception as e:
                self._once.note("snapshot", f"OSC reply: no status: {type(e).__name__}: {e}")
                continue
            try:
                sock.sendto(data, self.address)
                self.sent += 1
            except OSError as e:
                self._once.note("send", f"OSC reply to {self.address[0]}:{self.address[1]}: "
                                f"{e.strerror or e}")
