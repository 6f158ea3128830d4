"""The panel as an attacker meets it, at the HTTP level only (raw sockets against a served
panel on an ephemeral port, never handler internals, so the tests hold whatever web
framework serves it): cross-origin requests, DNS rebinding, content types, bundled
presets, hostile Content-Length / Transfer-Encoding, and token mode."""

from __future__ import annotations

import json
import socket
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from robot.config.bundled import DEFAULT_ROBOT, GAITS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.panel.controller import BusSpec, LoopOptions, PanelController, make_controller
from robot.panel.guard import MAX_BODY
from robot.panel.presets import PresetStore
from robot.panel.server import build_server, panel_url, serve_in_thread

EVIL = "http://evil.example"
READ_TIMEOUT_S = 1.5  # the served panel's; a stalled body must be answered after it


@dataclass
class Reply:
    status: int
    headers: dict[str, str]
    body: Any
    seconds: float


def request(port: int, head: str, body: bytes = b"", *, close_write: bool = False,
            timeout: float = 5.0) -> Reply:
    """Send ``head`` (CRLF added) and ``body`` on a raw socket; read until the server
    closes or ``timeout``. ``close_write``: half-close after sending (else the client
    stays silent with the connection open, as a stalling attacker would)."""
    t0 = time.monotonic()
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(head.replace("\n", "\r\n").encode() + b"\r\n" + body)
        if close_write:
            s.shutdown(socket.SHUT_WR)
        data = b""
        try:
            while chunk := s.recv(65536):
                data += chunk
        except TimeoutError:
            pass
    seconds = time.monotonic() - t0
    assert data, f"empty reply after {seconds:.1f} s to {head.splitlines()[0]!r}"
    top, _, payload = data.partition(b"\r\n\r\n")
    lines = top.decode("latin-1").split("\r\n")
    headers = {k.strip().lower(): v.strip() for k, _, v in (x.partition(":") for x in lines[1:])}
    parsed = json.loads(payload) if "json" in headers.get("content-type", "") else payload
    return Reply(int(lines[0].split()[1]), headers, parsed, seconds)


def post(port: int, path: str, body: bytes, *, ctype: str = "application/json",
         extra: str = "", host: str | None = None) -> Reply:
    head = (f"POST {path} HTTP/1.1\nHost: {host or f'127.0.0.1:{port}'}\n"
            f"Content-Type: {ctype}\nContent-Length: {len(body)}\n{extra}")
    return request(port, head, body)


def get(port: int, path: str, *, host: str | None = None, extra: str = "") -> Reply:
    return request(port, f"GET {path} HTTP/1.1\nHost: {host or f'127.0.0.1:{port}'}\n{extra}")


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory
           ) -> Iterator[tuple[PanelController, int]]:
    """A panel on 127.0.0.1 whose loop is NOT running (so a start would show)."""
    robot = load_robot(DEFAULT_ROBOT)
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 presets=PresetStore(tmp_path_factory.mktemp("presets")),
                                 preset="walk")
    server = build_server(controller, port=0, read_timeout_s=READ_TIMEOUT_S)
    serve_in_thread(server)
    yield controller, int(server.server_address[1])
    server.shutdown()
    server.server_close()
    controller.shutdown(timeout=2.0)


def assert_not_started(controller: PanelController) -> None:
    # A start is counted before its request is answered (PanelController.start), so a
    # refused request that had slipped through would show here already: no wait needed.
    assert not controller.running and controller.runs == 0


@pytest.mark.parametrize("ctype, body", [
    ("text/plain", b'{"go": 1}'),
    ("application/x-www-form-urlencoded", b"go=1"),
    ("multipart/form-data; boundary=x", b"--x\r\nContent-Disposition: form-data; "
     b'name="go"\r\n\r\n1\r\n--x--\r\n'),
])
def test_cross_origin_start_refused(served: tuple[PanelController, int], ctype: str,
                                    body: bytes) -> None:
    controller, port = served
    r = post(port, "/api/start", body, ctype=ctype, extra=f"Origin: {EVIL}\n")
    assert r.status == 403 and "cross-origin" in r.body["error"]
    # The same simple request without an Origin (a non-browser client) fails on its type.
    r = post(port, "/api/start", body, ctype=ctype)
    assert r.status == 415 and "application/json" in r.body["error"]
    assert_not_started(controller)


@pytest.mark.parametrize("origin", [EVIL, "null", "http://127.0.0.1:1", "https://127.0.0.1:{port}",
                                    "http://localhost:{port}"])
def test_foreign_origin_refused_even_with_json(served: tuple[PanelController, int],
                                               origin: str) -> None:
    controller, port = served
    r = post(port, "/api/start", b"{}", extra=f"Origin: {origin.format(port=port)}\n")
    assert r.status == 403, r.body
    r = get(port, "/api/state", extra=f"Origin: {origin.format(port=port)}\n")
    assert r.status == 403
    assert_not_started(controller)


