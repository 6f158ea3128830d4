"""OSC to a running `biped panel` on the pty emulator (18 Dynamixels, the real SDK), judged
at the wire: a parameter sent over OSC moves the servos as the same change from the panel's
API does, and ``/biped/estop`` ends with torque off on every servo and nothing moving after
it, also while 10,000 other messages a second arrive (and the loop keeps its rate).

The OSC datagrams are built by python-osc's own builder; the oracles are the emulator's
packet log and registers (panel_wire: addresses from the manuals).
"""

from __future__ import annotations

import math
import socket
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from bus_harness import robot_for
from panel_wire import (
    TORQUE_ADDRESS,
    Panel,
    assert_estop_held,
    is_goal,
    launched,
    patient_robot_file,
    torque_now,
)
from panel_wire import osc_datagram as osc
from waiting import sleep_until, wait_for

from robot.config.robot import RobotConfig
from sim.emulator.chain import Emulator, Packet

RATE = 200.0
CYCLE_S = 0.8                                  # the walk with fps set for 160 ticks a cycle
N = int(round(CYCLE_S * RATE))
FPS = 2 * math.pi / (0.3 * CYCLE_S)            # walk's vM = 0.3 (robot/configs/gaits)
LEAN = 0.25                                    # torso_lean [rad]: exact in float32
FLOOD_HZ = 10_000
LEG = ("hip", "knee", "ankle")                 # the legs follow the main phase only




@pytest.fixture(scope="module")
def chain() -> Iterator[tuple[Emulator, RobotConfig]]:
    robot = robot_for("dynamixel")
    with Emulator("dynamixel", robot, seed=3) as emu:
        yield emu, robot




@pytest.fixture
def served(chain: tuple[Emulator, RobotConfig], tmp_path: Path
           ) -> Iterator[tuple[Panel, int]]:
    """The panel (not walking) and its OSC port."""
    emu, _ = chain
    with launched(emu, patient_robot_file(tmp_path), tmp_path, "--osc", "0", "--set", f"fps={FPS!r}",
                  rate=RATE) as panel:
        assert panel.proc.stdout is not None
        line = panel.proc.stdout.readline()
        assert "OSC on 127.0.0.1:" in line, line + "".join(panel.err)
        yield panel, int(line.rsplit(":", 1)[1])


def _send(port: int, data: bytes) -> None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.sendto(data, ("127.0.0.1", port))


def _walking(panel: Panel) -> None:
    assert wait_for(lambda: panel.state()["state"] == "walking"), panel.state()


def _stopped(panel: Panel) -> None:
    assert panel.request("POST", "/api/stop")[0] == 200
    assert wait_for(lambda: not panel.state()["running"]), panel.state()


def _goals(log: list[Packet], ids: list[int], t0: float) -> np.ndarray:
    """Each goal packet after ``t0``: the goals of ``ids`` [ticks], one row a tick."""
    rows = [[p.values[i] for i in ids] for p in log if p.t >= t0 and is_goal(p, "dynamixel")]
    return np.array(rows, dtype=float)


def _one_change(emu: Emulator, panel: Panel, send: Callable[[], object]
                ) -> tuple[np.ndarray, np.ndarray]:
    """Walk, change torso_lean by ``send()``, and return a cycle of leg goals before it and
    one long after it (converged), each N ticks."""
    robot = robot_for("dynamixel")
    ids = [j.servo_id for j in robot.joints if any(k in j.name for k in LEG)]
    assert panel.request("POST", "/api/params", {"torso_lean": 0.0})[0] == 200
    emu.log(clear=True)
    assert panel.request("POST", "/api/start")[0] == 200
    _walking(panel)
    # the amplitude ramps in over ~3 cycles: the loop says when it is whole (on a loaded
    # machine the wall clock's cycles are not the loop's)
    assert wait_for(lambda: panel.state().get("amplitude", 0.0) >= 0.999, timeout_s=30), \
        panel.state()
    t_full = time.monotonic()
    sleep_until(t_full + 1.1 * CYCLE_S)
    t_change = time.monotonic()
    send()
    assert wait_for(lambda: panel.request("GET", "/api/params")[1]["params"]["torso_lean"]
                    == LEAN)
    sleep_until(t_change + 1.0 + 1.2 * CYCLE_S)     # 10 time constants of the follow, then
    log = emu.log()                                 # a cycle
    before = _goals(log, ids, t_full)[:N]
    after = _goals(log, ids, t_change + 1.0)[:N]
    _stopped(panel)
    assert before.shape == after.shape == (N, len(ids)), (before.shape, after.shape)
    return before, after


