"""Where MIDI comes from (``--midi PORT``): an input port by name (mido's rtmidi backend:
ALSA on Linux, CoreMIDI, Windows MM), or ``socket:HOST:PORT``: raw MIDI bytes over TCP from
a mido ``PortServer`` (mido's socket ports; also what the tests use, since a machine
without a sound card has no MIDI system), read with a blocking receive and parsed by mido.
Needs the ``midi`` extra (``pip install 'biped[midi]'``)."""

from __future__ import annotations

import logging
import socket
import threading
import time
from typing import Any

from robot.errors import ConfigError
from robot.showctl.midi_in import MidiIn
from robot.showctl.sources import host_port

log = logging.getLogger(__name__)

SOCKET = "socket:"


class MidiPort:
    """The input ``name`` feeding ``midi``; ``open`` connects (ConfigError, one line)."""

    def __init__(self, name: str, midi: MidiIn) -> None:
        self.name = name
        self.midi = midi
        self._port: Any = None
        self._sock: socket.socket | None = None
        self._thread: threading.Thread | None = None
        self._closed = False

    def open(self) -> None:
        import mido

        if self.name.startswith(SOCKET):
            host, port = host_port(self.name[len(SOCKET):], flag="--midi socket:")
            try:
                self._sock = socket.create_connection((host, port), timeout=10.0)
                self._sock.settimeout(None)
            except OSError as e:
                raise ConfigError(f"--midi {self.name}: cannot connect: {e.strerror or e}"
                                  ) from None
            self._thread = threading.Thread(target=self._read, name="midi-in", daemon=True)
            self._thread.start()
            return
        try:
            self._port = mido.open_input(self.name, callback=self._callback)
        except Exception as e:        # rtmidi's own errors: no MIDI system, no such port
            try:
                names = ", ".join(mido.get_input_names()) or "(none)"
            except Exception:
                names = "(no MIDI system on this machine)"
            raise ConfigError(f"--midi {self.name!r}: cannot open it ({e}); inputs: "
                              f"{names}; or socket:HOST:PORT") from None

    def _callback(self, msg: Any) -> None:
        self.midi.handle(msg, time.monotonic())

    def _read(self) -> None:
        sock = self._sock
        assert sock is not None
        why = "closed by the other end"
        try:
            while data := sock.recv(4096):
                self.midi.feed_bytes(data, time.monotonic())
        except OSError as e:
            why = str(e.strerror or e)
        if not self._closed:
            log.error("MIDI %s: the connection ended (%s)", self.name, why)

    def close(self) -> None:
        self._closed = True
        if self._sock is not None:
            try:
                self._sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            self._sock.close()
        if self._port is not None:
            try:
                self._port.close()
            except OSError:
                pass
