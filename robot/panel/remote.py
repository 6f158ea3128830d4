"""Show control on the panel: OSC and MIDI actions (robot.showctl) enter through the
panel's own route table, as the page's requests do, so they are validated, rate-limited,
ordered against an e-stop and refused exactly as a slider, a button or the e-stop of the
page are (robot.panel.routes → controller → the loop process). Only the HTTP guard (Host,
Origin, token) is not theirs: OSC has no such headers, and its sources are checked by the
listener's allow-list instead (robot.showctl.sources).

A refusal (409 a take is playing, 400 no such preset...) is logged once per kind of
refusal, as a wrong OSC message is.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from http import HTTPStatus
from typing import Any

from robot.errors import BipedError
from robot.panel.controller import PanelController
from robot.panel.guard import Refused
from robot.panel.loop_process import LoopUnavailable
from robot.panel.options import PanelStateError
from robot.panel.presets import PresetExistsError
from robot.panel.routes import Request, Response, Routes, dispatch
from robot.showctl.actions import Command, Named
from robot.showctl.cues import CueList
from robot.showctl.once import OnceLog
from robot.showctl.osc_out import Status

log = logging.getLogger(__name__)

#: Named actions → (route, the body's key for the name).
NAMED_ROUTES = {"preset": "/api/preset", "take": "/api/play", "record": "/api/record",
                "pose": "/api/sequence/play"}
COMMAND_ROUTES = {"start": "/api/start", "stop": "/api/stop", "take stop": "/api/stop"}


def _status(e: Exception) -> int:
    if isinstance(e, Refused):
        return e.status
    if isinstance(e, (PresetExistsError, PanelStateError)):
        return HTTPStatus.CONFLICT
    if isinstance(e, LoopUnavailable):
        return HTTPStatus.SERVICE_UNAVAILABLE
    return HTTPStatus.BAD_REQUEST


class PanelTarget:
    """The feed's target on a panel: actions → POSTs through ``routes`` (``attach`` them
    once the server has them); ``cues``: the cue list."""

    def __init__(self, controller: PanelController, *, cues: CueList | None = None,
                 once: OnceLog | None = None) -> None:
        self.controller = controller
        self.cues = cues or CueList()
        self.once = once or OnceLog(log)
        self._routes: Routes = {}

    def attach(self, routes: Routes) -> None:
        self._routes = routes

    # -- the feed's target ---------------------------------------------------------------
    def params(self, changes: Mapping[str, float], received: float) -> None:
        self._post("/api/params", dict(changes), received)

    def estop(self, received: float) -> None:
        self._post("/api/estop", {}, received)

    def act(self, action: Command | Named, received: float) -> None:
        if isinstance(action, Command):
            if action.what == "go":
                cue = self.cues.go()
                if cue is None:
                    self.once.note("go past the end", f"GO: no cue after the last one fired "
                                   f"in {self.cues.source}")
                else:
                    log.info("cue %s (GO)", cue.label)
                    self.act(cue.action, received)
            elif action.what == "estop":
                self.estop(received)
            elif action.what == "take stop" and not self._take_running():
                self.once.note("take stop idle", "take stop: no take is recording or playing")
            else:
                self._post(COMMAND_ROUTES[action.what], {}, received)
            return
        if action.what == "cue":
            cue = self.cues.find(action.name or "")
            if cue is None:
                self.once.note("cue unknown", f"cue {action.name!r}: not in the cue list; "
                               f"valid: {self.cues.names()}")
                return
            log.info("cue %s", cue.label)
            self.act(cue.action, received)
            return
        body: dict[str, Any] = {} if action.name is None else {"name": action.name}
        if action.what == "pose":
            body["layer"] = action.layer
        self._post(NAMED_ROUTES[action.what], body, received)

    # -- status out ----------------------------------------------------------------------
    def status(self) -> Status:
        """What ``--osc-reply`` sends (robot.showctl.osc_out)."""
        s = self.controller.state()
        loop = self.controller.loop_state()
        playing = loop.get("playing")
        show = loop.get("show") if playing else None
        return Status(state=str(s["state"]), fault=s.get("fault"),
                      show_t=show.get("t") if show else None,
                      take=playing or loop.get("recording"),
                      joints=tuple(zip(s.get("joints", []), s.get("q_cmd") or [],
                                       strict=False)))

    # -- the route table -----------------------------------------------------------------
    def _take_running(self) -> bool:
        s = self.controller.loop_state()
        return bool(s.get("running") and (s.get("recording") or s.get("playing")))

    def _post(self, path: str, body: dict[str, Any], received: float) -> None:
        request = Request("POST", path, body=body, received=received)
        try:
            reply = dispatch(self._routes, request)
        except BipedError as e:
            self.once.note(f"refused {path} {_status(e)}", f"show control: {path} refused "
                           f"({_status(e)}): {e}")
            return
        except Refused as e:
            self.once.note(f"refused {path} {e.status}", f"show control: {path} refused "
                           f"({e.status}): {e}")
            return
        if isinstance(reply, Response) and reply.status >= 400:
            why = json.loads(reply.body or b"{}").get("error", "")
            self.once.note(f"refused {path} {reply.status}", f"show control: {path} "
                           f"refused ({reply.status}): {why}")