def _cyclic_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The smallest, over every shift of ``b`` by whole ticks, of the largest difference
    [ticks] between two cycles of the same periodic stream."""
    return min(float(np.abs(a - np.roll(b, s, axis=0)).max()) for s in range(len(b)))


def test_an_osc_parameter_moves_the_servos_as_the_panel_does(
        chain: tuple[Emulator, RobotConfig], served: tuple[Panel, int]) -> None:
    emu, _ = chain
    panel, port = served
    before_http, after_http = _one_change(
        emu, panel, lambda: panel.request("POST", "/api/params", {"torso_lean": LEAN}))
    before_osc, after_osc = _one_change(
        emu, panel, lambda: _send(port, osc("/biped/param/torso_lean", LEAN)))
    moved = _cyclic_distance(before_osc, after_osc)
    assert moved >= 20, f"torso_lean {LEAN} moved the legs only {moved} ticks"
    assert _cyclic_distance(before_http, before_osc) <= 1.0
    assert _cyclic_distance(after_http, after_osc) <= 1.0, "OSC and the panel disagree"
    report = panel.request("GET", "/api/showctl")[1]
    assert report["feed"]["param_updates"] == 1 and report["feed"]["ignored"] == {}


def _flood(port: int, seconds: float, stop: threading.Event) -> int:
    """FLOOD_HZ datagrams a second for ``seconds`` (bounded): parameter changes, a few
    wrong ones among them; how many were sent."""
    good = [osc("/biped/param/speed", v) for v in np.linspace(0.6, 1.2, 50)]
    bad = [osc("/biped/param/speed", "fast"), osc("/biped/nothing", 1.0),
           osc("/biped/param/speed", 9.0)]
    batch = FLOOD_HZ // 100
    sent, t0 = 0, time.monotonic()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for k in range(int(seconds * 100)):
            if stop.is_set():
                break
            for j in range(batch):
                n = sent + j
                s.sendto(bad[n % 3] if n % 97 == 0 else good[n % 50], ("127.0.0.1", port))
            sent += batch
            sleep_until(t0 + (k + 1) / 100)
    return sent


@pytest.mark.parametrize("flood", [False, True], ids=["quiet", "flood"])
def test_osc_estop_ends_with_torque_off_and_nothing_after(
        chain: tuple[Emulator, RobotConfig], served: tuple[Panel, int], flood: bool) -> None:
    emu, robot = chain
    panel, port = served
    _send(port, osc("/biped/start", 1.0))            # a TouchOSC button's press
    _walking(panel)
    stop, sent = threading.Event(), [0]
    flooder = threading.Thread(target=lambda: sent.__setitem__(0, _flood(port, 4.0, stop)))
    t0 = time.monotonic()
    if flood:
        flooder.start()
    sleep_until(t0 + 2.0)
    s1 = panel.state()
    walking_in_flood = s1["running"] and s1["state"] in ("walking", "late")
    estop_sent = time.monotonic()
    _send(port, osc("/biped/estop"))
    assert wait_for(lambda: panel.state()["state"] == "estop"), panel.state()
    if flood:
        flooder.join(10)
    stop.set()
    t_end = time.monotonic()
    log = emu.log()
    assert_estop_held(robot, log, "dynamixel", estop_sent)
    assert torque_now(emu, robot) == {i: 0 for i in robot.ids}
    first_off = min(p.t for p in log if p.t >= estop_sent
                    and p.address == TORQUE_ADDRESS["dynamixel"])
    report = panel.request("GET", "/api/showctl")[1]
    where = (f"e-stop on the wire {1e3 * (first_off - estop_sent):.1f} ms after it was "
             f"sent; {sent[0]} flood datagrams; {report}")
    assert walking_in_flood, (where, s1)
    assert report["feed"]["estops"] == 1, where
    if flood:
        assert sent[0] >= 0.9 * FLOOD_HZ * 2.0, where
        # Coalesced: at most one update a control tick went on to the loop (of 40,000).
        assert report["feed"]["param_updates"] <= RATE * (t_end - t0) + 5, where
        assert set(report["feed"]["ignored"]) == {"type /biped/param/speed", "address",
                                                  "value /biped/param/speed"}, where
        assert [i for i in robot.ids if emu.registers(i)["bus_watchdog"] == -1] == [], where
    time_after = time.monotonic()
    sleep_until(time_after + 0.5)                    # still nothing moving half a second on
    late = [p for p in emu.log() if p.t >= time_after and is_goal(p, "dynamixel")]
    assert late == [], f"{len(late)} goals after the e-stop"
