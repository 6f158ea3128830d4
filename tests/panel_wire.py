"""Shared pieces of the panel's wire-level tests: `biped panel` as a subprocess on the pty
emulator (the real vendor SDK), requests fired at chosen moments from their own
connections, and oracles read from the emulator's packet log and registers.

The oracles are written here from the manuals' register addresses (Goal Position, Torque
Enable), not from robot/bus/tables.py, and judge only what reached the servos.
"""

from __future__ import annotations

import http.client
import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from waiting import sleep_until, wait_for

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator, Packet

REPO = Path(__file__).resolve().parent.parent
#: From the manuals: X-series Goal Position 116, Torque Enable 64; STS3215 42, 40.
GOAL_ADDRESS = {"dynamixel": 116, "feetech": 42}
TORQUE_ADDRESS = {"dynamixel": 64, "feetech": 40}
#: Requests that move servos (each must own the bus alone).
MOVERS = ("/api/start", "/api/record", "/api/play", "/api/pose/release",
          "/api/pose/capture", "/api/sequence/play")


@dataclass
class Panel:
    proc: subprocess.Popen[str]
    host: str
    port: int
    token: str | None = None
    err: list[str] = field(default_factory=list)

    @property
    def base(self) -> str:
        return f"http://{self.host}:{self.port}/"

    def request(self, method: str, path: str, body: dict[str, Any] | None = None,
                *, timeout: float = 30.0) -> tuple[int, dict[str, Any]]:
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        try:
            conn.request(method, path, json.dumps(body or {}) if method == "POST" else None,
                         self.headers())
            r = conn.getresponse()
            return r.status, json.loads(r.read() or b"{}")
        finally:
            conn.close()

    def headers(self) -> dict[str, str]:
        h = {"Content-Type": "application/json"}
        if self.token:
            h["Authorization"] = f"Bearer {self.token}"
        return h

    def state(self) -> dict[str, Any]:
        return self.request("GET", "/api/state")[1]


@contextmanager
def launched(emu: Emulator | None, robot_toml: Path, tmp: Path, *extra: str,
             rate: float = 200.0, start: bool = False) -> Iterator[Panel]:
    """`biped panel` on ``emu`` (None: the sim bus; ``--no-start`` unless ``start``;
    stderr collected in ``Panel.err``); SIGTERM and a wait for its exit at the end
    (killed if it will not end)."""
    bus = ["--bus", "sim"] if emu is None else ["--bus", emu.protocol, "--port", emu.port]
    cmd = [sys.executable, "-m", "robot.cli", "panel", *bus,
           "--robot", str(robot_toml), "--http-port", "0", "--rate", f"{rate:g}",
           "--presets-dir", str(tmp / "presets"), "--studio-dir", str(tmp / "studio"),
           *extra, *([] if start else ["--no-start"])]
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "MUJOCO_GL": "egl"})
    assert proc.stdout is not None and proc.stderr is not None
    panel = Panel(proc, "127.0.0.1", 0)
    reader = threading.Thread(target=lambda: panel.err.extend(iter(proc.stderr.readline, "")),
                              daemon=True)
    reader.start()
    try:
        line = proc.stdout.readline()
        assert " open http://" in line, line + "".join(panel.err)
        url = line.split(" open ")[1].split()[0]
        local = line.split("this machine: ")[1].rstrip(")\n") if "this machine" in line else url
        panel.port = int(local.split("//")[1].split("/")[0].rsplit(":", 1)[1])
        if "?token=" in local:
            panel.token = local.split("?token=")[1]
        yield panel
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        reader.join(5)


# ------------------------------------------------------------------------------ shots
@dataclass
class Shot:
    """One request fired ``offset_s`` after the first one's connection: path and body;
    afterwards its status, reply, and when it was sent and answered [s, monotonic]."""

    path: str
    body: dict[str, Any] = field(default_factory=dict)
    offset_s: float = 0.0
    status: int = 0
    reply: dict[str, Any] = field(default_factory=dict)
    sent: float = 0.0
    answered: float = 0.0


