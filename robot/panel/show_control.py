"""The panel's show control, assembled: the feed (robot.showctl.feed) on the panel's route
table (robot.panel.remote), the OSC listener and status sender, the MIDI input with learn,
and their two routes:

  GET  /api/showctl      what listens, the counts (actions, updates, e-stops, ignored by
                         kind), the cue list, the MIDI mapping and what learn waits for
  POST /api/midi/learn   {"param": NAME} arms learn (the next control change moved is
                         bound to NAME and saved to the mapping); {"param": null} cancels
"""

from __future__ import annotations

import logging
from typing import Any

from robot.panel.controller import PanelController
from robot.panel.guard import Refused
from robot.panel.remote import PanelTarget
from robot.panel.routes import Handler, Request, Routes, ok
from robot.showctl.feed import Feed
from robot.showctl.midi_in import MidiIn
from robot.showctl.midi_port import MidiPort
from robot.showctl.once import OnceLog
from robot.showctl.options import ShowOptions
from robot.showctl.osc_in import OscListener
from robot.showctl.osc_out import StatusSender

log = logging.getLogger(__name__)


class PanelShowControl:
    """Show control for one panel. No socket and no thread before ``open``."""

    def __init__(self, controller: PanelController, options: ShowOptions) -> None:
        self.options = options
        once = OnceLog(logging.getLogger("robot.showctl"))
        self.target = PanelTarget(controller, cues=options.cues, once=once)
        self.feed = Feed(self.target, rate_hz=controller.options.rate_hz, once=once)
        o, m = options.osc, options.midi
        self.osc = (OscListener(self.feed, port=o.port, host=o.host, sources=o.sources)
                    if o is not None else None)
        self.reply = (StatusSender(self.target.status, host=o.reply[0], port=o.reply[1],
                                   hz=o.reply_hz) if o is not None and o.reply else None)
        self.midi = MidiIn(self.feed, m.map_path, m.mapping) if m is not None else None
        self._port = MidiPort(m.port, self.midi) if m is not None and self.midi else None

    def routes(self) -> Routes:
        return {("GET", "/api/showctl"): lambda _: ok(self.report()),
                ("POST", "/api/midi/learn"): self._learn()}

    def open(self, routes: Routes) -> None:
        """Start on the server's whole route table (``routes``); ConfigError (one line)
        if a port cannot be had."""
        self.target.attach(routes)
        self.feed.start()
        if self.osc is not None:
            self.osc.open()
        if self._port is not None:
            self._port.open()
        if self.reply is not None:
            self.reply.start()

    def close(self) -> None:
        for part in (self.osc, self._port, self.reply):
            if part is not None:
                part.close()
        self.feed.close()

    def report(self) -> dict[str, Any]:
        midi = self.midi
        return {
            "osc": None if self.osc is None else {
                "host": self.osc.host, "port": self.osc.port,
                "datagrams": self.osc.received,
                "reply": None if self.reply is None else {
                    "to": f"{self.reply.address[0]}:{self.reply.address[1]}",
                    "sent": self.reply.sent}},
            "feed": self.feed.report(),
            "cues": [c.label for c in self.target.cues.cues],
            "midi": None if midi is None else {
                "port": self.options.midi.port if self.options.midi else None,
                "mapping": str(midi.path), "learning": midi.learning, "last": midi.last,
                "cc": [{"channel": c.channel, "cc": c.cc, "param": c.param,
                        "range": [c.lo, c.hi], "curve": c.curve} for c in midi.map.cc],
                "notes": len(midi.map.notes)}}

    def _learn(self) -> Handler:
        def learn(r: Request) -> Any:
            if self.midi is None:
                raise Refused(409, "MIDI learn needs a MIDI input: start the panel with "
                                   "--midi PORT")
            return ok({"learning": self.midi.learn(r.body.get("param")),
                       "mapping": str(self.midi.path)})
        return learn
