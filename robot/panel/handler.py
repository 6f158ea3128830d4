"""One connection of the panel's web side: its head read within the head timeout, the
guard (robot.panel.guard) applied once, the body within the read timeout, the route
dispatched, the answer written as JSON (or the connection handed to the live hub). Errors
become ``{"error": "..."}`` with their status, never an empty reply or a traceback."""

from __future__ import annotations

import io
import json
import logging
import time
from dataclasses import replace
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler
from typing import Any
from urllib.parse import parse_qs, urlsplit

from robot.errors import BipedError, ConfigError
from robot.panel.admission import DeadlineReader
from robot.panel.guard import Refused
from robot.panel.loop_process import LoopUnavailable
from robot.panel.options import PanelStateError
from robot.panel.presets import PresetExistsError
from robot.panel.routes import Body, Request, Response, Upgrade, dispatch, json_response

log = logging.getLogger(__name__)

HEADERS = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff",
           "Referrer-Policy": "no-referrer", "X-Frame-Options": "DENY",
           "Content-Security-Policy": "default-src 'self'; img-src 'self' data:; "
           "style-src 'self' 'unsafe-inline'; frame-ancestors 'none'; base-uri 'none'; "
           "form-action 'none'"}


class Handler(BaseHTTPRequestHandler):
    """One connection: parse (its head within the head timeout), admit (the guard), read
    the body (within the read timeout), dispatch, answer."""

    server: Any  # robot.panel.server.PanelServer (its guard, routes, timeouts, admission)
    server_version = "biped-panel/1"
    default_request_version = "HTTP/1.0"  # errors always get a status line and headers

    def __init__(self, request: Any, client_address: Any, server: Any, *,
                 received: float | None = None, counted: list[bool] | None = None) -> None:
        self.received = time.monotonic() if received is None else received
        self._counted = counted if counted is not None else [False]
        super().__init__(request, client_address, server)

    def setup(self) -> None:
        super().setup()
        self._reader = DeadlineReader(self.connection,
                                      self.received + self.server.head_timeout_s)
        self.rfile = io.BufferedReader(self._reader)

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
                if self._counted[0]:
                    self._counted[0] = False
                    self.server.admission.leave(str(self.client_address[0]))
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
        request = Request(method, url.path, parse_qs(url.query), headers,
                          received=self.received)
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
        if isinstance(e, LoopUnavailable):
            return json_response(HTTPStatus.SERVICE_UNAVAILABLE, {"error": str(e)})
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
        self._reader.deadline = time.monotonic() + self.server.read_timeout_s
        raw = self.rfile.read(n) if n else b""
        if len(raw) < n:
            raise Refused(HTTPStatus.BAD_REQUEST,
                          f"request body ended after {len(raw)} of {n} bytes")
        try:
            body = json.loads(raw or b"{}")
        except (ValueError, RecursionError) as e:  # also a number of > 4300 digits
            why = str(e).split(": value has")[0].split("; use sys.")[0]
            raise ConfigError(f"request body is not JSON we accept: {why}") from None
        if not isinstance(body, dict):
            raise ConfigError("request body must be a JSON object")
        return body

    def _answer(self, response: Response) -> None:
        self.connection.settimeout(self.server.read_timeout_s)  # a client that never reads
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
