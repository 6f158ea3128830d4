"""Takes: record a performance (parameter timeline + joint stream), replay it.

Replaying the timeline in the simulation reproduces the recorded joint stream (1e-6 rad;
in practice bit for bit) whether the take came from `biped walk --record` or from the
panel with changes made live at whatever tick they happened to land on. On the pty
emulator (real vendor SDK) `biped play` ends like a walk: judged from the servos'
registers, torque off and every goal inside the joint limits. Bad take files are refused
with one line naming the file and line, before anything moves."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import numpy as np
import pytest
from waiting import wait_for

import robot.cli as cli
from robot.config.bundled import DEFAULT_ROBOT
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.errors import ConfigError
from robot.motion.takes import read_take
from robot.panel.controller import BusSpec, LoopOptions, make_controller
from robot.panel.studio import Studio
from robot.servo.models import MODELS
from sim.emulator.chain import Emulator

pytest_plugins = ("bus_harness",)
TOL = 1e-6  # [rad]


def biped(*args: str) -> int:
    return cli.main(list(args))


def test_walk_record_then_play_reproduces_the_stream(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]
                                                     ) -> None:
    take, replay = tmp_path / "walk.take.jsonl", tmp_path / "replay.take.jsonl"
    assert biped("walk", "--seconds", "2", "--set", "turn=0.15", "--set", "speed=0.8",
                 "--record", str(take)) == 0
    assert biped("play", str(take), "--record", str(replay), "--json") == 0
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out["balance"] is True and out["exit_code"] == 0
    a, b = read_take(take), read_take(replay)
    assert a.header.params.turn == 0.15 and a.header.balance
    assert a.stop_tick is not None and abs(a.stop_tick - 400) <= 1  # 2 s at 200 Hz
    assert a.q.shape == b.q.shape and len(a.q) > 400
    assert np.max(np.abs(a.q - b.q)) <= TOL
    assert a.states == b.states and a.states[-1] == "rest"


def test_panel_take_with_live_changes_replays_exactly(tmp_path: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    controller = make_controller(robot, BusSpec("sim"), load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 preset="walk")
    studio = Studio(controller, takes_dir=tmp_path / "takes", keys_dir=tmp_path / "keys")
    # The sim runs faster than real time here; changes arrive from another thread at
    # whatever ticks they land on, as a phone's would.
    name = studio.record("live")
    done = threading.Event()

    def ticks() -> int:
        return int(controller.state()["tick"])

    def puppeteer() -> None:
        for changes in ({"speed": 0.7}, {"turn": 0.1}, {"Slgt_R": 0.6, "Slgt_L": 0.6},
                        {"turn": -0.05}, {"speed": 0.9}):
            at = ticks()
            wait_for(lambda at=at: ticks() >= at + 30)   # each some ticks after the last
            controller.set_params(changes)
        done.set()
    threading.Thread(target=puppeteer).start()
    assert done.wait(60)
    assert controller.running, controller.state()  # walking still, no fault
    controller.stop()
    assert controller.wait(30) and studio.recording is None
    assert controller.last_stats is not None and not controller.last_stats.fault
    controller.shutdown(timeout=5)
    path = tmp_path / "takes" / f"{name}.take.jsonl"
    take = read_take(path)
    assert len(take.changes) >= 4 and take.stop_tick is not None
    assert studio.takes() == [name]
    # Replay on a fresh simulated robot, from the command line.
    replay = tmp_path / "replay.take.jsonl"
    assert biped("play", str(path), "--record", str(replay)) == 0
    again = read_take(replay)
    assert take.q.shape == again.q.shape
    assert np.max(np.abs(take.q - again.q)) <= TOL


def test_panel_plays_a_take_and_refuses_the_sliders_meanwhile(tmp_path: Path) -> None:
    robot = load_robot(DEFAULT_ROBOT)
    takes = tmp_path / "takes"
    takes.mkdir()
    assert biped("walk", "--seconds", "1", "--rate", "100", "--set", "turn=0.1",
                 "--record", str(takes / "t1.take.jsonl")) == 0
    controller = make_controller(robot, BusSpec("sim", options={"realtime": True}),
                                 load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=10))
    studio = Studio(controller, takes_dir=takes, keys_dir=tmp_path / "keys")
    try:
        assert studio.takes() == ["t1"]
        studio.play("t1")
        assert studio.playing == "t1"
        assert controller.live_params().turn == 0.1  # the take's own parameters
        with pytest.raises(Exception, match="take t1 is playing"):
            controller.set_params({"turn": 0.3})
        assert controller.wait(30) and studio.playing is None
        with pytest.raises(Exception, match="not found; valid: t1"):
            studio.play("nope")
    finally:
        controller.shutdown(timeout=5)


def test_play_on_the_emulator_ends_safe(emu: Emulator, robot_toml: Path, tmp_path: Path
                                        ) -> None:
    take = tmp_path / "sim.take.jsonl"
    assert biped("walk", "--robot", str(robot_toml), "--seconds", "1", "--rate", "50",
                 "--set", "turn=0.2", "--record", str(take)) == 0
    assert biped("play", str(take), "--bus", emu.protocol, "--port", emu.port) == 0
    robot = load_robot(robot_toml)
    per_rad = MODELS[robot.bus.model].ticks_per_rad
    for j in robot.joints:
        regs = emu.registers(j.servo_id)
        assert regs["torque_enable"] == 0, j.name
        lo, hi = sorted(j.zero_ticks + j.sign * q * per_rad for q in (j.min_rad, j.max_rad))
        assert lo - 1 <= regs["goal_position"] <= hi + 1, (j.name, regs["goal_position"])
    # A Dynamixel ends with its bus watchdog disarmed (a Feetech has none).
    if emu.protocol == "dynamixel":
        assert all(emu.registers(i).get("bus_watchdog", 0) == 0 for i in robot.ids)


@pytest.mark.parametrize("line, needle", [
    ('{"take": 2}', "not a take header"),
    ('{"take": 1, "joints": [], "rate_hz": 200, "params": {}}', "joints: expected"),
    ('{"take": 1, "joints": ["r_knee"], "rate_hz": 0, "params": {}}', "rate_hz"),
    ('{"take": 1, "joints": ["r_knee"], "rate_hz": 100, "params": {"vM": 9}}',
     "vM = 9 is outside"),
    ("not json", "line 1: not JSON"),
])
def test_bad_take_headers_are_one_line_errors(tmp_path: Path, line: str, needle: str,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.take.jsonl"
    path.write_text(line + "\n")
    assert biped("play", str(path)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err and str(path) in err, err


def test_bad_take_lines_name_the_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                      ) -> None:
    good = tmp_path / "good.take.jsonl"
    assert biped("walk", "--seconds", "0.2", "--record", str(good)) == 0
    lines = good.read_text().splitlines()
    for bad, needle in ((json.dumps({"gait_tick": 3, "set": {"turn": 7}}), "turn = 7"),
                        (json.dumps({"gait_tick": 3, "set": {"nope": 1}}), "unknown gait"),
                        (json.dumps({"tick": 1, "q": [0.0]}), "finite joint angles"),
                        (json.dumps({"gait_tick": -1, "stop": True}), "gait_tick")):
        path = tmp_path / "bad.take.jsonl"
        path.write_text("\n".join([lines[0], lines[1], bad, *lines[2:]]) + "\n")
        capsys.readouterr()
        assert biped("play", str(path)) == 2
        err = capsys.readouterr().err.strip()
        assert "line 3" in err and needle in err and len(err.splitlines()) == 1, err
    other = tmp_path / "other.take.jsonl"
    other.write_text(good.read_text())
    assert biped("play", str(other), "--robot", "biped12-legs") == 2
    assert "recorded on biped18-dynamixel" in capsys.readouterr().err


def test_csv_record_still_written(tmp_path: Path) -> None:
    """`biped walk --record run.csv` keeps its per-tick log format."""
    out = tmp_path / "run.csv"
    assert biped("walk", "--seconds", "0.3", "--record", str(out)) == 0
    header = out.read_text().splitlines()[0].split(",")
    assert header[:6] == ["t", "state", "tick", "period_error_ms", "overruns", "amplitude"]
    assert "cmd_r_knee" in header and "present_r_knee" in header


HEADER = {"take": 1, "joints": ["r_knee"], "rate_hz": 100, "params": {}}


def test_read_take_by_hand(tmp_path: Path) -> None:
    """A take written by hand: a stream line without ``t`` is at tick / rate_hz [s]; a set
    line's alias is stored under its canonical name."""
    path = tmp_path / "hand.take.jsonl"
    rows = [HEADER, {"gait_tick": 2, "set": {"turn": 0.1}},
            {"tick": 0, "t": 0.0, "q": [0.5]}, {"tick": 1, "q": [0.25]},
            {"gait_tick": 4, "stop": True}]
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))
    take = read_take(path)
    assert take.header.joints == ("r_knee",) and take.stop_tick == 4
    assert take.changes == {2: {"turn": 0.1}}
    assert take.t.tolist() == [0.0, 0.01] and take.q.tolist() == [[0.5], [0.25]]
    assert take.gait_seconds == pytest.approx(0.04)