def fire(panel: Panel, shots: Sequence[Shot]) -> list[Shot]:
    """Send every shot on its own connection, each connected after the one before it (so
    the panel sees them arrive in this order) and sent at its offset; wait for every
    answer."""
    connected = [threading.Event() for _ in shots]
    t0: list[float] = []

    def one(k: int, shot: Shot) -> None:
        if k:
            connected[k - 1].wait(10)
            sleep_until(t0[0] + shot.offset_s)
        conn = http.client.HTTPConnection(panel.host, panel.port, timeout=30)
        try:
            conn.connect()
            if not k:
                t0.append(time.monotonic())
            connected[k].set()
            shot.sent = time.monotonic()
            conn.request("POST", shot.path, json.dumps(shot.body), panel.headers())
            r = conn.getresponse()
            shot.status, shot.reply = r.status, json.loads(r.read() or b"{}")
            shot.answered = time.monotonic()
        finally:
            connected[k].set()
            conn.close()

    threads = [threading.Thread(target=one, args=(k, s)) for k, s in enumerate(shots)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    return list(shots)


def settle(panel: Panel) -> None:
    """E-stop and wait until no run is active (the next repetition starts from rest)."""
    assert panel.request("POST", "/api/estop")[0] == 200
    assert wait_for(lambda: not panel.state()["running"]), panel.state()


# ------------------------------------------------------------------------------ oracles
def torque_writes(p: Packet, protocol: str) -> dict[int, int]:
    """Torque Enable values a packet wrote, by id ({} for any other packet)."""
    if p.address != TORQUE_ADDRESS[protocol] or p.instruction not in ("write", "sync_write"):
        return {}
    return dict(p.values)


def is_goal(p: Packet, protocol: str) -> bool:
    return p.instruction in ("write", "sync_write") and p.address == GOAL_ADDRESS[protocol]


def assert_one_owner(robot: RobotConfig, log: list[Packet], protocol: str) -> None:
    """Goals go to servos with torque on: between a servo's torque-off and its next
    torque-on at most one goal packet names it (a run's start writes goal := present
    just before torque on). Two owners (a walk and a limb release) break this."""
    torque: dict[int, int] = {i: 0 for i in robot.ids}
    stray: dict[int, int] = {i: 0 for i in robot.ids}
    for p in log:
        for i, v in torque_writes(p, protocol).items():
            torque[i], stray[i] = v, 0
        if is_goal(p, protocol):
            for i in p.values:
                if not torque.get(i):
                    stray[i] += 1
                    assert stray[i] <= 1, f"goals to servo {i} with its torque off at {p.t}"


def assert_estop_held(robot: RobotConfig, log: list[Packet], protocol: str,
                      estop_sent: float) -> None:
    """After the e-stop was sent, every servo gets torque off written; from the moment
    the last of them has, no goal and no torque-on reaches the wire."""
    off: set[int] = set()
    after = [p for p in log if p.t >= estop_sent]
    for k, p in enumerate(after):
        off |= {i for i, v in torque_writes(p, protocol).items() if v == 0}
        if off >= set(robot.ids):
            late = [q for q in after[k + 1:] if is_goal(q, protocol)
                    or any(v for v in torque_writes(q, protocol).values())]
            assert not late, (f"{len(late)} goal/torque-on packets after the e-stop's "
                              f"torque off: first {late[0]}")
            return
    raise AssertionError(f"torque off never reached servos {sorted(set(robot.ids) - off)} "
                         "after the e-stop")


def torque_now(emu: Emulator, robot: RobotConfig) -> dict[int, int]:
    return {i: emu.registers(i)["torque_enable"] for i in robot.ids}


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def gone(pid: int) -> bool:
    """``pid`` has exited (or is a zombie waiting for its parent)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


def patient_robot_file(tmp: Path) -> Path:
    """The bundled 18-Dynamixel robot with bus_harness.PATIENT_TIMEOUT_MS (a starved
    emulator on a loaded machine), written under ``tmp``."""
    from bus_harness import PATIENT_TIMEOUT_MS

    from robot.config.bundled import ROBOTS_DIR
    text = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
    path = tmp / "robot.toml"
    path.write_text(text.replace("timeout_ms = 20.0", f"timeout_ms = {PATIENT_TIMEOUT_MS}"))
    return path


def osc_datagram(address: str, *args: float | str) -> bytes:
    """One OSC message, built by python-osc's builder (not by the code under test)."""
    from pythonosc.osc_message_builder import OscMessageBuilder
    b = OscMessageBuilder(address)
    for a in args:
        b.add_arg(a)
    return bytes(b.build().dgram)
