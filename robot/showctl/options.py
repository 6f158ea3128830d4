"""Show control as the command line asks for it (robot.commands.show_args builds these;
checked there, before anything moves)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from robot.showctl.cues import CueList
from robot.showctl.midi_map import MidiMap
from robot.showctl.osc_out import REPLY_HZ
from robot.showctl.sources import Sources


@dataclass(frozen=True)
class OscOptions:
    """Listen on ``host``:``port`` for ``sources``; status to ``reply`` (host, port) at
    ``reply_hz`` [Hz] (None: no status out)."""

    port: int
    host: str = "127.0.0.1"
    sources: Sources = Sources()
    reply: tuple[str, int] | None = None
    reply_hz: float = REPLY_HZ


@dataclass(frozen=True)
class MidiOptions:
    """MIDI input ``port`` (a name, or socket:HOST:PORT) through the mapping in
    ``map_path`` (``mapping``: as read when the command started)."""

    port: str
    map_path: Path
    mapping: MidiMap


@dataclass(frozen=True)
class ShowOptions:
    """OSC, MIDI (each None: off) and the cue list (empty: none)."""

    osc: OscOptions | None = None
    midi: MidiOptions | None = None
    cues: CueList | None = None

    @property
    def on(self) -> bool:
        return self.osc is not None or self.midi is not None
