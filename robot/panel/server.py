"""The panel's HTTP server: a static page and JSON endpoints over a PanelController.

Endpoints (JSON in and out; errors are ``{"error": "..."}``, never an empty reply):
  GET  /api/state    loop state, timing, servos, sim metrics, stick figure
  GET  /api/params   current parameters with ranges, grouped
  GET  /api/presets  preset names
  POST /api/params   {name: value, ...} → 200 {"params": {...}} or 400 (nothing changes)
  POST /api/preset   {"name": ...} → load a preset (validated set_params of all its values)
  POST /api/save     {"name": ..., "overwrite": false} → write the current params as a user
                     preset (a bundled preset is never replaced: 409)
  POST /api/start | /api/stop | /api/estop    run, safe ramp-out, torque off at once
  POST /api/reset    simulation only, while stopped: robot back on its feet
  GET  /api/live     WebSocket (robot.panel.live): the state, parameters and studio status
                     pushed 20 times a second; the page uses it instead of polling
  GET  /api/takes | /api/sequences        recorded takes, saved keyframe sequences
  POST /api/record {"name"?} | /api/play {"name"}   record a take (ends with stop), replay
  POST /api/pose/release {"limb"} | /api/pose/capture | /api/pose/clear | /api/pose/save
       {"name"} | /api/sequence/play {"name", "layer": bool}: posing by hand (panel.studio)

Every request passes ``robot.panel.guard`` first (Host, Origin, JSON content type, body
length), the WebSocket handshake too (browsers always send Origin on it). With a token,
every /api request needs ``Authorization: Bearer <token>`` or ``?token=<token>`` (401
otherwise; a browser's WebSocket can only send the query); the page and its assets are public (they hold no
secret) and the page sends the token from its own URL with each API call. Serving beyond
loopback requires a token.
"""

from __future__ import annotations

import hmac
import json
import logging
import socket
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from typing import Any
from urllib.parse import parse_qs, urlsplit

from robot.errors import BipedError, ConfigError
from robot.panel.controller import PanelController, PanelStateError
from robot.panel.guard import WILDCARD, Guard, Refused, is_loopback, lan_address
from robot.panel.live import LiveHub
from robot.panel.presets import PresetExistsError
from robot.panel.studio import Studio

log = logging.getLogger(__name__)

STATIC = {"/": ("index.html", "text/html; charset=utf-8"),
          "/index.html": ("index.html", "text/html; charset=utf-8"),
          "/panel.js": ("panel.js", "text/javascript; charset=utf-8"),
          "/panel.css": ("panel.css", "text/css; charset=utf-8"),
          "/input.js": ("input.js", "text/javascript; charset=utf-8"),
          "/studio.js": ("studio.js", "text/javascript; charset=utf-8")}
ACTIONS = {"/api/start": "start", "/api/stop": "stop", "/api/estop": "emergency_stop",
           "/api/reset": "reset_sim"}
READ_TIMEOUT_S = 10.0  # a client that stalls mid-request is dropped after this
HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff",
           "Referrer-Policy": "no-referrer", "X-Frame-Options": "DENY",
           "Content-Security-Policy": "default-src 'self'; img-src 'self' data:; "
           "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'; base-uri 'none'; "
           "form-action 'none'"}

__all__ = ["build_server", "is_loopback", "panel_url", "serve_in_thread"]


def static_file(name: str) -> bytes:
    return resources.files("robot.panel").joinpath("static", name).read_bytes()


def live_snapshot(controller: PanelController, studio: Studio) -> dict[str, Any]:
    """What the WebSocket pushes: the state, the parameters in effect, the studio."""
    streamer = controller.streamer
    params = streamer.engine.params if controller.running and streamer is not None \
        else controller.params
    return {**controller.state(), "params": params.as_dict(), "preset": controller.preset,
            "driver": controller.driver if controller.running else None,
            "studio": studio.status()}


