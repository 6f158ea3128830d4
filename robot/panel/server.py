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
  GET  /api/show/audio?take=NAME          a show take's soundtrack (byte ranges: the page seeks)
  POST /api/record {"name"?} | /api/play {"name"}   record a take (ends with stop), replay
  POST /api/pose/release {"limb"} | /api/pose/capture | /api/pose/clear | /api/pose/save
       {"name"} | /api/sequence/play {"name", "layer": bool}: posing by hand (panel.studio)

The endpoints are a table (``robot.panel.routes``); this module is the HTTP plumbing
around it. Every request passes ``robot.panel.guard`` here, once, before its route is
looked up (Host, Origin, token, JSON content type, body length), the WebSocket handshake
too (browsers always send Origin on it). With a token, every /api request needs
``Authorization: Bearer <token>`` or ``?token=<token>`` (401 otherwise; a browser's
WebSocket can only send the query); the page and its assets are public (they hold no
secret) and the page sends the token from its own URL with each API call. Serving beyond
loopback requires a token.
"""

from __future__ import annotations

import json
import logging
import socket
import sys
import threading
from dataclasses import replace
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, urlsplit

from robot.errors import BipedError, ConfigError
from robot.panel.controller import PanelController, PanelStateError
from robot.panel.guard import WILDCARD, Guard, Refused, is_loopback, lan_address
from robot.panel.live import LiveHub
from robot.panel.presets import PresetExistsError
from robot.panel.routes import (
    Body,
    Request,
    Response,
    Routes,
    Upgrade,
    dispatch,
    json_response,
    live_snapshot,
    route_table,
)
from robot.panel.studio import Studio

log = logging.getLogger(__name__)

READ_TIMEOUT_S = 10.0  # a client that stalls mid-request is dropped after this
HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff",
           "Referrer-Policy": "no-referrer", "X-Frame-Options": "DENY",
           "Content-Security-Policy": "default-src 'self'; img-src 'self' data:; "
           "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'; base-uri 'none'; "
           "form-action 'none'"}

__all__ = ["PanelServer", "build_server", "is_loopback", "panel_url", "serve_in_thread"]


class PanelServer(ThreadingHTTPServer):
    """The panel on one address: its guard, its route table, its live hub (closed with
    the server), and how long a client may stall mid-request [s]."""

    daemon_threads = True

    def __init__(self, address: tuple[str, int], *, guard: Guard, routes: Routes,
                 hub: LiveHub, read_timeout_s: float = READ_TIMEOUT_S) -> None:
        self.guard = guard
        self.routes = routes
        self.hub = hub
        self.read_timeout_s = read_timeout_s
        if ":" in address[0]:
            self.address_family = socket.AF_INET6
        super().__init__(address, _Handler)

    def server_close(self) -> None:
        self.hub.close()
        super().server_close()

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A failed connection is one log line, never a traceback on stderr."""
        exc = sys.exc_info()[1]
        level = logging.DEBUG if isinstance(exc, (ConnectionError, TimeoutError)) \
            else logging.WARNING
        log.log(level, "panel: connection from %s failed: %s: %s", client_address[0],
                type(exc).__name__, exc)


class _Handler(BaseHTTPRequestHandler):
    """One connection: parse, admit (the guard), read the body, dispatch, answer."""

    server: PanelServer
    server_version = "biped-panel/1"
    default_request_version = "HTTP/1.0"  # errors always get a status line and headers

    def setup(self) -> None:
        super().setup()
        self.connection.settimeout(self.server.read_timeout_s)

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002
        log.debug("%s " + format, self.address_string(), *args)

    def do_GET(self) -> None:
        self._serve("GET")

    def do_POST(self) -> None:
        self._serve("POST")

    def send_error(self, code: int, message: str | None = None,
                   explain: str | None = None) -> None:
        """The base class's errors (bad request line, unknown method...) as JSON."""
        self.close_connection = True
        self._answer(json_response(code, {"error": message or HTTPStatus(code).phrase}))

    def _serve(self, method: str) -> None:
        try:
            request = self._admitted(method)
            if method == "POST":
                request = replace(request, body=self._body())
            reply = dispatch(self.server.routes, request)
            if isinstance(reply, Upgrade):
                self.close_connection = True
                reply.accept(self.connection, self.requestline, list(self.headers.items()))
            else:
                self._answer(reply)
        except ConnectionError:
            raise  # the client went away: nothing to answer (handle_error logs it)
        except Exception as e:
            self._answer(self._failure(method, e))

    def _admitted(self, method: str) -> Request:
        """The request, once the guard has let it through (else Refused)."""
        url = urlsplit(self.path)
        headers: dict[str, str] = {}
        for k, v in self.headers.items():
            headers.setdefault(k.lower(), v)
        request = Request(method, url.path, parse_qs(url.query), headers)
        self.server.guard.admit(method, request.path, request.query, headers,
                                str(self.connection.getsockname()[0]))
        return request

    def _failure(self, method: str, e: Exception) -> Response:
        """The JSON answer to what a request raised (closing the connection when the
        rest of it cannot be trusted to be a request)."""
        if isinstance(e, Refused):
            self.close_connection = True  # an unread body must not be parsed as a request
            return json_response(e.status, {"error": str(e)})
        if isinstance(e, (PresetExistsError, PanelStateError)):
            return json_response(HTTPStatus.CONFLICT, {"error": str(e)})
        if isinstance(e, BipedError):
            return json_response(HTTPStatus.BAD_REQUEST, {"error": str(e)})
        self.close_connection = True
        if isinstance(e, TimeoutError):
            return json_response(HTTPStatus.REQUEST_TIMEOUT, {
                "error": f"request body not received within {self.server.read_timeout_s:g} s"})
        log.error("panel: %s %s failed: %s: %s", method, self.path, type(e).__name__, e,
                  exc_info=log.isEnabledFor(logging.DEBUG))  # a bug: answer, keep serving
        return json_response(HTTPStatus.INTERNAL_SERVER_ERROR,
                             {"error": f"internal error: {type(e).__name__}: {e}"})

    def _body(self) -> Body:
        cl = self.headers.get_all("Content-Length")
        n = self.server.guard.body_length(", ".join(cl) if cl else None,
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

    def _answer(self, response: Response) -> None:
        self.send_response(response.status)
        self.send_header("Content-Type", response.content_type)
        self.send_header("Content-Length", str(len(response.body)))
        for k, v in {**HEADERS, **response.headers}.items():
            self.send_header(k, v)
        if self.close_connection:
            self.send_header("Connection", "close")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(response.body)


def build_server(controller: PanelController, *, host: str = "127.0.0.1", port: int = 0,
                 token: str | None = None, read_timeout_s: float = READ_TIMEOUT_S,
                 studio: Studio | None = None) -> PanelServer:
    """A PanelServer bound to (host, port) (port 0: ephemeral) serving the panel for
    ``controller``. Call ``serve_forever()`` (e.g. in a thread) and ``shutdown()``, then
    ``server_close()`` (which also closes the WebSockets).
    read_timeout_s: a client silent this long mid-request is answered 408 or dropped;
    studio: takes and keyframes (default: in the user's data directory)."""
    if not is_loopback(host) and not token:
        raise ConfigError(f"--host {host}: serving beyond loopback needs a token (--token)")
    room = studio or Studio(controller)
    hub = LiveHub(lambda: live_snapshot(controller, room))
    return PanelServer((host, port), guard=Guard.for_bind(host, token=token),
                       routes=route_table(controller, room, hub), hub=hub,
                       read_timeout_s=read_timeout_s)


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
