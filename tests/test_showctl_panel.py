"""Show control through the command line, on the pty emulator: MIDI into `biped panel` over
mido's socket ports (a PortServer here; the machine has no MIDI system) — a control change
moves a parameter, a note records a take, MIDI Show Control GO fires a cue and STOP ends
the take, learn through the panel's HTTP API writes the mapping — and `biped play --osc`
stopped by a cue and by /biped/estop, judged at the wire. Bad files: one line, exit 2."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import mido
import mido.sockets
import pytest
from bus_harness import robot_for
from panel_wire import REPO, Panel, assert_estop_held, is_goal, launched, patient_robot_file, torque_now
from panel_wire import osc_datagram as osc
from waiting import wait_for

from robot.config.robot import RobotConfig
from robot.showctl.midi_map import load_map
from sim.emulator.chain import Emulator

MAP = """
[[cc]]
channel = 1
cc = 7
param = "speed"
range = [0.0, 1.5]

[[note]]
channel = 1
note = 60
record = "from-midi"
"""
CUES = """
[[cue]]
number = "4"
name = "faster"
preset = "jog"

[[cue]]
number = "5"
name = "halt"
do = "stop"
"""


@pytest.fixture(scope="module")
def chain() -> Iterator[tuple[Emulator, RobotConfig]]:
    robot = robot_for("dynamixel")
    with Emulator("dynamixel", robot, seed=5) as emu:
        yield emu, robot




def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_midi_drives_the_panel_and_learn_writes_the_mapping(
        chain: tuple[Emulator, RobotConfig], tmp_path: Path) -> None:
    emu, _ = chain
    mapping, cues = tmp_path / "midi.toml", tmp_path / "cues.toml"
    mapping.write_text(MAP)
    cues.write_text(CUES)
    port = _free_port()
    server = mido.sockets.PortServer("127.0.0.1", port)
    try:
        with launched(emu, patient_robot_file(tmp_path), tmp_path, "--midi", f"socket:127.0.0.1:{port}",
                      "--midi-map", str(mapping), "--cues", str(cues)) as panel:
            # The panel connects; mido's PortServer.poll() blocks (mido 1.3.3), accept does not.
            client: list[mido.ports.BaseIOPort] = []
            assert wait_for(lambda: bool(client) or bool(
                (c := server.accept(block=False)) and client.append(c) is None)), panel.err
            _drive(panel, client[0], mapping)
            client[0].close()
    finally:
        server.close()


def _param(panel: Panel, name: str) -> float:
    return float(panel.request("GET", "/api/params")[1]["params"][name])


def _drive(panel: Panel, server: mido.ports.BaseIOPort, mapping: Path) -> None:
    server.send(mido.Message("control_change", channel=0, control=7, value=127))
    assert wait_for(lambda: _param(panel, "speed") == 1.5), panel.err
    server.send(mido.Message("note_on", channel=0, note=60, velocity=90))
    assert wait_for(lambda: panel.state()["running"]), panel.err
    assert wait_for(lambda: panel.request("GET", "/api/sequences")[1]["recording"]
                    == "from-midi")
    # MSC GO, cue 4 (RP-002: F0 7F <all-call> 02 <lighting> <GO> "4" F7): a preset, live.
    server.send(mido.Message("sysex", data=[0x7F, 0x7F, 0x02, 0x01, 0x01, *b"4"]))
    assert wait_for(lambda: panel.request("GET", "/api/params")[1]["preset"] == "jog")
    # Learn: touch a slider (the API the page calls), move a fader.
    status, reply = panel.request("POST", "/api/midi/learn", {"param": "torso_lean"})
    assert status == 200 and reply["learning"] == "torso_lean", reply
    assert panel.request("GET", "/api/showctl")[1]["midi"]["learning"] == "torso_lean"
    server.send(mido.Message("control_change", channel=2, control=20, value=0))
    assert wait_for(lambda: _param(panel, "torso_lean") == -0.4), panel.err
    learned = load_map(mapping).cc_for(3, 20)
    assert learned is not None and (learned.param, learned.lo, learned.hi) == (
        "torso_lean", -0.4, 0.4)
    assert load_map(mapping).cc_for(1, 7) is not None      # what was there stays
    report = panel.request("GET", "/api/showctl")[1]["midi"]
    assert report["learning"] is None and report["last"] == {
        "type": "cc", "channel": 3, "cc": 20, "value": 0}
    # MSC STOP ends the take (ramp out, rest): it is on disk, whole.
    server.send(mido.Message("sysex", data=[0x7F, 0x7F, 0x02, 0x01, 0x02]))
    assert wait_for(lambda: not panel.state()["running"]), panel.state()
    assert panel.request("GET", "/api/takes")[1]["takes"] == ["from-midi"]
    bad = panel.request("POST", "/api/midi/learn", {"param": "nope"})
    assert bad[0] == 400 and "unknown gait parameter 'nope'" in bad[1]["error"]


@pytest.mark.parametrize(("args", "where"), [
    (["--midi-map", "{bad}"], "{bad}: cc[0].param"),
    (["--cues", "{bad}"], "{bad}: cue[0]"),
    (["--osc", "9000", "--osc-host", "0.0.0.0"], "--osc-allow: listening on 0.0.0.0"),
    (["--osc", "9000", "--osc-reply", "nowhere"], "--osc-reply 'nowhere'"),
])
def test_bad_show_control_options_are_one_line_and_exit_2(tmp_path: Path, args: list[str],
                                                           where: str) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text('[[cc]]\nchannel = 1\ncc = 7\nparam = "sped"\n' if "--midi-map" in args
                   else '[[cue]]\ndo = "stop"\n')
    argv = [a.format(bad=bad) for a in args]
    r = subprocess.run([sys.executable, "-m", "robot.cli", "panel", "--http-port", "0",
                        "--studio-dir", str(tmp_path), *argv], cwd=REPO, capture_output=True,
                       text=True, timeout=120)
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert where.format(bad=bad) in lines[0], lines[0]
    assert not (tmp_path / "takes").exists()


# ------------------------------------------------------------------------------ play
SEQUENCE = """
name = "sway"
interpolation = "min_jerk"
loop = true
[[keyframe]]
t = 0.0
r_shoulder_pitch = 0.0
[[keyframe]]
t = 1.0
r_shoulder_pitch = -0.6
[[keyframe]]
t = 2.0
r_shoulder_pitch = 0.0
"""




def _play(emu: Emulator, tmp: Path, *extra: str
          ) -> tuple[subprocess.Popen[str], int, list[str], threading.Thread]:
    seq = tmp / "sway.toml"
    seq.write_text(SEQUENCE)
    cues = tmp / "cues.toml"
    cues.write_text(CUES)
    proc = subprocess.Popen(
        [sys.executable, "-m", "robot.cli", "play", str(seq), "--bus", "dynamixel", "--port",
         emu.port, "--robot", str(patient_robot_file(tmp)), "--seconds", "60", "--json", "--osc", "0",
         "--cues", str(cues), *extra], cwd=REPO, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True)
    assert proc.stderr is not None
    err: list[str] = []
    found: list[int] = []

    def read() -> None:
        assert proc.stderr is not None
        for line in iter(proc.stderr.readline, ""):
            err.append(line)
            if "OSC on 127.0.0.1:" in line:
                found.append(int(line.split("OSC on 127.0.0.1:")[1].split()[0]))
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    assert wait_for(lambda: bool(found) or proc.poll() is not None), err
    assert found, "".join(err)
    return proc, found[0], err, reader


def _moving(emu: Emulator) -> bool:
    return sum(is_goal(p, "dynamixel") for p in emu.log()) > 50


@pytest.mark.parametrize("how", ["cue", "estop"])
def test_play_stops_on_a_cue_and_on_the_estop(chain: tuple[Emulator, RobotConfig],
                                              tmp_path: Path, how: str) -> None:
    emu, robot = chain
    emu.log(clear=True)
    proc, port, err, reader = _play(emu, tmp_path)
    try:
        assert wait_for(lambda: _moving(emu)), "".join(err)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            for _ in range(20):                   # what a play does not take: logged once
                s.sendto(osc("/biped/param/speed", 0.5), ("127.0.0.1", port))
                s.sendto(osc("/biped/cue", "faster"), ("127.0.0.1", port))
            sent = time.monotonic()
            s.sendto(osc("/biped/cue", 5) if how == "cue" else osc("/biped/estop"),
                     ("127.0.0.1", port))
        out, _ = proc.communicate(timeout=60)
        reader.join(10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    result = json.loads(out)
    assert torque_now(emu, robot) == {i: 0 for i in robot.ids}
    log = emu.log()
    if how == "estop":
        assert result["stop_reason"] == "emergency stop (show control)", result
        assert_estop_held(robot, log, "dynamixel", sent)
    else:
        assert result["stop_reason"] == "show control: stop" and result["exit_code"] == 0
        goals = [p for p in log if p.t >= sent and is_goal(p, "dynamixel")]
        assert len(goals) >= 0.3 * 200 - 1, "a cue's stop ramps to rest (0.3 s at least)"
    if how == "cue":        # queued before the cue (an e-stop goes before everything)
        ignored = [e for e in err if "does nothing during biped play" in e or
                   "/biped/param/... is ignored" in e]
        assert len(ignored) == 2, "".join(err)
