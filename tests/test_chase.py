"""`biped play SHOW --chase`: a show follows LTC in a WAV (written by the independent
encoder of tests/ltc_encode.py) in the simulation, at 24, 25, 29.97 drop-frame and 30
fps. The oracle is the encoder's schedule: a WAV is heard from the run's start on the
loop's clock, so tick k (its deadline k / rate after the start) meets the timecode the WAV
holds at k / rate; the take's t (the show time) must stay within a frame of it (measured:
below a thousandth), and the pose must be the show's at that time. A dropout shorter than
the freewheel plays on; a longer one stops the show (ramp to rest, torque off). A jump is
met by a ramp: on the emulator, no goal on the wire beyond the slew limit, and the take's
acceleration within the import's limit. MTC over a mido socket port drives a show in real
time. Bad options: one line, exit 2, nothing moves."""

from __future__ import annotations

import json
import threading
import time
from pathlib import Path

import mido
import mido.sockets
import numpy as np
import pytest
from command_ends import assert_goals_safe
from ltc_encode import drop_frame_labels, encode, plain_labels, write_wav

import robot.cli as cli
from robot.config.robot_file import load_robot
from robot.previs.violations import accel_limits
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)

RATE_HZ = 200.0
SHOULDER = 12                       # r_shoulder_pitch in the bundled robots' joint order
#: The show: the right shoulder from -0.4 rad to +0.4 rad at 0.1 rad/s (8 s), in a line.
LINE = """name = "line"
interpolation = "smooth"
[[keyframe]]
t = 0.0
r_shoulder_pitch = -0.4
[[keyframe]]
t = 8.0
r_shoulder_pitch = 0.4
"""


def _show(tmp_path: Path) -> Path:
    path = tmp_path / "line.toml"
    path.write_text(LINE)
    return path


def _play(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict]:
    capsys.readouterr()
    code = cli.main(["play", *argv, "--json"])
    return code, json.loads(capsys.readouterr().out)


def _take(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    rows = [json.loads(line) for line in path.read_text().splitlines()[1:]]
    return (np.array([r["tick"] for r in rows]), np.array([r["t"] for r in rows]),
            np.array([r["q"] for r in rows]), [r["state"] for r in rows])


RATES = {"30": (30.0, 30, False, "01:00:00:00"), "25": (25.0, 25, False, "01:00:00:00"),
         "24": (24.0, 24, False, "01:00:00:00"),
         "29.97df": (30000 / 1001, 30, True, "00:10:00;00")}


@pytest.mark.parametrize("name", list(RATES))
def test_the_show_stays_within_a_frame_of_the_timecode(tmp_path: Path, name: str,
                                                        capsys: pytest.CaptureFixture[str]
                                                        ) -> None:
    fps, base, drop, start = RATES[name]
    pre = base                                   # a second of pre-roll, then 9 s
    labels = (drop_frame_labels(17982 - pre, 10 * base) if drop
              else plain_labels(3600 * base - pre, 10 * base, base))
    wav, take = tmp_path / "ltc.wav", tmp_path / "c.take.jsonl"
    write_wav(wav, encode(labels, fps, drop=drop))
    code, out = _play(capsys, str(_show(tmp_path)), "--chase", f"ltc:{wav}",
                      "--chase-start", start, "--record", str(take))
    assert code == 0 and out["torque"] == "off"
    chase = out["chase"]
    assert chase["fps"] == name and chase["jumps"] == 0 and chase["stopped"] == "end of show"
    ticks, t, q, states = _take(take)
    truth = ticks / RATE_HZ - pre / fps          # the WAV's timecode at each tick's deadline
    shown = np.isin(states, ["waiting", "walking"])   # then the ramp to rest: its last t
    error_frames = np.abs(t - truth)[shown] * fps
    assert error_frames.max() < 1.0 and chase["max_error_frames"] < 1.0
    assert error_frames.max() < 0.01             # measured: 0.0007 at 30 fps
    playing = [i for i, s in enumerate(states) if s == "walking"]
    assert t[playing[0]] < 1.0 / fps and t[playing[-1]] > 7.9
    assert states[0] == "waiting" and t[0] < -0.5
    shoulder = q[playing, SHOULDER]
    assert np.abs(shoulder - (-0.4 + 0.1 * t[playing])).max() < 1e-6


def _labels_with_gap(gap_frames: int) -> list:
    """30 fps: 1 s of pre-roll, 3 s of show, ``gap_frames`` of silence, then on as if the
    timecode had run through the gap, to 8 s."""
    first = plain_labels(3600 * 30 - 30, 120, 30)
    after = 3600 * 30 + 90 + gap_frames
    return first + [None] * gap_frames + plain_labels(after, 30 * 8 + 30 - 120 - gap_frames, 30)


def test_a_dropout_shorter_than_the_freewheel_plays_on(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]
                                                       ) -> None:
    wav, take = tmp_path / "gap.wav", tmp_path / "g.take.jsonl"
    write_wav(wav, encode(_labels_with_gap(8), 30.0))
    code, out = _play(capsys, str(_show(tmp_path)), "--chase", f"ltc:{wav}",
                      "--chase-start", "01:00:00:00", "--record", str(take))
    assert code == 0
    chase = out["chase"]
    assert chase["stopped"] == "end of show" and chase["dropouts"] == 1
    assert chase["jumps"] == 0 and chase["max_error_frames"] < 1.0
    ticks, t, _, states = _take(take)
    shown = np.isin(states, ["waiting", "walking"])
    assert np.abs(t - (ticks / RATE_HZ - 1.0))[shown].max() * 30 < 1.0   # freewheeled on time