@pytest.mark.parametrize("header, row, needle", [
    ({**HEADER, "joints": ["r_knee", 3]}, None, "line 1: joints: expected a list of joint names"),
    ({**HEADER, "note": 7}, None, "line 1: note: expected a string, got 7"),
    (HEADER, {"tick": 0, "t": "soon", "q": [0.0]}, "line 2: t: expected a number, got 'soon'"),
    (HEADER, {"tick": 0, "t": float("inf"), "q": [0.0]},
     "line 2: t: expected a finite number, got inf"),
    (HEADER, {"tick": 0, "q": [True]}, "line 2: q: expected 1 finite joint angles [rad]"),
    (HEADER, {"tick": 0, "q": [float("nan")]}, "line 2: q: expected 1 finite joint angles"),
    (HEADER, {"gait_tick": 1, "set": {"turn": "left"}}, "line 2: set: turn must be a number"),
])
def test_bad_take_values_are_one_line_errors(tmp_path: Path, header: dict[str, object],
                                             row: dict[str, object] | None,
                                             needle: str) -> None:
    path = tmp_path / "bad.take.jsonl"
    path.write_text("".join(json.dumps(r) + "\n" for r in (header, row) if r is not None))
    with pytest.raises(ConfigError) as info:
        read_take(path)
    msg = str(info.value)
    assert msg.startswith(f"{path}: ") and needle in msg and "\n" not in msg, msg
