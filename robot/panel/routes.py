"""The panel's endpoints as a table: (method, path) → a small handler.

A handler takes a :class:`Request` (already admitted by the guard, its JSON body parsed)
and returns a :class:`Response` or an :class:`Upgrade` (hand the connection to the live
hub). Handlers never see sockets or headers they do not need, and none of them checks
Host, Origin, token or content type: ``robot.panel.server`` does that once, through
``robot.panel.guard``, before it looks a route up. Errors are raised, not returned:
``Refused`` (its status), ``PresetExistsError`` / ``PanelStateError`` (409), any other
``BipedError`` (400); the server turns them into ``{"error": "..."}``.
"""

from __future__ import annotations

import json
import socket
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from http import HTTPStatus
from importlib import resources
from typing import Any

from robot.panel.controller import PanelController
from robot.panel.guard import Refused
from robot.panel.live import LiveHub
from robot.panel.studio import Studio

#: A JSON object as the client sent it.
Body = Mapping[str, object]

_HTML, _JS = "text/html; charset=utf-8", "text/javascript; charset=utf-8"
#: URL path → (file in robot/panel/static/, Content-Type).
STATIC = {"/": ("index.html", _HTML), "/index.html": ("index.html", _HTML),
          "/panel.js": ("panel.js", _JS), "/panel.css": ("panel.css", "text/css; charset=utf-8"),
          "/input.js": ("input.js", _JS), "/studio.js": ("studio.js", _JS),
          "/midi.js": ("midi.js", _JS)}


@dataclass(frozen=True)
class Request:
    """One admitted request: ``headers`` by lowercase name (the first of repeats);
    ``received``: when it arrived (its connection was accepted) [s, time.monotonic]."""

    method: str
    path: str
    query: Mapping[str, list[str]] = field(default_factory=dict)
    headers: Mapping[str, str] = field(default_factory=dict)
    body: Body = field(default_factory=dict)
    received: float = field(default_factory=time.monotonic)


@dataclass(frozen=True)
class Response:
    """``headers``: more response headers (the audio route's byte ranges)."""

    status: int
    body: bytes
    content_type: str
    headers: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class Upgrade:
    """Hand the connection over: ``accept(sock, request_line, headers)`` serves it."""

    accept: Callable[[socket.socket, str, list[tuple[str, str]]], None]


Reply = Response | Upgrade
Handler = Callable[[Request], Reply]
Routes = Mapping[tuple[str, str], Handler]


def json_response(status: int, obj: Mapping[str, object]) -> Response:
    return Response(int(status), json.dumps(obj).encode(), "application/json")


def ok(obj: Mapping[str, object]) -> Response:
    return json_response(HTTPStatus.OK, obj)


def dispatch(routes: Routes, request: Request) -> Reply:
    """The route's reply, or 404 naming the path."""
    handler = routes.get((request.method, request.path))
    if handler is not None:
        return handler(request)
    what = "page" if request.method == "GET" else "endpoint"
    return json_response(HTTPStatus.NOT_FOUND, {"error": f"no such {what}: {request.path}"})


def static_file(name: str) -> bytes:
    """A file of robot/panel/static/ (package data)."""
    return resources.files("robot.panel").joinpath("static", name).read_bytes()


def live_snapshot(controller: PanelController, studio: Studio) -> dict[str, Any]:
    """What the WebSocket pushes: the state, the parameters in effect, the studio."""
    return {**controller.state(), "params": controller.live_params().as_dict(),
            "preset": controller.preset, "driver": controller.driver,
            "studio": studio.status()}


def _static(name: str, ctype: str) -> Handler:
    return lambda _: Response(HTTPStatus.OK, static_file(name), ctype)


def _live(hub: LiveHub) -> Handler:
    def live(request: Request) -> Reply:
        if request.headers.get("upgrade", "").lower() != "websocket":
            raise Refused(HTTPStatus.BAD_REQUEST, "/api/live is a WebSocket: send "
                          "Upgrade: websocket")
        if hub.full():
            raise Refused(HTTPStatus.SERVICE_UNAVAILABLE, f"{hub.max_clients} live "
                          "clients already; close one")
        return Upgrade(hub.serve)
    return live


def _action(controller: PanelController, act: Callable[[Request], object]) -> Handler:
    """start / stop / estop / reset: run it, answer the state it left."""
    def action(request: Request) -> Reply:
        act(request)
        return ok({"ok": True, "state": controller.state()["state"]})
    return action


def _studio(studio: Studio, act: Callable[[Request], Mapping[str, object]]) -> Handler:
    """A studio action: its reply fields, with ok and the studio's status."""
    return lambda r: ok({"ok": True, **act(r), "studio": studio.status()})


