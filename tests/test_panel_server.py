"""The panel's HTTP/JSON server on an ephemeral port, over a real controller driving the
MuJoCo bus (paced to the wall clock): every endpoint, refused values, presets, the token."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from robot.config.bundled import DEFAULT_ROBOT, GAITS_DIR, ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.params import GROUPS, SPECS
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.panel.controller import BusSpec, LoopOptions, PanelController, make_controller
from robot.panel.presets import PresetStore
from robot.panel.server import build_server, serve_in_thread
from sim.emulator.chain import Emulator

Call = Callable[..., tuple[int, Any]]


def http(base: str, method: str, path: str, body: Any = None, *, raw: bytes | None = None,
         headers: dict[str, str] | None = None) -> tuple[int, Any]:
    data = raw if raw is not None else (json.dumps(body).encode() if body is not None else None)
    req = urllib.request.Request(base.rstrip("/") + path, data=data, method=method,
                                 headers={"Content-Type": "application/json", **(headers or {})})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            status, payload, ctype = r.status, r.read(), r.headers["Content-Type"]
    except urllib.error.HTTPError as e:
        status, payload, ctype = e.code, e.read(), e.headers["Content-Type"]
    return status, json.loads(payload) if "json" in ctype else payload.decode()


@pytest.fixture(scope="module")
def panel(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[PanelController, Call]]:
    robot = load_robot(DEFAULT_ROBOT)
    presets = PresetStore(tmp_path_factory.mktemp("presets"))
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 presets=presets, preset="walk")
    server = build_server(controller, port=0)
    _, base = serve_in_thread(server)
    controller.start()
    yield controller, lambda *a, **k: http(base, *a, **k)
    server.shutdown()
    server.server_close()
    controller.emergency_stop()
    controller.shutdown()


def wait_for(pred: Callable[[], bool], timeout: float = 8.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.05)
    return False


def test_static_page_and_assets(panel: tuple[PanelController, Call]) -> None:
    _, call = panel
    status, html = call("GET", "/")
    assert status == 200 and "panel.js" in html and "EMERGENCY STOP" in html
    for asset, needle in (("/panel.js", "/api/params"), ("/panel.css", "fieldset")):
        status, text = call("GET", asset)
        assert status == 200 and needle in text
    assert call("GET", "/../pyproject.toml")[0] == 404
    assert call("GET", "/api/nothing")[0] == 404
    assert call("POST", "/api/nothing", {})[0] == 404


def test_get_params_grouped_with_ranges(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    status, d = call("GET", "/api/params")
    assert status == 200
    assert [g["name"] for g in d["groups"]] == list(GROUPS)
    listed = [p["name"] for g in d["groups"] for p in g["params"]]
    assert sorted(listed) == sorted(SPECS)
    for g in d["groups"]:
        for p in g["params"]:
            s = SPECS[p["name"]]
            assert (p["lo"], p["hi"], p["unit"]) == (s.lo, s.hi, s.unit) and s.group == g["name"]
    assert d["params"] == controller.params.as_dict()


def test_post_params_reaches_the_running_loop(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    assert wait_for(lambda: controller.state()["state"] == "walking")
    status, d = call("POST", "/api/params", {"Slgt_R": 0.9, "turn": 0.1})
    assert status == 200 and d["params"]["Slgt_R"] == 0.9 and d["params"]["turn"] == 0.1
    assert wait_for(lambda: controller.live_params().Slgt_R == 0.9, 1.0)
    assert call("GET", "/api/params")[1]["params"]["Slgt_R"] == 0.9
    call("POST", "/api/params", {"turn": 0.0})


@pytest.mark.parametrize("body, needle", [
    ({"Slgt_R": 9.0}, "Slgt_R = 9.0 is outside [0, 3]"),
    ({"vM": -1}, "vM = -1 is outside [0, 2]"),
    ({"vM": "fast"}, "vM must be a number in [0, 2]"),
    ({"vM": None}, "vM must be a number"),
    ({"vM": True}, "vM must be a number"),
    ({"nope": 1.0}, "unknown gait parameter 'nope'"),
    ({"Slgt_L": 0.6, "Fhgt_R": 99}, "Fhgt_R = 99 is outside [0, 3]"),
])
def test_bad_values_refused_and_nothing_changes(panel: tuple[PanelController, Call],
                                                body: dict[str, Any], needle: str) -> None:
    controller, call = panel
    assert wait_for(lambda: controller.live_params() == controller.params)
    before = call("GET", "/api/params")[1]["params"]
    engine_before = controller.live_params()
    status, d = call("POST", "/api/params", body)
    assert status == 400 and needle in d["error"]
    assert call("GET", "/api/params")[1]["params"] == before
    tick = controller.state()["tick"]
    assert wait_for(lambda: controller.state()["tick"] >= tick + 5)  # a few ticks later,
    assert controller.live_params() == engine_before                   # nothing pending landed


@pytest.mark.parametrize("raw", [b"not json", b"[1, 2]", b"\xff\xfe"])
def test_bad_bodies_refused(panel: tuple[PanelController, Call], raw: bytes) -> None:
    _, call = panel
    before = call("GET", "/api/params")[1]["params"]
    status, d = call("POST", "/api/params", raw=raw)
    assert status == 400 and "JSON" in d["error"]
    assert call("GET", "/api/params")[1]["params"] == before


def test_presets_list_and_load(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    status, d = call("GET", "/api/presets")
    assert status == 200 and {"walk", "march", "crouch"} <= set(d["presets"])
    march = load_gait("march").for_robot(controller.robot)   # with the robot's [balance]
    status, d = call("POST", "/api/preset", {"name": "march"})
    assert status == 200 and d["params"] == march.as_dict()
    assert controller.params == march
    assert call("GET", "/api/params")[1]["preset"] == "march"
    for bad in ("no_such_preset", "../walk", None):
        status, d = call("POST", "/api/preset", {"name": bad})
        assert status == 400 and "preset" in d["error"]
    assert controller.params == march
    call("POST", "/api/preset", {"name": "walk"})


def test_save_preset(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    bundled = (GAITS_DIR / "walk.toml").read_bytes()
    call("POST", "/api/params", {"Slgt_R": 0.8})
    status, d = call("POST", "/api/save", {"name": "my_walk"})
    assert status == 200 and "my_walk" in d["presets"]
    saved = Path(d["saved"])
    assert saved.parent == controller.presets.presets_dir
    assert load_gait(saved).params == controller.params
    assert call("POST", "/api/save", {"name": "my_walk"})[0] == 409
    assert call("POST", "/api/save", {"name": "my_walk", "overwrite": True})[0] == 200
    for overwrite in (False, True):
        status, d = call("POST", "/api/save", {"name": "walk", "overwrite": overwrite})
        assert status == 409 and "bundled" in d["error"]
    for bad in ("../evil", "a/b", "", " x", "x" * 60, 5):
        status, d = call("POST", "/api/save", {"name": bad})
        assert status == 400 and "preset name" in d["error"]
    assert (GAITS_DIR / "walk.toml").read_bytes() == bundled
    assert not list(controller.presets.presets_dir.glob("*evil*"))
    call("POST", "/api/preset", {"name": "walk"})


def test_state_telemetry_and_figure(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    assert wait_for(lambda: call("GET", "/api/state")[1]["q_present"] is not None)
    status, s = call("GET", "/api/state")
    assert status == 200 and s["running"] and s["state"] in ("ramp_in", "walking")
    assert s["loop_hz"] == pytest.approx(100.0, rel=0.05) and s["rate_hz"] == 100.0
    assert len(s["servos"]) == len(controller.robot.joints)
    assert all(v["temperature"] is not None and v["load"] is not None for v in s["servos"])
    assert s["sim"]["fell"] is False and s["sim"]["torso_height_m"] > 0.1
    for which in ("cmd", "present"):
        for view in ("side", "front"):
            fig = s["figure"][which][view]
            assert set(fig) >= {"r_leg", "l_leg", "torso", "r_arm", "l_arm"}
            zs = [p[1] for pts in fig.values() for p in pts]
            assert min(zs) == pytest.approx(0.0, abs=1e-3) and max(zs) > 0.2


def test_start_stop_estop_reset(panel: tuple[PanelController, Call]) -> None:
    controller, call = panel
    if not controller.running:
        assert call("POST", "/api/start")[0] == 200
    assert call("POST", "/api/start")[0] == 409
    assert call("POST", "/api/reset")[0] == 409
    status, _ = call("POST", "/api/stop")
    assert status == 200
    seen: set[str] = set()
    assert wait_for(lambda: seen.add(call("GET", "/api/state")[1]["state"]) or
                    not controller.running)
    assert "ramp_out" in seen or "rest" in seen
    assert call("GET", "/api/state")[1]["state"] == "stopped"
    assert call("POST", "/api/stop") == (200, {"ok": True, "state": "stopped"})  # idempotent
    assert call("POST", "/api/start")[0] == 200
    assert wait_for(lambda: call("GET", "/api/state")[1]["state"] == "walking")
    assert all(controller.state()["torque"])  # what the wire was told: torque on
    assert call("POST", "/api/estop")[0] == 200
    assert controller.wait(1.0)
    assert call("GET", "/api/state")[1]["state"] == "estop"
    assert not any(controller.state()["torque"])
    assert call("POST", "/api/estop")[0] == 200  # idle: still torque off, still 200
    assert call("POST", "/api/reset")[0] == 200
    assert call("POST", "/api/start")[0] == 200


def test_token_required_beyond_loopback() -> None:
    robot = load_robot(DEFAULT_ROBOT)
    controller = PanelController(robot, BusSpec("sim"), load_gait("walk").params)
    with pytest.raises(ConfigError, match="token"):
        build_server(controller, host="0.0.0.0", port=0)
    server = build_server(controller, host="0.0.0.0", port=0, token="s3cret")
    _, base = serve_in_thread(server)
    try:
        for path in ("/", "/panel.js", "/panel.css"):  # public: no secret in them
            status, text = http(base, "GET", path)
            assert status == 200 and "s3cret" not in text
        for path in ("/api/state", "/api/params"):
            assert http(base, "GET", path)[0] == 401
            assert http(base, "GET", path, headers={"Authorization": "Bearer nope"})[0] == 401
            assert http(base, "GET", path, headers={"Authorization": "Bearer s3cret"})[0] == 200
            assert http(base, "GET", path + "?token=s3cret")[0] == 200
        before = controller.params
        assert http(base, "POST", "/api/params", {"vM": 0.5})[0] == 401
        assert http(base, "POST", "/api/start")[0] == 401
        assert controller.params == before and not controller.running
    finally:
        server.shutdown()
        server.server_close()


def test_biped_panel_command_prints_token_and_stops_on_sigterm(tmp_path: Path) -> None:
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "robot.cli", "panel", "--host", "0.0.0.0", "--http-port", "0",
         "--rate", "100", "--presets-dir", str(tmp_path)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        m = re.search(r" open (http://\S+)(?: \(this machine: (\S+)\))?$", line)
        assert m is not None, line
        url, local = m[1], m[2] or m[1]  # a LAN address, and loopback (the same without LAN)
        port = local.split("/")[2].split(":")[1]
        assert local.startswith(f"http://127.0.0.1:{port}/?token="), line
        assert "0.0.0.0" not in url and f":{port}/?token=" in url, line
        token = proc.stdout.readline().split()[-1]
        assert url.endswith(f"?token={token}") and len(token) >= 20
        base = url.split("?")[0]  # what a phone opens
        assert http(base, "GET", "/api/state")[0] == 401
        assert http(base, "GET", "/")[0] == 200
        auth = {"Authorization": f"Bearer {token}"}
        assert wait_for(lambda: http(base, "GET", "/api/state", headers=auth)[1]["running"])
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=15)
        assert proc.returncode == 143 and "stopping" in out
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


#: Every instruction that writes a register (the emulator's packet names).
WRITES = {"write", "sync_write", "reg_write", "bulk_write", "action"}


@pytest.mark.parametrize("protocol", ["dynamixel", "feetech"])
def test_idle_figure_shows_the_read_back_pose_without_writing(protocol: str,
                                                              tmp_path: Path) -> None:
    """No run: /api/state reads the present pose (<= 5 reads/s however often it is asked)
    and the stick figure follows a joint moved by hand; nothing is written to the servos."""
    robot = load_robot(ROBOTS_DIR / f"biped18-{protocol}.toml")
    with Emulator(protocol, robot, seed=1) as emu:
        emu.set_register(4, "present_position", 2048 + 600)  # r_knee, sign +1, zero 2048
        controller = make_controller(robot, BusSpec(protocol, port=emu.port,
                                                    options={"timeout_ms": 50.0}),
                                     load_gait("walk").params, presets=PresetStore(tmp_path))
        server = build_server(controller, port=0)
        _, base = serve_in_thread(server)
        try:
            emu.log(clear=True)                                # the bus is open: from here
            t0 = time.monotonic()
            states = [http(base, "GET", "/api/state")[1] for _ in range(30)]
            knee = robot.joint_names.index("r_knee")
            assert wait_for(lambda: http(base, "GET", "/api/state")[1]["q_present"]
                            is not None)
            s = http(base, "GET", "/api/state")[1]
            assert not s["running"] and s["state"] == "idle" and not states[-1]["running"]
            assert s["q_present"][knee] == pytest.approx(600 * 2 * 3.141592653589793 / 4096)
            assert s["figure"]["cmd"] is None
            assert set(s["figure"]["present"]["side"]) >= {"r_leg", "l_leg", "torso"}
            assert all(v["temperature"] is not None for v in s["servos"])
            emu.set_register(4, "present_position", 2048)  # moved back by hand
            assert wait_for(lambda: http(base, "GET", "/api/state")[1]["q_present"][knee]
                            == 0.0)
            elapsed = time.monotonic() - t0
            log = emu.log()
            assert [p for p in log if p.instruction in WRITES] == []
            reads = [p for p in log if "read" in p.instruction]
            assert 2 <= len(reads) <= 5 * elapsed + 2
        finally:
            server.shutdown()
            server.server_close()
            controller.shutdown()


def test_a_start_may_be_the_first_thing_asked() -> None:
    """No I/O in the constructor: the first request (here a start) starts the loop
    process and the bus."""
    robot = load_robot(DEFAULT_ROBOT)
    controller = PanelController(robot, BusSpec("sim"), load_gait("walk").params)
    assert controller.pid is None
    try:
        controller.start()
        assert controller.pid is not None and controller.running
    finally:
        controller.emergency_stop()
        assert controller.shutdown(timeout=5)["holding"] is False
