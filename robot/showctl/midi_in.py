"""MIDI in: control changes set gait parameters through the mapping (robot.showctl.midi_map),
notes fire what the mapping says, MIDI Show Control GO/STOP drive the cue list; everything
goes to the feed (robot.showctl.feed) as the OSC messages do, the e-stop on its own path.

Learn: ``learn(param)`` arms it; the next control change binds its channel and controller
to ``param`` over the parameter's whole range (linear), the mapping file is written (whole,
robot.showctl.midi_map.save_map) and the value applies. Channels are 1-16 here and in the
file (mido counts 0-15).
"""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path

import mido

from robot.config.params import canonical_name
from robot.errors import ConfigError
from robot.showctl.actions import Command, Named, SetParam
from robot.showctl.feed import Feed
from robot.showctl.midi_map import MidiMap, load_map, save_map
from robot.showctl.msc import MscCommand, NotMsc, parse_msc

log = logging.getLogger(__name__)


class MidiIn:
    """MIDI messages → the feed, through the mapping in ``path`` (learn writes it)."""

    def __init__(self, feed: Feed, path: Path, mapping: MidiMap | None = None) -> None:
        self.feed = feed
        self.path = path
        self.map = mapping if mapping is not None else load_map(path)
        self._parser = mido.Parser()
        self._lock = threading.Lock()
        self._learn: str | None = None
        self.last: dict[str, object] | None = None   # the last message, for the panel

    # -- learn ---------------------------------------------------------------------------
    @property
    def learning(self) -> str | None:
        return self._learn

    def learn(self, param: object) -> str | None:
        """Arm learn for ``param`` (a gait parameter's name; None cancels)."""
        name = None if param is None else canonical_name(str(param), where="MIDI learn") \
            if isinstance(param, str) else _refuse(param)
        with self._lock:
            self._learn = name
        return name

    # -- messages ------------------------------------------------------------------------
    def feed_bytes(self, data: bytes, received: float | None = None) -> None:
        """Raw MIDI bytes (any split): each whole message handled as it completes."""
        when = time.monotonic() if received is None else received
        with self._lock:
            self._parser.feed(data)
            messages = list(self._parser)
        for msg in messages:
            self.handle(msg, when)

    def handle(self, msg: mido.Message, received: float) -> None:
        once = self.feed.once
        if msg.type == "control_change":
            self._cc(msg.channel + 1, msg.control, msg.value, received)
        elif msg.type == "note_on" and msg.velocity > 0:
            self.last = {"type": "note", "channel": msg.channel + 1, "note": msg.note}
            m = self.map.note_for(msg.channel + 1, msg.note)
            if m is None:
                once.note("unmapped note", f"MIDI note {msg.note} on channel "
                          f"{msg.channel + 1}: not in {self.map.source}")
            else:
                self.feed.put(m.action, received)
        elif msg.type == "sysex":
            self._msc(parse_msc(msg.data, device=self.map.msc_device), received)

    def _cc(self, channel: int, cc: int, value: int, received: float) -> None:
        self.last = {"type": "cc", "channel": channel, "cc": cc, "value": value}
        with self._lock:
            learn, self._learn = self._learn, None
            if learn is not None:
                self.map = self.map.learned(channel, cc, learn)
        if learn is not None:
            try:
                save_map(self.map, self.path)
                log.info("MIDI learn: channel %d CC %d -> %s (saved to %s)", channel, cc,
                         learn, self.path)
            except (OSError, ConfigError) as e:
                log.error("MIDI learn: channel %d CC %d -> %s, but %s could not be written: "
                          "%s", channel, cc, learn, self.path, e)
        m = self.map.cc_for(channel, cc)
        if m is None:
            self.feed.once.note("unmapped cc", f"MIDI CC {cc} on channel {channel}: not in "
                                f"{self.map.source}")
            return
        self.feed.put(SetParam(m.param, m.value(value)), received)

    def _msc(self, cmd: MscCommand | NotMsc | None, received: float) -> None:
        if cmd is None:
            return
        if isinstance(cmd, NotMsc):
            self.feed.once.note(cmd.kind, cmd.why)
            return
        self.last = {"type": "msc", "command": cmd.command, "cue": cmd.cue}
        if cmd.command == "stop":
            self.feed.put(Command("stop"), received)
        elif cmd.cue is None:
            self.feed.put(Command("go"), received)
        else:
            self.feed.put(Named("cue", cmd.cue), received)


def _refuse(param: object) -> str:
    raise ConfigError(f"MIDI learn: param must be a gait parameter's name, got {param!r}")
