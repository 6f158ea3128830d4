"""Benchmark: a long panel session stays flat. `biped panel` walks 18 emulated Dynamixels
(the pty emulator, the real SDK) at 200 Hz for ``minutes``, watched all along by 20
WebSocket clients, with a connection flood (robot.bench.panel_flood: 800 half-sent
requests, half of them with the token, held ``hold_s`` and closed at once) every
``flood_every`` minutes.

A walk that stops (the loop's rate guard on a machine too busy for it) is restarted and
the stop reported. Sampled every ``sample_s`` from /proc: resident memory, threads and open file
descriptors of the web side (the `biped panel` process) and of the loop process (its
child), the loop's own overruns and state, the frames the clients got. Reported: the
first sample after a one-minute warm-up, the last, the largest, and the change per hour
of a least-squares line, per process; never asserted.

``python -m robot.bench.panel_soak --minutes 15 --flood-every 3`` prints JSON; `biped
bench --only panel-soak --minutes N` runs it too (not part of a plain `biped bench`).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from robot.bench.panel_flood import (
    TOKEN,
    Flood,
    launch_panel,
    panel_post,
    panel_state,
    stop_panel,
    thread_count,
)
from robot.config.bundled import ROBOTS_DIR
from robot.config.robot_file import load_robot

CLIENTS = 20
WARM_UP_S = 60.0


def _proc_figures(pid: int) -> dict[str, float]:
    """Resident memory [MiB], threads and open fds of process ``pid``."""
    rss = 0.0
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1]) / 1024
        fds = len(list(Path(f"/proc/{pid}/fd").iterdir()))
    except OSError:
        return {"rss_mib": float("nan"), "threads": 0, "fds": 0}
    return {"rss_mib": round(rss, 1), "threads": thread_count(pid), "fds": fds}


def _child_of(pid: int) -> int | None:
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            return int(stat.parent.name)
    return None


class Watchers:
    """``n`` WebSocket clients on /api/live, reconnecting if dropped; frames counted."""

    def __init__(self, base: str, n: int) -> None:
        self.url = base.replace("http://", "ws://") + f"api/live?token={TOKEN}"
        self.origin = base.rstrip("/")
        self.frames = [0] * n
        self.drops = 0
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._watch, args=(i,), daemon=True)
                         for i in range(n)]
        for t in self._threads:
            t.start()

    def _watch(self, i: int) -> None:
        from websockets.sync.client import connect
        from websockets.typing import Origin

        while not self._stop.is_set():
            try:
                with connect(self.url, origin=Origin(self.origin), open_timeout=20) as ws:
                    while not self._stop.is_set():
                        ws.recv(timeout=10)
                        self.frames[i] += 1
            except Exception:
                if not self._stop.is_set():
                    self.drops += 1
                    self._stop.wait(1.0)

    def close(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(15)


def _trend(samples: list[dict[str, Any]], key: str, who: str) -> dict[str, float]:
    rows = [s for s in samples if s["t"] >= WARM_UP_S and who in s]
    if len(rows) < 2:
        return {}
    t = np.array([r["t"] for r in rows]) / 3600.0
    v = np.array([r[who][key] for r in rows], dtype=float)
    slope = float(np.polyfit(t, v, 1)[0]) if np.ptp(t) > 0 else 0.0
    return {"first": float(v[0]), "last": float(v[-1]), "max": float(v.max()),
            "per_hour": round(slope, 2)}


def soak(*, minutes: float = 60.0, flood_every: float = 10.0, hold_s: float = 20.0,
         connections: int = 800, sample_s: float = 10.0) -> dict[str, Any]:
    """One soak (module docstring); the figures as a dict."""
    from sim.emulator.chain import Emulator

    robot = load_robot(ROBOTS_DIR / "biped18-dynamixel.toml")
    samples: list[dict[str, Any]] = []
    floods: list[dict[str, Any]] = []
    restarts: list[dict[str, Any]] = []
    with Emulator("dynamixel", robot) as emu, tempfile.TemporaryDirectory() as d:
        proc, base = launch_panel(sys.executable, emu.port, Path(d))
        port = int(base.rsplit(":", 1)[1].strip("/"))
        try:
            end = time.monotonic() + 30
            while panel_state(base)["state"] != "walking" and time.monotonic() < end:
                time.sleep(0.2)
            loop_pid = _child_of(proc.pid)
            watchers = Watchers(base, CLIENTS)
            t0 = time.monotonic()
            next_flood = t0 + flood_every * 60.0
            while time.monotonic() < t0 + minutes * 60.0:
                now = time.monotonic()
                if now >= next_flood:
                    floods.append(_one_flood(port, base, connections, hold_s, now - t0))
                    next_flood += flood_every * 60.0
                s = panel_state(base)
                if not s["running"]:       # stopped (e.g. the machine too busy): again
                    restarts.append({"at_s": round(now - t0), "why": s.get("fault")
                                     or s.get("stop_reason")})
                    panel_post(base, "/api/start")
                row: dict[str, Any] = {
                    "t": round(now - t0, 1), "state": s["state"], "overruns": s["overruns"],
                    "frames": sum(watchers.frames), "web": _proc_figures(proc.pid)}
                if loop_pid is not None:
                    row["loop"] = _proc_figures(loop_pid)
                samples.append(row)
                time.sleep(max(0.0, sample_s - (time.monotonic() - now)))
            watchers.close()
            tripped = [i for i in robot.ids if emu.registers(i)["bus_watchdog"] == -1]
        finally:
            stop_panel(proc)
    figures = {who: {k: _trend(samples, k, who) for k in ("rss_mib", "threads", "fds")}
               for who in ("web", "loop")}
    return {"minutes": minutes, "clients": CLIENTS, "floods": floods, "restarts": restarts,
            "states_seen": sorted({s["state"] for s in samples}),
            "overruns": {"first": samples[0]["overruns"], "last": samples[-1]["overruns"]}
            if samples else {},
            "frames_received": samples[-1]["frames"] if samples else 0,
            "client_drops": watchers.drops, "servo_watchdogs_tripped": len(tripped),
            "exit_code": proc.returncode, **figures, "samples": len(samples)}


def _one_flood(port: int, base: str, n: int, hold_s: float, at_s: float) -> dict[str, Any]:
    before = panel_state(base)
    halves = [Flood(port, n // 2, token=None), Flood(port, n - n // 2, token=TOKEN)]
    t_open = time.monotonic()
    while any(f.opening() for f in halves) or time.monotonic() < t_open + hold_s:
        for f in halves:
            f.drip()
        time.sleep(2.0)
    for f in halves:
        f.close()
    time.sleep(2.0)
    after = panel_state(base)
    return {"at_s": round(at_s), "overruns": after["overruns"] - before["overruns"],
            "ticks": after["tick"] - before["tick"], "state_after": after["state"],
            "refused_at_connect": sum(f.refused for f in halves)}


def run_soak_bench(*, quick: bool = False, minutes: float | None = None) -> dict[str, Any]:
    if minutes is None:
        minutes = 3.0 if quick else 60.0
    return soak(minutes=minutes, flood_every=1.0 if quick else min(10.0, minutes / 4))


def main() -> None:
    ap = argparse.ArgumentParser(prog="python -m robot.bench.panel_soak")
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--flood-every", type=float, default=10.0, metavar="MINUTES")
    ap.add_argument("--hold", type=float, default=20.0, metavar="SECONDS")
    a = ap.parse_args()
    print(json.dumps(soak(minutes=a.minutes, flood_every=a.flood_every, hold_s=a.hold),
                     indent=2))


if __name__ == "__main__":
    main()
