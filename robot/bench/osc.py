"""Benchmark: how long from an OSC message's arrival to the first goal on the wire it
changed, and from ``/biped/estop`` to torque off on the wire; quiet and under a flood.

`biped panel --osc` walks 18 emulated Dynamixels (the pty emulator, the real SDK, wall
clock) at 200 Hz, its cycle set to a whole number of ticks (160), so the legs' goals repeat
exactly every 160 ticks while nothing changes. Each trial sends ``/biped/param/torso_lean``
(0.25 rad, then back to 0) from this process after the legs have been steady for a cycle;
the latency is from the send (on loopback the datagram is in the panel's socket when
``sendto`` returns: its arrival) to the first goal packet in the emulator's log whose leg
goals differ from those a cycle earlier (the change's first tick moves a hip by ~8 ticks;
a steady stream differs by 0). The e-stop trials start the walk, send ``/biped/estop`` and
take the first Torque Enable write after it. The flood: 10,000 datagrams a second of
``/biped/param/Abnc_R`` (the arms' bounciness: the legs do not follow it) from another
thread. Never asserted (a benchmark). ``python -m robot.bench.osc [--quick]``.
"""

from __future__ import annotations

import argparse
import json
import math
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np
from pythonosc.osc_message_builder import OscMessageBuilder

from robot.bench.panel_flood import TOKEN, panel_post, panel_state, stop_panel
from robot.bus.tables import DYNAMIXEL_X
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot

RATE_HZ = 200.0
CYCLE_TICKS = 160
FPS = 2 * math.pi / (0.3 * CYCLE_TICKS / RATE_HZ)   # walk's vM = 0.3
LEAN = 0.25
FLOOD_HZ = 10_000
GOAL = DYNAMIXEL_X["goal_position"].address
TORQUE = DYNAMIXEL_X["torque_enable"].address


def osc(address: str, value: float | None = None) -> bytes:
    b = OscMessageBuilder(address)
    if value is not None:
        b.add_arg(value)
    return b.build().dgram


def _launch(emu_port: str, tmp: Path) -> tuple[subprocess.Popen[str], str, int]:
    text = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
    robot_file = tmp / "robot.toml"
    robot_file.write_text(text.replace("timeout_ms = 20.0", "timeout_ms = 50.0"))
    cmd = [sys.executable, "-m", "robot.cli", "panel", "--bus", "dynamixel", "--port",
           emu_port, "--robot", str(robot_file), "--http-port", "0", "--token", TOKEN,
           "--rate", f"{RATE_HZ:g}", "--presets-dir", str(tmp / "p"), "--studio-dir",
           str(tmp / "s"), "--osc", "0", "--set", f"fps={FPS!r}", "--no-start"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True, cwd=tmp)
    assert proc.stdout is not None
    http = int(proc.stdout.readline().split(" open http://")[1].split("/")[0].rsplit(":")[1])
    osc_port = int(proc.stdout.readline().rsplit(":", 1)[1])
    return proc, f"http://127.0.0.1:{http}/", osc_port


