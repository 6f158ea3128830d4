"""Every route of the panel's table goes through the guard: the routes are read from the
served table itself (so a route added later is covered without editing this file), and
each one is sent a cross-site, a DNS-rebinding, a token-less and a wrong-typed request."""

from __future__ import annotations

import json
import socket
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, PanelController
from robot.panel.guard import MAX_BODY, Guard
from robot.panel.live import LiveHub
from robot.panel.presets import PresetStore
from robot.panel.routes import Handler, Request, Response, route_table
from robot.panel.server import PanelServer, build_server, serve_in_thread
from robot.panel.studio import Studio

TOKEN = "r0ute-tok"
EVIL = "http://evil.example"


@dataclass
class Reply:
    status: int
    error: str


def send(port: int, method: str, path: str, *, host: str | None = None, origin: str | None = None,
         token: str | None = TOKEN, ctype: str = "application/json", body: bytes = b"{}",
         length: str | None = None) -> Reply:
    """One raw request on its own connection; the status and the JSON error (if any)."""
    lines = [f"{method} {path} HTTP/1.1", f"Host: {host or f'127.0.0.1:{port}'}"]
    if origin:
        lines.append(f"Origin: {origin}")
    if token:
        lines.append(f"Authorization: Bearer {token}")
    if method == "POST":
        lines += [f"Content-Type: {ctype}", f"Content-Length: {length or len(body)}"]
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode() + (body if method == "POST" else b""))
        s.shutdown(socket.SHUT_WR)
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, payload = data.partition(b"\r\n\r\n")
    status = int(head.split()[1])
    error = json.loads(payload).get("error", "") if b"application/json" in head else ""
    return Reply(status, str(error))


@pytest.fixture(scope="module")
def controller(tmp_path_factory: pytest.TempPathFactory) -> Iterator[PanelController]:
    robot = load_robot(DEFAULT_ROBOT)
    c = PanelController(robot, BusSpec("sim"), load_gait("walk").params,
                        presets=PresetStore(tmp_path_factory.mktemp("presets")))
    yield c
    c.shutdown(timeout=2.0)


@pytest.fixture
def studio(controller: PanelController, tmp_path: Path) -> Studio:
    return Studio(controller, takes_dir=tmp_path / "takes", keys_dir=tmp_path / "keys")


@pytest.fixture
def spied(controller: PanelController, studio: Studio
          ) -> Iterator[tuple[int, list[tuple[str, str]], list[tuple[str, str]]]]:
    """The panel's own table and plumbing with every handler replaced by a recorder:
    (port, the routes, the routes whose handler ran)."""
    hub = LiveHub(lambda: {})
    table = route_table(controller, studio, hub)
    ran: list[tuple[str, str]] = []

    def spy(key: tuple[str, str]) -> Handler:
        def handler(_: Request) -> Response:
            ran.append(key)
            return Response(200, b'{"spied": true}', "application/json")
        return handler

    server = PanelServer(("127.0.0.1", 0), guard=Guard.for_bind("127.0.0.1", token=TOKEN),
                         routes={key: spy(key) for key in table}, hub=hub)
    serve_in_thread(server)
    yield int(server.server_address[1]), list(table), ran
    server.shutdown()
    server.server_close()


def test_the_table_holds_the_documented_endpoints(spied: tuple[int, list, list]) -> None:
    _, routes, _ = spied
    expected = {("GET", p) for p in ("/", "/index.html", "/panel.js", "/panel.css", "/input.js",
                                     "/studio.js", "/midi.js", "/api/state", "/api/params",
                                     "/api/presets",
                                     "/api/live", "/api/takes", "/api/sequences",
                                     "/api/show/audio")}
    expected |= {("POST", "/api/" + p) for p in (
        "params", "preset", "save", "start", "stop", "estop", "reset", "record", "play",
        "pose/release", "pose/capture", "pose/clear", "pose/save", "sequence/play")}
    assert set(routes) == expected


def test_no_handler_runs_for_a_refused_request(spied: tuple[int, list, list]) -> None:
    port, routes, ran = spied
    for method, path in routes:
        refusals = [(send(port, method, path, origin=EVIL), 403, "cross-origin"),
                    (send(port, method, path, origin="null"), 403, "cross-origin"),
                    (send(port, method, path, host="evil.example"), 421, "DNS rebinding"),
                    (send(port, method, path, host=f"127.0.0.1.nip.io:{port}"), 421,
                     "DNS rebinding")]
        if path.startswith("/api/"):
            refusals += [(send(port, method, path, token=None), 401, "token"),
                         (send(port, method, path, token="wrong"), 401, "token")]
        if method == "POST":
            refusals += [(send(port, method, path, ctype="text/plain"), 415, "application/json"),
                         (send(port, method, path, length=str(MAX_BODY + 1)), 413, "too large"),
                         (send(port, method, path, length="-1"), 400, "Content-Length")]
        for reply, status, needle in refusals:
            assert (reply.status, needle in reply.error) == (status, True), (method, path, reply)
        assert ran == [], (method, path)


def test_every_handler_runs_for_an_admitted_request(spied: tuple[int, list, list]) -> None:
    """The control for the test above: the same requests from the panel's own page (and
    the static files without a token: they are public) reach their handler."""
    port, routes, ran = spied
    for method, path in routes:
        own = send(port, method, path, origin=f"http://127.0.0.1:{port}")
        public = path.startswith("/api/") or send(port, method, path, token=None).status == 200
        assert own.status == 200 and public, (method, path, own)
    assert ran == [key for key in routes for _ in range(1 if key[1].startswith("/api/") else 2)]


def test_the_served_table_refuses_cross_site_and_tokenless_requests(
        controller: PanelController, studio: Studio) -> None:
    """The real handlers behind build_server: nothing starts, nothing changes, no file."""
    server = build_server(controller, port=0, token=TOKEN, studio=studio)
    serve_in_thread(server)
    port, before = int(server.server_address[1]), controller.params
    try:
        for method, path in server.routes:
            assert send(port, method, path, origin=EVIL).status == 403, (method, path)
            if path.startswith("/api/"):
                assert send(port, method, path, token=None).status == 401, (method, path)
    finally:
        server.shutdown()
        server.server_close()
    assert not controller.running and controller.runs == 0 and controller.params == before
    assert not studio.takes() and not studio.sequences()
    assert not list(controller.presets.presets_dir.iterdir())