def build_server(controller: PanelController, *, host: str = "127.0.0.1", port: int = 0,
                 token: str | None = None, read_timeout_s: float = READ_TIMEOUT_S,
                 studio: Studio | None = None) -> ThreadingHTTPServer:
    """A ThreadingHTTPServer bound to (host, port) (port 0: ephemeral) serving the panel for
    ``controller``. Call ``serve_forever()`` (e.g. in a thread) and ``shutdown()``, then
    ``server_close()`` (which also closes the WebSockets).
    read_timeout_s: a client silent this long mid-request is answered 408 or dropped;
    studio: takes and keyframes (default: in the user's data directory)."""
    if not is_loopback(host) and not token:
        raise ConfigError(f"--host {host}: serving beyond loopback needs a token (--token)")
    guard = Guard.for_bind(host)
    room = studio or Studio(controller)
    hub = LiveHub(lambda: live_snapshot(controller, room))
    posts = _studio_posts(room)

    class Handler(BaseHTTPRequestHandler):
        server_version = "biped-panel/1"
        default_request_version = "HTTP/1.0"  # errors always get a status line and headers
        timeout = read_timeout_s

        def log_message(self, format: str, *args: Any) -> None:  # noqa: A002
            log.debug("%s " + format, self.address_string(), *args)

        def _authorised(self, query: dict[str, list[str]]) -> bool:
            if not token:
                return True
            given = query.get("token", [""])[0]
            auth = self.headers.get("Authorization", "")
            if auth.startswith("Bearer "):
                given = auth[len("Bearer "):].strip()
            return hmac.compare_digest(given.encode(), token.encode())

        def _send(self, status: int, body: bytes, ctype: str) -> None:
            self.send_response(status)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            for k, v in HEADERS.items():
                self.send_header(k, v)
            if self.close_connection:
                self.send_header("Connection", "close")
            self.end_headers()
            if self.command != "HEAD":
                self.wfile.write(body)

        def _json(self, status: int, obj: Any) -> None:
            self._send(status, json.dumps(obj).encode(), "application/json")

        def send_error(self, code: int, message: str | None = None,
                       explain: str | None = None) -> None:
            """The base class's errors (bad request line, unknown method...) as JSON."""
            self.close_connection = True
            self._json(code, {"error": message or HTTPStatus(code).phrase})

        def _check(self, method: str, url: Any) -> None:
            """Host, Origin and token for every request; content type for POST."""
            host = self.headers.get("Host")
            guard.check_host(host, str(self.connection.getsockname()[0]))
            guard.check_origin(self.headers.get("Origin"), host or "")
            if url.path.startswith("/api/") and not self._authorised(parse_qs(url.query)):
                raise Refused(HTTPStatus.UNAUTHORIZED, "missing or wrong token; use "
                              "Authorization: Bearer <token> or ?token=<token>")
            if method == "POST":
                guard.check_content_type(self.headers.get("Content-Type"))

        def _route(self, method: str) -> None:
            try:
                url = urlsplit(self.path)
                self._check(method, url)
                if method == "GET":
                    self._get(url.path)
                else:
                    self._post(url.path, self._body())
            except Refused as e:
                self.close_connection = True  # an unread body must not be parsed as a request
                self._json(e.status, {"error": str(e)})
            except (PresetExistsError, PanelStateError) as e:
                self._json(HTTPStatus.CONFLICT, {"error": str(e)})
            except BipedError as e:
                self._json(HTTPStatus.BAD_REQUEST, {"error": str(e)})
            except TimeoutError:
                self.close_connection = True
                self._json(HTTPStatus.REQUEST_TIMEOUT,
                           {"error": f"request body not received within {read_timeout_s:g} s"})
            except ConnectionError:
                raise  # the client went away: nothing to answer (handle_error logs it)
            except Exception as e:  # a bug: answer, and keep serving
                log.error("panel: %s %s failed: %s: %s", method, self.path, type(e).__name__, e,
                          exc_info=log.isEnabledFor(logging.DEBUG))
                self.close_connection = True
                self._json(HTTPStatus.INTERNAL_SERVER_ERROR,
                           {"error": f"internal error: {type(e).__name__}: {e}"})

        def _body(self) -> dict[str, Any]:
            cl = self.headers.get_all("Content-Length")
            n = guard.body_length(", ".join(cl) if cl else None,
                                  self.headers.get("Transfer-Encoding"))
            raw = self.rfile.read(n) if n else b""
            if len(raw) < n:
                raise Refused(HTTPStatus.BAD_REQUEST,
                              f"request body ended after {len(raw)} of {n} bytes")
            try:
                body = json.loads(raw or b"{}")
            except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as e:
                raise ConfigError(f"request body is not JSON: {e}") from None
            if not isinstance(body, dict):
                raise ConfigError("request body must be a JSON object")
            return body

        def _get(self, path: str) -> None:
            c = controller
            if path in STATIC:
                name, ctype = STATIC[path]
                self._send(HTTPStatus.OK, static_file(name), ctype)
            elif path == "/api/state":
                self._json(HTTPStatus.OK, c.state())
            elif path == "/api/params":
                self._json(HTTPStatus.OK, c.describe())
            elif path == "/api/presets":
                self._json(HTTPStatus.OK, {"presets": c.presets.names()})
            elif path == "/api/live":
                self._upgrade()
            elif path == "/api/takes":
                self._json(HTTPStatus.OK, {"takes": room.takes(), "dir": str(room.takes_dir)})
            elif path == "/api/sequences":
                self._json(HTTPStatus.OK, {"sequences": room.sequences(),
                                           "dir": str(room.keys_dir), **room.status()})
            else:
                self._json(HTTPStatus.NOT_FOUND, {"error": f"no such page: {path}"})

        def _upgrade(self) -> None:
            """Hand the connection to the live hub (a WebSocket handshake), or refuse."""
            if self.headers.get("Upgrade", "").lower() != "websocket":
                raise Refused(HTTPStatus.BAD_REQUEST, "/api/live is a WebSocket: send "
                              "Upgrade: websocket")
            if hub.full():
                raise Refused(HTTPStatus.SERVICE_UNAVAILABLE, f"{hub.max_clients} live "
                              "clients already; close one")
            self.close_connection = True
            hub.serve(self.connection, self.requestline, list(self.headers.items()))

        def _post(self, path: str, body: dict[str, Any]) -> None:
            c = controller
            if path in posts:
                self._json(HTTPStatus.OK, {"ok": True, **posts[path](body),
                                           "studio": room.status()})
                return
            if path == "/api/params":
                self._json(HTTPStatus.OK, {"params": c.set_params(body).as_dict()})
            elif path == "/api/preset":
                name = body.get("name")
                params = c.load_preset(name)
                self._json(HTTPStatus.OK, {"preset": name, "params": params.as_dict()})
            elif path == "/api/save":
                saved = c.save_preset(body.get("name"), overwrite=body.get("overwrite") is True)
                self._json(HTTPStatus.OK, {"saved": saved, "presets": c.presets.names()})
            elif path in ACTIONS:
                action = getattr(c, ACTIONS[path])
                action()
                self._json(HTTPStatus.OK, {"ok": True, "state": c.state()["state"]})
            else:
                self._json(HTTPStatus.NOT_FOUND, {"error": f"no such endpoint: {path}"})

        def do_GET(self) -> None:
            self._route("GET")

        def do_POST(self) -> None:
            self._route("POST")

    server_class = _Server6 if ":" in host else _Server
    server = server_class((host, port), Handler)
    server.hub = hub
    return server


