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
  GET  /api/showctl | POST /api/midi/learn {"param"}   show control, with --osc or --midi
                     (robot.panel.show_control)

The endpoints are a table (``robot.panel.routes``); this module is the HTTP plumbing
around it: the server (its connection caps and deadlines, robot.panel.admission) and one
connection (robot.panel.handler). Every request passes ``robot.panel.guard`` there, once,
before its route is looked up (Host, Origin, token, JSON content type, body length), the
WebSocket handshake too (browsers always send Origin on it). With a token, every /api
request needs ``Authorization: Bearer <token>`` or ``?token=<token>`` (401 otherwise; a
browser's WebSocket can only send the query); the page and its assets are public (they
hold no secret) and the page sends the token from its own URL with each API call.
Serving beyond loopback requires a token.
"""

from __future__ import annotations

import logging
import socket
import sys
import threading
import time
from http.server import ThreadingHTTPServer
from typing import Any

from robot.errors import ConfigError
from robot.panel.admission import HEAD_TIMEOUT_S, Admission
from robot.panel.controller import PanelController
from robot.panel.guard import WILDCARD, Guard, is_loopback, lan_address
from robot.panel.handler import Handler
from robot.panel.live import LiveHub
from robot.panel.routes import Routes, live_snapshot, route_table
from robot.panel.studio import Studio

log = logging.getLogger(__name__)

READ_TIMEOUT_S = 10.0  # a body that stalls after its headers is answered 408 after this

__all__ = ["PanelServer", "build_server", "is_loopback", "panel_url", "serve_in_thread"]


class PanelServer(ThreadingHTTPServer):
    """The panel on one address: its guard, its route table, its live hub (closed with
    the server), its connection caps and deadlines (robot.panel.admission), and how long
    a client may stall mid-body [s]. Every connection is stamped when it is accepted
    (``Request.received``): the order of requests against an e-stop."""

    daemon_threads = True
    request_queue_size = 128

    def __init__(self, address: tuple[str, int], *, guard: Guard, routes: Routes,
                 hub: LiveHub, read_timeout_s: float = READ_TIMEOUT_S,
                 head_timeout_s: float = HEAD_TIMEOUT_S,
                 admission: Admission | None = None) -> None:
        self.guard = guard
        self.routes = routes
        self.hub = hub
        self.read_timeout_s = read_timeout_s
        self.head_timeout_s = head_timeout_s
        self.admission = admission or Admission()
        if ":" in address[0]:
            self.address_family = socket.AF_INET6
        super().__init__(address, Handler)

    def verify_request(self, request: Any, client_address: Any) -> bool:
        """Over a cap: closed at once, no thread made for it."""
        return self.admission.admit(str(client_address[0]))

    def process_request(self, request: Any, client_address: Any) -> None:
        received = time.monotonic()
        thread = threading.Thread(target=self._serve_connection,
                                  args=(request, client_address, received), daemon=True)
        try:
            thread.start()
        except RuntimeError:           # no thread to be had: drop the connection
            self.admission.leave(str(client_address[0]))
            self.shutdown_request(request)

    def _serve_connection(self, request: Any, client_address: Any, received: float) -> None:
        counted = [True]  # until it becomes a WebSocket (the live hub counts those)
        try:
            Handler(request, client_address, self, received=received, counted=counted)
        except Exception:
            self.handle_error(request, client_address)
        finally:
            self.shutdown_request(request)
            if counted[0]:
                self.admission.leave(str(client_address[0]))

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


def build_server(controller: PanelController, *, host: str = "127.0.0.1", port: int = 0,
                 token: str | None = None, read_timeout_s: float = READ_TIMEOUT_S,
                 head_timeout_s: float = HEAD_TIMEOUT_S, admission: Admission | None = None,
                 studio: Studio | None = None, more_routes: Routes | None = None
                 ) -> PanelServer:
    """A PanelServer bound to (host, port) (port 0: ephemeral) serving the panel for
    ``controller``. Call ``serve_forever()`` (e.g. in a thread) and ``shutdown()``, then
    ``server_close()`` (which also closes the WebSockets).
    read_timeout_s: a body not received this long after its headers is answered 408;
    head_timeout_s: a request line and headers not received this long after the accept
    drop the connection; admission: the connection caps (robot.panel.admission);
    studio: takes and keyframes (default: in the user's data directory);
    more_routes: endpoints beyond the panel's own (show control's)."""
    if not is_loopback(host) and not token:
        raise ConfigError(f"--host {host}: serving beyond loopback needs a token (--token)")
    room = studio or Studio(controller)
    hub = LiveHub(lambda: live_snapshot(controller, room))
    return PanelServer((host, port), guard=Guard.for_bind(host, token=token),
                       routes={**route_table(controller, room, hub), **(more_routes or {})},
                       hub=hub,
                       read_timeout_s=read_timeout_s, head_timeout_s=head_timeout_s,
                       admission=admission)


def serve_in_thread(server: ThreadingHTTPServer) -> tuple[threading.Thread, str]:
    """Run ``server.serve_forever`` in a daemon thread; returns it and a base URL for this
    machine (loopback when serving on every address)."""
    host, port = str(server.server_address[0]), int(server.server_address[1])
    if host in WILDCARD:
        host = "127.0.0.1" if host == "0.0.0.0" else "::1"
    thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.1},
                              name="panel-http", daemon=True)
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