def test_a_longer_dropout_stops_the_show_safely(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    wav, take = tmp_path / "gap.wav", tmp_path / "g.take.jsonl"
    write_wav(wav, encode(_labels_with_gap(40), 30.0))
    code, out = _play(capsys, str(_show(tmp_path)), "--chase", f"ltc:{wav}",
                      "--chase-start", "01:00:00:00", "--freewheel", "20",
                      "--record", str(take))
    assert code == 0 and out["torque"] == "off" and not out["holding"]
    assert out["chase"]["stopped"] == "timecode lost"
    assert out["stop_reason"].startswith("timecode lost")
    _, t, q, states = _take(take)
    assert t[-1] < 3.0 + 25 / 30                 # played on 20 frames, then stopped
    assert states[-1] == "rest"                  # the way Stop does: to rest, then off
    rest = load_robot().rest
    assert abs(q[-1, SHOULDER] - rest.get("r_shoulder_pitch", 0.0)) < 1e-6


@pytest.mark.parametrize("protocol", ["dynamixel"])
def test_a_jump_ramps_on_the_wire(emu: Emulator, robot_toml: Path, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    """0.5 s of pre-roll, 1.5 s of show, a jump to 5 s, 1 s more, then the timecode ends."""
    base = 3600 * 30
    labels = plain_labels(base - 15, 60, 30) + plain_labels(base + 150, 30, 30)
    wav, take = tmp_path / "jump.wav", tmp_path / "j.take.jsonl"
    write_wav(wav, encode(labels, 30.0))
    code, out = _play(capsys, str(_show(tmp_path)), "--bus", emu.protocol, "--port", emu.port,
                      "--robot", str(robot_toml), "--rate", "100", "--chase", f"ltc:{wav}",
                      "--chase-start", "01:00:00:00", "--record", str(take))
    assert code == 0, out
    chase = out["chase"]
    assert chase["jumps"] == 1 and chase["stopped"] == "timecode lost"
    (before, after), = chase["jumped_s"]
    assert before == pytest.approx(1.5, abs=0.05) and after == pytest.approx(5.0, abs=0.05)
    robot = load_robot(robot_toml)
    assert_goals_safe(emu, robot, 100.0)                 # no goal step beyond the slew
    assert {emu.registers(i)["torque_enable"] for i in robot.ids} == {0}
    _, t, q, _ = _take(take)
    k = int(np.argmax(np.diff(t)))
    assert t[k + 1] - t[k] > 3.0                         # the show time jumped there
    move = q[k - 2:k + 200, SHOULDER]                    # but the shoulder ramped
    assert np.abs(np.diff(move)).max() * 100 <= robot.joint("r_shoulder_pitch").max_speed_rad_s
    accel = np.abs(np.diff(move, 2)).max() * 100 * 100
    assert accel <= accel_limits(robot)[SHOULDER]
    assert abs(q[k + 1, SHOULDER] - q[k, SHOULDER]) < 0.05   # no snap to 0.1 rad/s x 3.5 s


def test_mtc_over_a_socket_port_drives_a_show(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    """A sender on loopback (mido's socket port) plays 30 fps MTC from 00:59:59:15 for 3 s
    on the wall clock; the simulated show (in real time) follows and stops when it ends."""
    server = mido.sockets.PortServer("127.0.0.1", 0)
    port = server._socket.getsockname()[1]
    sent: list[float] = []

    def send() -> None:
        conn = server.accept()
        t0 = time.monotonic()
        for k in range(3 * 30 * 4):                  # 3 s of quarter frames
            frame = 3600 * 30 - 15 + 2 * (k // 8)
            s, f = divmod(frame, 30)
            h, m, sec = s // 3600, (s // 60) % 60, s % 60
            piece = k % 8
            nib = [f & 15, f >> 4, sec & 15, sec >> 4, m & 15, m >> 4, h & 15,
                   (h >> 4) | (3 << 1)][piece]
            while time.monotonic() < t0 + k / 120.0:
                time.sleep(0.0005)
            conn.send(mido.Message("quarter_frame", frame_type=piece, frame_value=nib))
        sent.append(time.monotonic() - t0)
        conn.close()
    sender = threading.Thread(target=send, daemon=True)
    sender.start()
    take = tmp_path / "m.take.jsonl"
    try:
        code, out = _play(capsys, str(_show(tmp_path)), "--chase", f"mtc:127.0.0.1:{port}",
                          "--chase-start", "01:00:00:00", "--record", str(take))
    finally:
        sender.join(timeout=10)
        server.close()
    assert code == 0 and sent
    chase = out["chase"]
    # on the wall clock of a loaded host: jitter, judged by the 95th percentile (the
    # simulation in real time can itself fall behind the wall clock under load)
    assert chase["fps"] == "30" and chase["jumps"] == 0 and chase["stopped"] == "timecode lost"
    assert chase["p95_error_frames"] < 1.0 and chase["max_error_frames"] < 8.0
    _, t, _, states = _take(take)
    playing = [t[i] for i, s in enumerate(states) if s == "walking"]
    # it joins where the timecode is (after the ramp in, which a loaded host may start
    # late) and plays to 2.5 s, then half a second of freewheel
    assert playing and playing[0] < 1.5 and 2.4 < playing[-1] < 3.1


@pytest.mark.parametrize(("argv", "says"), [
    (["--chase-start", "01:00:00:00"], "--chase-start and --freewheel apply with --chase"),
    (["--chase", "smpte:x"], "--chase smpte:x: expected ltc:FILE.wav"),
    (["--chase", "ltc:nowhere.wav"], "--chase ltc:nowhere.wav: file not found"),
    (["--chase", "ltc:{silent}"], "no LTC found"),
    (["--chase", "ltc:{silent}", "--chase-start", "1:00"], "--chase-start '1:00': expected"),
])
def test_bad_chase_options_are_one_line(tmp_path: Path, argv: list[str], says: str,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    silent = tmp_path / "silent.wav"
    write_wav(silent, np.zeros(4800))
    capsys.readouterr()
    args = [a.replace("{silent}", str(silent)) for a in argv]
    assert cli.main(["play", str(_show(tmp_path)), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and len(err.splitlines()) == 1
