"""Benchmark: does a connection flood on the panel's HTTP port reach the control loop?

`biped panel` walks 18 emulated Dynamixels (the pty emulator, the real SDK, wall clock) at
200 Hz, served on every address with a token. Another process opens ``connections``
half-sent requests (the request line and a header that never ends, one more byte every
``drip_s``: slowloris), without the token or with it, holds them ``hold_s`` and closes them
all at once. Judged from outside the panel, so the same measurement runs on any version:

- the wire: the goal packets' arrival times in the emulator's log (the loop's period as
  the servos see it: worst gap, p99, gaps over 2 periods) in the windows before the
  flood, while it holds, and after the close; and every servo's Bus Watchdog at the end
  (-1: tripped, the servo now ignores goals);
- the loop's own counters from ``/api/state`` (overruns, state, the rate it reports);
- the panel process's threads (``/proc/<pid>/status``) at their peak.

Never asserted (a benchmark). ``python -m robot.bench.panel_flood [--connections N]
[--hold S] [--with-token]`` prints JSON; `biped bench --only panel-flood` runs it too.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np

from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot

RATE_HZ = 200.0
TOKEN = "flood-bench-t0ken"
GOAL_ADDRESS = 116  # Dynamixel X Goal Position (e-Manual)


def _robot_file(tmp: Path) -> Path:
    """The bundled 18-servo Dynamixel robot with a reply timeout for a busy machine."""
    text = (ROBOTS_DIR / "biped18-dynamixel.toml").read_text()
    path = tmp / "robot.toml"
    path.write_text(text.replace("timeout_ms = 20.0", "timeout_ms = 50.0"))
    return path


def panel_state(base: str) -> dict[str, Any]:
    req = urllib.request.Request(base + "api/state",
                                 headers={"Authorization": f"Bearer {TOKEN}"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return dict(json.load(r))


def panel_post(base: str, path: str) -> int:
    """POST ``path`` (an empty JSON body) with the token; the status."""
    req = urllib.request.Request(base + path.lstrip("/"), data=b"{}", method="POST",
                                 headers={"Authorization": f"Bearer {TOKEN}",
                                          "Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return int(r.status)
    except urllib.error.HTTPError as e:
        return int(e.code)


def stop_panel(proc: subprocess.Popen[str], timeout: float = 60.0) -> None:
    """SIGTERM (a safe stop) and wait; killed if it has not ended after ``timeout`` [s]."""
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def thread_count(pid: int) -> int:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("Threads:"):
                return int(line.split()[1])
    except OSError:
        pass
    return 0


class Flood:
    """``n`` half-sent requests to 127.0.0.1:``port``, opened by ``OPENERS`` threads at once
    (as an attacker would; a server that accepts slowly keeps them in its backlog) while
    ``drip()`` sends one more byte on each one already open."""

    OPENERS = 16

    def __init__(self, port: int, n: int, *, token: str | None) -> None:
        head = f"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
        if token:
            head += f"Authorization: Bearer {token}\r\n"
        self.head = (head + "X-Slow: ").encode()
        self.port = port
        self.socks: list[socket.socket] = []
        self.refused = 0
        self._lock = threading.Lock()
        share = [n // self.OPENERS + (k < n % self.OPENERS) for k in range(self.OPENERS)]
        self._openers = [threading.Thread(target=self._open, args=(m,), daemon=True)
                         for m in share]
        for t in self._openers:
            t.start()

    def _open(self, m: int) -> None:
        for _ in range(m):
            try:
                s = socket.create_connection(("127.0.0.1", self.port), timeout=5)
                s.sendall(self.head)
            except OSError:
                with self._lock:
                    self.refused += 1
                continue
            with self._lock:
                self.socks.append(s)

    def opening(self) -> bool:
        return any(t.is_alive() for t in self._openers)

    def drip(self) -> int:
        """One more byte on every connection open so far; returns how many took it."""
        with self._lock:
            socks = list(self.socks)
        alive = 0
        for s in socks:
            try:
                s.send(b"a", socket.MSG_DONTWAIT)
                alive += 1
            except OSError:
                pass
        return alive

    def close(self) -> None:
        for t in self._openers:
            t.join()
        for s in self.socks:
            s.close()


def _gaps_ms(times: np.ndarray, lo: float, hi: float) -> dict[str, float]:
    t = times[(times >= lo) & (times <= hi)]
    if len(t) < 2:
        return {"goals": int(len(t)), "worst_ms": float("nan")}
    gaps = np.diff(t) * 1e3
    period = 1e3 / RATE_HZ
    return {"goals": int(len(t)), "rate_hz": round((len(t) - 1) / (t[-1] - t[0]), 1),
            "p99_ms": round(float(np.percentile(gaps, 99)), 2),
            "worst_ms": round(float(gaps.max()), 2),
            "gaps_over_2_periods": int((gaps > 2 * period).sum())}


def _rates(states: list[dict[str, Any]], times: list[float]) -> dict[str, float]:
    """Overruns per second in the windows before the flood, while it held, after it."""
    n = [int(s.get("overruns", 0)) for s in states]
    return {w: round((n[k + 1] - n[k]) / max(times[k + 1] - times[k], 1e-9), 1)
            for k, w in enumerate(("quiet", "holding", "after_close"))}


def launch_panel(python: str, emu_port: str, tmp: Path) -> tuple[subprocess.Popen[str], str]:
    """`biped panel` (run by ``python``) on every address with ``TOKEN``, walking the
    emulated chain on ``emu_port``; the process and its loopback base URL."""
    cmd = [python, "-m", "robot.cli", "panel", "--bus", "dynamixel", "--port", emu_port,
           "--robot", str(_robot_file(tmp)), "--host", "0.0.0.0", "--token", TOKEN,
           "--http-port", "0", "--rate", f"{RATE_HZ:g}", "--presets-dir", str(tmp / "p"),
           "--studio-dir", str(tmp / "s")]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            cwd=tmp, env={**os.environ, "MUJOCO_GL": "egl"})
    assert proc.stdout is not None
    line = proc.stdout.readline()
    port = int(line.split("127.0.0.1:")[1].split("/")[0]) if "127.0.0.1:" in line else \
        int(line.split(" open http://")[1].split("/")[0].rsplit(":", 1)[1])
    return proc, f"http://127.0.0.1:{port}/"


def measure_flood(*, connections: int = 800, hold_s: float = 20.0, drip_s: float = 4.0,
                  with_token: bool = False, settle_s: float = 5.0,
                  python: str = sys.executable) -> dict[str, Any]:
    """One flood on a walking panel (module docstring); the figures as a dict."""
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    seen: dict[str, Any] = {"states": set(), "threads_max": 0, "reported_hz_min": None}
    with Emulator("dynamixel", robot) as emu, tempfile.TemporaryDirectory() as d:
        proc, base = launch_panel(python, emu.port, Path(d))
        port = int(base.rsplit(":", 1)[1].strip("/"))
        try:
            end = time.monotonic() + 30
            while panel_state(base)["state"] != "walking":
                if time.monotonic() > end:
                    raise RuntimeError("the panel never reached walking")
                time.sleep(0.1)
            t_base, start = time.monotonic(), panel_state(base)
            time.sleep(settle_s)
            before = panel_state(base)
            t_flood = time.monotonic()
            flood = Flood(port, connections, token=TOKEN if with_token else None)
            stop = threading.Event()

            def watch() -> None:
                while not stop.wait(0.25):
                    seen["threads_max"] = max(seen["threads_max"], thread_count(proc.pid))
                    try:
                        s = panel_state(base)
                    except OSError:
                        continue
                    seen["states"].add(s["state"])
                    hz = s.get("loop_hz")
                    if hz and s["state"] == "walking":
                        low = seen["reported_hz_min"]
                        seen["reported_hz_min"] = hz if low is None else min(low, hz)
            watcher = threading.Thread(target=watch, daemon=True)
            watcher.start()
            alive, next_drip = 0, time.monotonic() + drip_s
            while flood.opening() or time.monotonic() < t_flood + hold_s:
                if time.monotonic() >= next_drip:
                    alive = flood.drip()
                    next_drip += drip_s
                time.sleep(0.05)
            opened_s = time.monotonic() - t_flood
            alive = flood.drip()
            held = panel_state(base)
            t_close = time.monotonic()
            flood.close()
            time.sleep(settle_s)
            stop.set()
            watcher.join(5)
            after = panel_state(base)
            tripped = [i for i in robot.ids if emu.registers(i)["bus_watchdog"] == -1]
            goals = np.array([p.t for p in emu.log() if p.instruction == "sync_write"
                              and p.address == GOAL_ADDRESS])
        finally:
            stop_panel(proc)
    return {
        "connections": connections, "with_token": with_token, "hold_s": hold_s,
        "refused_at_connect": flood.refused, "still_open_at_close": alive,
        "flood_s": round(opened_s, 1),
        "panel_threads_max": seen["threads_max"],
        "wire_before": _gaps_ms(goals, t_base, t_flood),
        "wire_holding": _gaps_ms(goals, t_flood, t_close),
        "wire_after_close": _gaps_ms(goals, t_close, t_close + settle_s),
        "overruns": {"start": start.get("overruns"), "before": before.get("overruns"),
                     "holding": held.get("overruns"), "after": after.get("overruns")},
        "overruns_per_s": _rates([start, before, held, after],
                                 [t_base, t_flood, t_close, t_close + settle_s]),
        "loop_hz_reported_min": seen["reported_hz_min"],
        "states_seen": sorted(seen["states"]), "state_after": after.get("state"),
        "fault_after": after.get("fault"),
        "servo_watchdogs_tripped": len(tripped), "exit_code": proc.returncode}


def run_flood_bench(*, quick: bool = False) -> dict[str, Any]:
    n, hold = (200, 8.0) if quick else (800, 20.0)
    return {f"{'with' if tok else 'without'}_token": measure_flood(
        connections=n, hold_s=hold, with_token=tok) for tok in (False, True)}


def main() -> None:
    ap = argparse.ArgumentParser(prog="python -m robot.bench.panel_flood")
    ap.add_argument("--connections", type=int, default=800)
    ap.add_argument("--hold", type=float, default=20.0)
    ap.add_argument("--with-token", action="store_true")
    ap.add_argument("--python", default=sys.executable,
                    help="the interpreter that runs `biped panel` (another checkout's venv)")
    a = ap.parse_args()
    print(json.dumps(measure_flood(connections=a.connections, hold_s=a.hold,
                                   with_token=a.with_token, python=a.python), indent=2))


if __name__ == "__main__":
    main()
