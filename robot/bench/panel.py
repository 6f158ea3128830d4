"""Benchmark: does the panel's audience slow the control loop?

The panel walks the robot on the pty emulator (18 Dynamixels, the real SDK, wall clock)
at 200 Hz, and N clients in another process watch it, either as the old page did
(polling ``/api/state`` every 100 ms after each answer) or as the page does now (one
WebSocket each on ``/api/live``). Reported per (mode, N): loop overruns in the window,
period-error percentiles, and how many state snapshots the server made; never asserted.

``python -m robot.bench.panel [--seconds S] [--clients 0,20,50]`` prints JSON; `biped bench
--only panel` runs it too.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np

from robot.bus.factory import make_bus
from robot.config.bundled import ROBOTS_DIR
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.loop.streamer import Telemetry
from robot.panel.controller import LoopOptions, make_controller
from robot.panel.server import build_server, serve_in_thread
from robot.panel.studio import Studio

POLL_S = 0.1  # the old page: the next poll 100 ms after each answer


def _client_main(mode: str, n: int, base: str, seconds: float) -> None:
    """In the client process: ``n`` watchers for ``seconds``; prints what they received."""
    stop = time.monotonic() + seconds
    got = [0] * n

    def poll(i: int) -> None:
        while time.monotonic() < stop:
            with urllib.request.urlopen(base + "api/state", timeout=10) as r:
                r.read()
            got[i] += 1
            time.sleep(POLL_S)

    def live(i: int) -> None:
        from websockets.sync.client import connect
        from websockets.typing import Origin

        url = base.replace("http://", "ws://") + "api/live"
        with connect(url, origin=Origin(base.rstrip("/")), open_timeout=20) as ws:
            while time.monotonic() < stop:
                ws.recv(timeout=10)
                got[i] += 1

    threads = [threading.Thread(target=poll if mode == "poll" else live, args=(i,))
               for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print(json.dumps({"received": sum(got)}))


def _window(mode: str, n: int, seconds: float) -> dict[str, Any]:
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    lateness: list[float] = []
    overruns: list[int] = []
    recording = threading.Event()

    def observe(tel: Telemetry) -> None:
        if recording.is_set():
            lateness.append(tel.period_error_ms)
            overruns.append(tel.overruns)
    with Emulator("dynamixel", robot) as emu, tempfile.TemporaryDirectory() as tmp:
        bus = make_bus("dynamixel", robot=robot, port=emu.port, timeout_ms=50.0)
        controller = make_controller(robot, bus, load_gait("walk").params,
                                     options=LoopOptions(rate_hz=200.0, read_every=10))
        server = build_server(controller, port=0, studio=Studio(
            controller, takes_dir=Path(tmp) / "t", keys_dir=Path(tmp) / "k"))
        _, base = serve_in_thread(server)
        hub = server.hub
        try:
            controller.start(observer=observe)
            end = time.monotonic() + 20
            while controller.state()["state"] != "walking" and time.monotonic() < end:
                time.sleep(0.05)
            client = None
            if n:
                client = subprocess.Popen(
                    [sys.executable, "-m", "robot.bench.panel", "--client", mode, str(n),
                     base, str(seconds + 1.0)], stdout=subprocess.PIPE, text=True)
                time.sleep(1.0)  # let them connect
            frames0 = hub.frames
            recording.set()
            time.sleep(seconds)
            recording.clear()
            frames = hub.frames - frames0
            received = 0
            if client is not None:
                out, _ = client.communicate(timeout=60)
                received = json.loads(out.strip().splitlines()[-1])["received"]
            running = controller.running
        finally:
            if controller.running:
                controller.stop()
                controller.wait(20)
            server.shutdown()
            server.server_close()
            controller.shutdown(timeout=10)
    lat = np.asarray(lateness) if lateness else np.zeros(1)
    return {"mode": mode, "clients": n, "seconds": seconds, "ticks": len(lateness),
            "overruns": (overruns[-1] - overruns[0]) if overruns else 0,
            "period_error_p50_ms": round(float(np.percentile(lat, 50)), 3),
            "period_error_p99_ms": round(float(np.percentile(lat, 99)), 3),
            "period_error_max_ms": round(float(lat.max()), 3),
            "received_by_clients": received, "live_snapshots": frames,
            "loop_still_running": running}


def run_panel_bench(*, quick: bool = False, clients: tuple[int, ...] = (0, 20, 50),
                    seconds: float | None = None) -> dict[str, Any]:
    secs = seconds or (3.0 if quick else 10.0)
    out: dict[str, Any] = {}
    for n in clients:
        for mode in ("poll", "ws") if n else ("poll",):
            key = "idle" if not n else f"{mode}_{n}"
            out[key] = _window(mode, n, secs)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(prog="python -m robot.bench.panel")
    ap.add_argument("--client", nargs=4, metavar=("MODE", "N", "BASE", "SECONDS"))
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--clients", default="0,20,50")
    a = ap.parse_args()
    if a.client:
        mode, n, base, secs = a.client
        _client_main(mode, int(n), base, float(secs))
        return
    counts = tuple(int(c) for c in a.clients.split(","))
    print(json.dumps(run_panel_bench(clients=counts, seconds=a.seconds), indent=2))


if __name__ == "__main__":
    main()