def _panel_routes(c: PanelController) -> dict[tuple[str, str], Handler]:
    def set_params(r: Request) -> Reply:
        return ok({"params": c.set_params(r.body).as_dict()})

    def load_preset(r: Request) -> Reply:
        name = r.body.get("name")
        return ok({"preset": name, "params": c.load_preset(name).as_dict()})

    def save_preset(r: Request) -> Reply:
        saved = c.save_preset(r.body.get("name"), overwrite=r.body.get("overwrite") is True)
        return ok({"saved": saved, "presets": c.presets.names()})

    def estop(r: Request) -> Reply:
        """Answered once torque off has been sent; ``failed``: what the bus refused."""
        failed = c.emergency_stop(received=r.received)
        return ok({"ok": not failed, "state": "estop", "failed": failed})

    return {
        ("GET", "/api/state"): lambda _: ok(c.state()),
        ("GET", "/api/params"): lambda _: ok(c.describe()),
        ("GET", "/api/presets"): lambda _: ok({"presets": c.presets.names()}),
        ("POST", "/api/params"): set_params,
        ("POST", "/api/preset"): load_preset,
        ("POST", "/api/save"): save_preset,
        ("POST", "/api/start"): _action(c, lambda r: c.start(received=r.received)),
        ("POST", "/api/stop"): _action(c, lambda r: c.stop()),
        ("POST", "/api/estop"): estop,
        ("POST", "/api/reset"): _action(c, lambda r: c.reset_sim(received=r.received)),
    }


#: Sound files the page's <audio> plays, by suffix.
AUDIO = {".wav": "audio/wav", ".mp3": "audio/mpeg", ".ogg": "audio/ogg", ".oga": "audio/ogg",
         ".flac": "audio/flac", ".m4a": "audio/mp4"}


def byte_range(data: bytes, kind: str, asked: str) -> Response:
    """``data`` whole, or the one range ``bytes=a-b`` asked (206): a media element seeks
    only in a file served with byte ranges (RFC 9110 section 14)."""
    ranges = {"Accept-Ranges": "bytes"}
    unit, _, spec = asked.partition("=")
    first, dash, last = spec.partition("-")
    if unit.strip() != "bytes" or not dash or "," in spec or not (first or last).isdigit():
        return Response(HTTPStatus.OK, data, kind, ranges)
    n = len(data)
    lo, hi = (int(first), int(last) if last.isdigit() else n - 1) if first.isdigit() \
        else (max(0, n - int(last)), n - 1)
    if lo >= n or lo > hi:
        return Response(HTTPStatus.REQUESTED_RANGE_NOT_SATISFIABLE, b"", kind,
                        {**ranges, "Content-Range": f"bytes */{n}"})
    hi = min(hi, n - 1)
    return Response(HTTPStatus.PARTIAL_CONTENT, data[lo:hi + 1], kind,
                    {**ranges, "Content-Range": f"bytes {lo}-{hi}/{n}"})


def _studio_routes(s: Studio) -> dict[tuple[str, str], Handler]:
    def sequences(_: Request) -> Reply:
        return ok({"sequences": s.sequences(), "dir": str(s.keys_dir), **s.status()})

    def audio(r: Request) -> Reply:
        """A take's soundtrack, for the page's <audio> (the browser plays the sound)."""
        path = s.audio_file(r.query.get("take", [""])[0])
        kind = AUDIO.get(path.suffix.lower())
        if kind is None:
            raise Refused(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, f"{path.name}: not a sound file "
                          f"the page plays ({', '.join(AUDIO)})")
        return byte_range(path.read_bytes(), kind, r.headers.get("range", ""))

    return {
        ("GET", "/api/takes"): lambda _: ok({"takes": s.takes(), "dir": str(s.takes_dir)}),
        ("GET", "/api/sequences"): sequences,
        ("GET", "/api/show/audio"): audio,
        ("POST", "/api/record"): _studio(s, lambda r: {
            "take": s.record(r.body.get("name"), received=r.received)}),
        ("POST", "/api/play"): _studio(s, lambda r: s.play(r.body.get("name"),
                                                         received=r.received)),
        ("POST", "/api/pose/release"): _studio(s, lambda r: s.release(
            r.body.get("limb"), received=r.received)),
        ("POST", "/api/pose/capture"): _studio(s, lambda r: s.capture(
            r.body.get("t"), received=r.received)),
        ("POST", "/api/pose/clear"): _studio(s, lambda _: s.clear()),
        ("POST", "/api/pose/save"): _studio(s, lambda r: {"saved": s.save(r.body.get("name")),
                                                          "sequences": s.sequences()}),
        ("POST", "/api/sequence/play"): _studio(s, lambda r: s.play_sequence(
            r.body.get("name"), layer=r.body.get("layer") is True, received=r.received)),
    }


def route_table(controller: PanelController, studio: Studio, hub: LiveHub) -> Routes:
    """Every endpoint of the panel: the page and its assets, the API, the live socket."""
    static = {("GET", path): _static(name, ctype) for path, (name, ctype) in STATIC.items()}
    return {**static, **_panel_routes(controller), **_studio_routes(studio),
            ("GET", "/api/live"): _live(hub)}