def test_own_origin_served(served: tuple[PanelController, int]) -> None:
    controller, port = served
    before = controller.params
    for host in (f"127.0.0.1:{port}", f"localhost:{port}"):
        r = post(port, "/api/params", json.dumps({"turn": 0.1}).encode(), host=host,
                 extra=f"Origin: http://{host}\n")
        assert r.status == 200 and r.body["params"]["turn"] == 0.1
    r = post(port, "/api/params", json.dumps({"turn": before.turn}).encode(),
             ctype="application/json; charset=utf-8")
    assert r.status == 200 and controller.params == before


@pytest.mark.parametrize("host", ["evil.example:{port}", "evil.example", "127.0.0.1.nip.io:{port}",
                                  "localhost.evil.example:{port}", "192.0.2.99:{port}"])
def test_foreign_host_refused(served: tuple[PanelController, int], host: str) -> None:
    controller, port = served
    h = host.format(port=port)
    for r in (get(port, "/api/state", host=h), get(port, "/", host=h),
              post(port, "/api/start", b"{}", host=h, extra=f"Origin: http://{h}\n")):
        assert r.status == 421 and "DNS rebinding" in r.body["error"], (r.status, r.body)
    assert_not_started(controller)


def test_missing_or_malformed_host_refused(served: tuple[PanelController, int]) -> None:
    _, port = served
    assert request(port, "GET /api/state HTTP/1.0\n").status == 400
    assert get(port, "/api/state", host="a b").status == 400
    for ok in (f"LOCALHOST:{port}", f"[::1]:{port}", f"localhost.:{port}", "127.0.0.1"):
        assert get(port, "/api/state", host=ok).status == 200, ok


def test_cross_origin_save_cannot_touch_bundled_preset(served: tuple[PanelController, int]
                                                       ) -> None:
    controller, port = served
    bundled = (GAITS_DIR / "walk.toml").read_bytes()
    evil = json.dumps({"name": "walk", "overwrite": True}).encode()
    r = post(port, "/api/save", evil, ctype="text/plain", extra=f"Origin: {EVIL}\n")
    assert r.status == 403
    r = post(port, "/api/save", evil, extra=f"Origin: {EVIL}\n")
    assert r.status == 403
    # Even the panel's own page cannot replace or shadow a bundled preset.
    for name in ("walk", "Walk", "march"):
        r = post(port, "/api/save", json.dumps({"name": name, "overwrite": True}).encode())
        assert r.status == 409 and "bundled" in r.body["error"], r.body
    assert (GAITS_DIR / "walk.toml").read_bytes() == bundled
    assert not list(controller.presets.presets_dir.glob("*alk*"))


def test_user_file_cannot_shadow_bundled_preset(served: tuple[PanelController, int]) -> None:
    controller, port = served
    fake = (GAITS_DIR / "walk.toml").read_text().replace("vM = 0.3", "vM = 1.5")
    (controller.presets.presets_dir / "walk.toml").write_text(fake)
    try:
        r = post(port, "/api/preset", b'{"name": "walk"}')
        assert r.status == 200 and r.body["params"]["vM"] == load_gait("walk").params.vM
    finally:
        (controller.presets.presets_dir / "walk.toml").unlink()


def test_presets_saved_to_the_user_config_dir(tmp_path: Path,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "xdg"))
    store = PresetStore()
    assert store.presets_dir == tmp_path / "xdg" / "biped" / "gaits"
    saved = store.save("mine", load_gait("walk").params)
    assert saved.parent == store.presets_dir and "mine" in store.names()
    monkeypatch.setenv("XDG_CONFIG_HOME", "relative/ignored")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert PresetStore().presets_dir == tmp_path / "home" / ".config" / "biped" / "gaits"
    with pytest.raises(Exception, match="bundled presets live"):
        PresetStore(GAITS_DIR)


@pytest.mark.parametrize("length, status, needle", [
    ("-1", 400, "Content-Length"),
    ("abc", 400, "Content-Length"),
    ("1e3", 400, "Content-Length"),
    ("9" * 400, 413, "too large"),
    (str(MAX_BODY + 1), 413, "too large"),
    ("5, 7", 400, "Content-Length"),
])
def test_bad_content_length_answered_fast(served: tuple[PanelController, int],
                                          capfd: pytest.CaptureFixture[str], length: str,
                                          status: int, needle: str) -> None:
    controller, port = served
    head = (f"POST /api/start HTTP/1.1\nHost: 127.0.0.1:{port}\n"
            f"Content-Type: application/json\nContent-Length: {length}\n")
    r = request(port, head, b"{}")  # the client then stays silent, connection open
    assert r.status == status and needle in r.body["error"], (r.status, r.body)
    assert r.seconds < 1.0
    assert get(port, "/api/state").status == 200  # still serving
    assert "Traceback" not in capfd.readouterr().err
    assert_not_started(controller)


