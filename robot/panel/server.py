"""The panel's HTTP server: a static page and JSON endpoints over a PanelController.

Endpoints (JSON in and out; errors are ``{"error": "..."}``):
  GET  /api/state    loop state, timing, servos, sim metrics, stick figure
  GET  /api/params   current parameters with ranges, grouped
  GET  /api/presets  preset names
  POST /api/params   {name: value, ...} → 200 {"params": {...}} or 400 (nothing changes)
  POST /api/preset   {"name": ...} → load a preset (validated set_params of all its values)
  POST /api/save     {"name": ..., "overwrite": false} → write the current params as TOML
  POST /api/start | /api/stop | /api/estop    run, safe ramp-out, torque off at once
  POST /api/reset    simulation only, while stopped: robot back on its feet

With a token, every request needs ``Authorization: Bearer <token>`` or ``?token=<token>``
(401 otherwise). Serving beyond loopback requires a token.
"""

from __future__ import annotations

import hmac
import json
import logging
import socket
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from typing import Any
from urllib.parse import parse_qs, urlsplit

from robot.errors import BipedError, ConfigError
from robot.panel.controller import PanelController, PanelStateError
from robot.panel.presets import PresetExistsError

log = logging.getLogger(__name__)

LOOPBACK = ("127.0.0.1", "localhost", "::1")
STATIC = {"/": ("index.html", "text/html; charset=utf-8"),
          "/index.html": ("index.html", "text/html; charset=utf-8"),
          "/panel.js": ("panel.js", "text/javascript; charset=utf-8"),
          "/panel.css": ("panel.css", "text/css; charset=utf-8")}
ACTIONS = {"/api/start": "start", "/api/stop": "stop", "/api/estop": "emergency_stop",
           "/api/reset": "reset_sim"}
MAX_BODY = 64 * 1024  # [bytes]


def is_loopback(host: str) -> bool:
    return host in LOOPBACK


def static_file(name: str) -> bytes:
    return resources.files("robot").joinpath("panel_static", name).read_bytes()


def build_server(controller: PanelController, *, host: str = "127.0.0.1", port: int = 0,
                 token: str | None = None) -> ThreadingHTTPServer:
    """A ThreadingHTTPServer bound to (host, port) (port 0: ephemeral) serving the panel for
    ``controller``. Call ``serve_forever()`` (e.g. in a thread) and ``shutdown()``."""
    if not is_loopback(host) and not token:
        raise ConfigError(f"--host {host}: serving beyond loopback needs a token (--token)")

    class Handler(BaseHTTPRequestHandler):
        server_version = "biped-panel/1"

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
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def _json(self, status: int, obj: Any) -> None:
            self._send(status, json.dumps(obj).encode(), "application/json")

        def _route(self, method: str) -> None:
            url = urlsplit(self.path)
            if not self._authorised(parse_qs(url.query)):
                self._json(HTTPStatus.UNAUTHORIZED, {"error": "missing or wrong token; use "
                           "Authorization: Bearer <token> or ?token=<token>"})
                return
            try:
                if method == "GET":
                    self._get(url.path)
                else:
                    self._post(url.path, self._body())
            except PresetExistsError as e:
                self._json(HTTPStatus.CONFLICT, {"error": str(e)})
            except PanelStateError as e:
                self._json(HTTPStatus.CONFLICT, {"error": str(e)})
            except BipedError as e:
                self._json(HTTPStatus.BAD_REQUEST, {"error": str(e)})

        def _body(self) -> dict[str, Any]:
            n = int(self.headers.get("Content-Length") or 0)
            if n > MAX_BODY:
                raise ConfigError(f"request body too large ({n} bytes; max {MAX_BODY})")
            raw = self.rfile.read(n) if n else b"{}"
            try:
                body = json.loads(raw or b"{}")
            except (json.JSONDecodeError, UnicodeDecodeError) as e:
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
            else:
                self._json(HTTPStatus.NOT_FOUND, {"error": f"no such page: {path}"})

        def _post(self, path: str, body: dict[str, Any]) -> None:
            c = controller
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
    return server_class((host, port), Handler)


def serve_in_thread(server: ThreadingHTTPServer) -> tuple[threading.Thread, str]:
    """Run ``server.serve_forever`` in a daemon thread; returns it and the base URL."""
    host, port = str(server.server_address[0]), int(server.server_address[1])
    if host in ("0.0.0.0", "::"):
        host = "127.0.0.1" if host == "0.0.0.0" else "::1"
    shown = f"[{host}]" if ":" in host else host
    thread = threading.Thread(target=server.serve_forever, name="panel-http", daemon=True)
    thread.start()
    return thread, f"http://{shown}:{port}/"


class _Server(ThreadingHTTPServer):
    daemon_threads = True


class _Server6(_Server):
    address_family = socket.AF_INET6