def _studio_posts(room: Studio) -> dict[str, Any]:
    """POST path → handler(body) → reply fields, for the studio's actions."""
    return {
        "/api/record": lambda b: {"take": room.record(b.get("name"))},
        "/api/play": lambda b: room.play(b.get("name")),
        "/api/pose/release": lambda b: room.release(b.get("limb")),
        "/api/pose/capture": lambda b: room.capture(b.get("t")),
        "/api/pose/clear": lambda b: room.clear(),
        "/api/pose/save": lambda b: {"saved": room.save(b.get("name")),
                                     "sequences": room.sequences()},
        "/api/sequence/play": lambda b: room.play_sequence(b.get("name"),
                                                           layer=b.get("layer") is True),
    }


def serve_in_thread(server: ThreadingHTTPServer) -> tuple[threading.Thread, str]:
    """Run ``server.serve_forever`` in a daemon thread; returns it and a base URL for this
    machine (loopback when serving on every address)."""
    host, port = str(server.server_address[0]), int(server.server_address[1])
    if host in WILDCARD:
        host = "127.0.0.1" if host == "0.0.0.0" else "::1"
    thread = threading.Thread(target=server.serve_forever, name="panel-http", daemon=True)
    thread.start()
    return thread, base_url(host, port)


def base_url(host: str, port: int) -> str:
    return f"http://[{host}]:{port}/" if ":" in host else f"http://{host}:{port}/"


def panel_url(host: str, port: int) -> str:
    """The URL another device (a phone) opens: on every address (0.0.0.0, ::), this
    machine's LAN address (loopback if it has none); else ``host`` itself."""
    if host in WILDCARD:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        found = lan_address(family)
        if found is None:
            log.warning("no LAN address found; the panel URL uses loopback")
        host = found or ("::1" if family == socket.AF_INET6 else "127.0.0.1")
    return base_url(host, port)


class _Server(ThreadingHTTPServer):
    daemon_threads = True
    hub: LiveHub | None = None

    def server_close(self) -> None:
        if self.hub is not None:
            self.hub.close()
        super().server_close()

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A failed connection is one log line, never a traceback on stderr."""
        exc = sys.exc_info()[1]
        level = logging.DEBUG if isinstance(exc, (ConnectionError, TimeoutError)) \
            else logging.WARNING
        log.log(level, "panel: connection from %s failed: %s: %s", client_address[0],
                type(exc).__name__, exc)


class _Server6(_Server):
    address_family = socket.AF_INET6