class Flooder:
    """FLOOD_HZ datagrams a second to ``port`` until ``stop``."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.sent = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        msgs = [osc("/biped/param/Abnc_R", v) for v in np.linspace(1.0, 5.0, 40)]
        t0 = time.monotonic()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            k = 0
            while not self._stop.is_set() and k < 100 * 600:   # 10 minutes at most
                for j in range(FLOOD_HZ // 100):
                    s.sendto(msgs[j % 40], ("127.0.0.1", self.port))
                self.sent += FLOOD_HZ // 100
                k += 1
                time.sleep(max(0.0, t0 + k / 100 - time.monotonic()))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)


def _wait_state(base: str, want: str, timeout: float = 30.0) -> None:
    end = time.monotonic() + timeout
    while (s := panel_state(base))["state"] != want:
        if time.monotonic() > end:
            raise RuntimeError(f"the panel never reached {want}: {s['state']}, "
                               f"{s.get('fault') or s.get('stop_reason')}")
        time.sleep(0.05)


def _stats(ms: list[float]) -> dict[str, Any]:
    if not ms:
        return {"n": 0}
    a = np.array(ms)
    return {"n": len(ms), "p50_ms": round(float(np.percentile(a, 50)), 2),
            "p99_ms": round(float(np.percentile(a, 99)), 2),
            "max_ms": round(float(a.max()), 2)}


def _param_latencies(log: list[Any], leg_ids: list[int], sends: list[float]) -> list[float]:
    goals = [p for p in log if p.instruction == "sync_write" and p.address == GOAL]
    t = np.array([p.t for p in goals])
    g = np.array([[p.values.get(i, 0) for i in leg_ids] for p in goals], dtype=float)
    out = []
    for ts in sends:
        j = int(np.searchsorted(t, ts))
        while j < len(t) and (j < CYCLE_TICKS or
                              np.abs(g[j] - g[j - CYCLE_TICKS]).max() <= 2.0):
            j += 1
        if j < len(t):
            out.append((t[j] - ts) * 1e3)
    return out


def _walk(base: str) -> int:
    """Walking with the amplitude ramped in (start it if it is not): 1 if it was started."""
    if panel_state(base)["state"] == "walking":
        return 0
    panel_post(base, "/api/start")
    _wait_state(base, "walking")
    time.sleep(4.3 * CYCLE_TICKS / RATE_HZ)             # the amplitude's ramp in
    return 1


def _trials(emu: Any, base: str, port: int, leg_ids: list[int], n_param: int,
            n_estop: int) -> dict[str, Any]:
    """The latencies [ms]; ``restarts``: walks started again during the parameter trials
    (the rate guard stopped one: a loaded machine)."""
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    _walk(base)
    param: list[float] = []
    restarts = 0
    for k in range(n_param):
        restarts += _walk(base)
        emu.log(clear=True)
        time.sleep(1.0 + 1.2 * CYCLE_TICKS / RATE_HZ)    # the follow settles, a cycle more
        ts = time.monotonic()
        tx.sendto(osc("/biped/param/torso_lean", LEAN if k % 2 == 0 else 0.0),
                  ("127.0.0.1", port))
        time.sleep(0.3)
        param += _param_latencies(emu.log(), leg_ids, [ts])
    estop = []
    for _ in range(n_estop):
        _walk(base)
        time.sleep(0.5)
        emu.log(clear=True)
        ts = time.monotonic()
        tx.sendto(osc("/biped/estop"), ("127.0.0.1", port))
        _wait_state(base, "estop")
        off = [p.t for p in emu.log() if p.t >= ts and p.address == TORQUE]
        if off:
            estop.append((min(off) - ts) * 1e3)
    tx.close()
    return {"param": param, "estop": estop, "restarts": restarts,
            "missed": n_param - len(param)}


def measure_osc(*, n_param: int = 30, n_estop: int = 10) -> dict[str, Any]:
    from sim.emulator.chain import Emulator
    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    legs = [j.servo_id for j in robot.joints if any(k in j.name for k in ("hip", "knee",
                                                                          "ankle"))]
    out: dict[str, Any] = {}
    with Emulator("dynamixel", robot) as emu, tempfile.TemporaryDirectory() as d:
        proc, base, port = _launch(emu.port, Path(d))
        try:
            quiet = _trials(emu, base, port, legs, n_param, n_estop)
            flooder = Flooder(port)
            try:
                flood = _trials(emu, base, port, legs, n_param, n_estop)
            finally:
                flooder.stop()
            showctl = json.loads(_get(base, "api/showctl"))
        finally:
            stop_panel(proc)
    out["param_quiet"] = _stats(quiet["param"])
    out["estop_quiet"] = _stats(quiet["estop"])
    out["param_flood"] = _stats(flood["param"])
    out["estop_flood"] = _stats(flood["estop"])
    out["flood"] = {"sent": flooder.sent, "received": showctl["osc"]["datagrams"],
                    "param_updates": showctl["feed"]["param_updates"]}
    out["walk_restarts"] = {"quiet": quiet["restarts"], "flood": flood["restarts"]}
    out["changes_not_seen"] = {"quiet": quiet["missed"], "flood": flood["missed"]}
    return out


def _get(base: str, path: str) -> str:
    req = urllib.request.Request(base + path, headers={"Authorization": f"Bearer {TOKEN}"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return str(r.read().decode())


def run_osc_bench(*, quick: bool = False) -> dict[str, Any]:
    """The `biped bench --only osc` section."""
    return measure_osc(n_param=6, n_estop=3) if quick else measure_osc()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true")
    print(json.dumps(run_osc_bench(quick=p.parse_args().quick), indent=2))


if __name__ == "__main__":
    main()