def test_chunked_body_refused_not_awaited(served: tuple[PanelController, int]) -> None:
    controller, port = served
    head = (f"POST /api/start HTTP/1.1\nHost: 127.0.0.1:{port}\n"
            f"Content-Type: application/json\nTransfer-Encoding: chunked\n")
    r = request(port, head, b"2\r\n{}\r\n")  # never the closing 0-chunk
    assert r.status == 411 and "Content-Length" in r.body["error"] and r.seconds < 1.0
    assert_not_started(controller)


def test_stalled_body_times_out_with_json(served: tuple[PanelController, int]) -> None:
    _, port = served
    head = (f"POST /api/params HTTP/1.1\nHost: 127.0.0.1:{port}\n"
            f"Content-Type: application/json\nContent-Length: 100\n")
    r = request(port, head, b'{"turn"')
    assert r.status == 408 and r.seconds < READ_TIMEOUT_S + 1.0
    r = request(port, head, b'{"turn"', close_write=True)  # body cut short by the client
    assert r.status == 400 and "7 of 100" in r.body["error"]


def test_other_methods_and_bad_request_lines_get_json(served: tuple[PanelController, int]
                                                      ) -> None:
    _, port = served
    for head in (f"DELETE /api/state HTTP/1.1\nHost: 127.0.0.1:{port}\n", "BLAH\n",
                 "GET /" + "x" * 70000 + " HTTP/1.1\n"):
        r = request(port, head, close_write=True)
        assert 400 <= r.status < 600 and "error" in r.body


@pytest.fixture(scope="module")
def token_panel() -> Iterator[tuple[PanelController, int]]:
    """On every address, with a token, as for a phone."""
    robot = load_robot(DEFAULT_ROBOT)
    controller = PanelController(robot, BusSpec("sim"), load_gait("walk").params)
    server = build_server(controller, host="0.0.0.0", port=0, token="s3cret-tok")
    serve_in_thread(server)
    yield controller, int(server.server_address[1])
    server.shutdown()
    server.server_close()
    controller.shutdown(timeout=2.0)


def test_token_page_and_assets_public_api_needs_token(token_panel: tuple[PanelController, int]
                                                      ) -> None:
    controller, port = token_panel
    for path in ("/", "/panel.js", "/panel.css"):
        r = get(port, path)
        assert r.status == 200 and b"s3cret-tok" not in r.body
    for path in ("/api/state", "/api/params", "/api/presets"):
        assert get(port, path).status == 401
        assert get(port, path, extra="Authorization: Bearer wrong\n").status == 401
        assert get(port, path + "?token=wrong").status == 401
        assert get(port, path, extra="Authorization: Bearer s3cret-tok\n").status == 200
        assert get(port, path + "?token=s3cret-tok").status == 200
    for path in ("/api/start", "/api/params"):
        assert post(port, path, b'{"vM": 0.5}').status == 401
    assert_not_started(controller)


def test_token_panel_answers_to_its_lan_url(token_panel: tuple[PanelController, int]) -> None:
    _, port = token_panel
    url = panel_url("0.0.0.0", port)
    host = url.split("//")[1].rstrip("/")
    assert not host.startswith("0.0.0.0")
    auth = "Authorization: Bearer s3cret-tok\n"
    r = get(port, "/api/state", host=host, extra=f"{auth}Origin: http://{host}\n")
    assert r.status == 200
    hostname = socket.gethostname()
    assert get(port, "/api/state", host=f"{hostname}:{port}", extra=auth).status == 200
    assert get(port, "/api/state", host=f"evil.example:{port}", extra=auth).status == 421


def test_bearer_scheme_is_case_insensitive(token_panel: tuple[PanelController, int]) -> None:
    """RFC 7235: the auth scheme is case-insensitive; the token itself is not."""
    _, port = token_panel
    for scheme in ("bearer", "BEARER", "BeArEr"):
        assert get(port, "/api/state", extra=f"Authorization: {scheme} s3cret-tok\n"
                   ).status == 200, scheme
    assert get(port, "/api/state", extra="Authorization: bearer S3CRET-TOK\n").status == 401
    assert get(port, "/api/state", extra="Authorization: Basic s3cret-tok\n").status == 401


def test_number_with_thousands_of_digits_is_one_line_400(served: tuple[PanelController, int],
                                                          capfd: pytest.CaptureFixture[str]
                                                          ) -> None:
    controller, port = served
    before = controller.params
    for body in (b'{"vM": ' + b"9" * 5000 + b"}", b'{"vM": ' + b"9" * 1000 + b"}",
                 b'{"vM": 1e999}', b'{"vM": NaN}', b"[" * 60000):
        r = post(port, "/api/params", body)
        assert r.status == 400 and "\n" not in r.body["error"], (r.status, r.body)
        assert "sys." not in r.body["error"]
    assert controller.params == before
    assert "Traceback" not in capfd.readouterr().err
