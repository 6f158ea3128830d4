"""One way to assemble a run (robot.run) and the motion sources the loop streams
(robot.loop.source): the Run's result on the sim bus is the CLI's JSON for the same walk,
a pose move goes through the protocol, and the tuner's objective walks in-process."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robot import cli
from robot.bus.factory import make_bus
from robot.bus.servo_map import ServoMap
from robot.config.bundled import DEFAULT_ROBOT_NAME
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.loop.source import MotionSource
from robot.loop.streamer import Streamer, Telemetry
from robot.motion.keyframes import Sequence
from robot.motion.layered import LayeredEngine
from robot.motion.posing import PoseMove
from robot.motion.scripted import PlaybackEngine, RecordingEngine
from robot.run.run import Run, execute
from robot.run.spec import RunOptions, RunSpec
from robot.run.walk import walk_imu, walk_summary
from robot.tuning.objective import Setup, evaluate

ROBOT = load_robot(DEFAULT_ROBOT_NAME)
PARAMS = load_gait("walk").for_robot(ROBOT)
SECONDS = 1.5


def cli_json(argv: list[str], capsys: pytest.CaptureFixture[str],
             monkeypatch: pytest.MonkeyPatch) -> dict:
    monkeypatch.setattr(cli, "COMMANDS", ("walk",))
    code = cli.main(["walk", "--json", *argv])
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == out["exit_code"]
    return out


def test_the_runs_result_on_the_sim_bus_is_the_clis_json(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    want = cli_json(["--seconds", f"{SECONDS:g}", "--stop-on-fall"], capsys, monkeypatch)
    # The same walk assembled by hand: the plain engine, the robot's IMU, the sim bus.
    bus = make_bus("sim", robot=ROBOT)
    imu = walk_imu(ROBOT, bus)
    assert imu is not None                        # the bundled robot balances by default
    spec = RunSpec(robot=ROBOT, source=GaitEngine(ROBOT, PARAMS), bus=bus, imu=imu,
                   options=RunOptions(seconds=SECONDS, stop_on_fall=True))
    result = execute(spec)
    got = json.loads(json.dumps(result.as_dict()))
    header = {"robot", "gait", "bus", "seconds", "balance"}
    # What walk_summary adds from the engine: the heading asked for and the drift beyond
    # it, the time a target was out of reach and each joint held at a limit or to its
    # servo's speed, the flight time per gait cycle.
    engine_keys = {"heading_asked_deg", "heading_drift_deg_min", "heading_drifts",
                   "ik_unreachable_s", "clamped_joints_s", "speed_limited_joints_s",
                   "flight_s_per_cycle", "braced_s", "stop_braced_s"}
    assert set(got) == set(want) - header - engine_keys
    wall = {"realtime_factor"}                    # wall clock: differs run to run
    assert {k: got[k] for k in set(got) - wall} == {k: want[k] for k in set(got) - wall}
    summary = json.loads(json.dumps(walk_summary(spec, result, gait="walk")))
    assert {k: summary[k] for k in set(want) - wall} == {k: want[k] for k in set(want) - wall}
    assert result.stats.ticks == want["ticks"] > SECONDS * 200   # ramps + gait ticks
    assert not bus.is_open                         # the run closed what it opened


def test_the_run_leaves_a_bus_it_does_not_own_open() -> None:
    bus = make_bus("sim", robot=ROBOT)
    bus.open()
    seen: list[str] = []
    with Run(RunSpec(robot=ROBOT, source=GaitEngine(ROBOT, PARAMS), bus=bus,
                     observer=lambda tel: seen.append(tel.state),
                     options=RunOptions(seconds=0.2, close_bus=False, watch=False))) as run:
        run.stream()
    assert bus.is_open and run.result.metrics is None
    assert {"ramp_in", "walking", "ramp_out", "rest"} <= set(seen)
    bus.close()


def test_every_engine_and_player_and_the_pose_move_are_motion_sources() -> None:
    seq = Sequence("wave", ("r_shoulder_pitch",), np.array([0.0, 1.0]),
                   np.array([[0.0], [0.3]]), "min_jerk", False, "<test>")
    sources = [GaitEngine(ROBOT, PARAMS), LayeredEngine(ROBOT, PARAMS, keyframes=seq),
               LayeredEngine(ROBOT, PARAMS, keyframes=seq, walk=False),
               RecordingEngine(ROBOT, PARAMS, sink=lambda *a, **k: None),
               PlaybackEngine(ROBOT, PARAMS, changes={}, stop_tick=10),
               PoseMove(ROBOT, np.zeros(len(ROBOT.joints)))]
    assert all(isinstance(s, MotionSource) for s in sources)


def test_a_pose_move_streams_through_the_protocol() -> None:
    rate = 50.0
    smap = ServoMap(ROBOT)
    lo = np.array([j.min_rad for j in ROBOT.joints])
    hi = np.array([j.max_rad for j in ROBOT.joints])
    want_goal = np.clip(np.full(len(lo), 0.2), lo, hi)          # by hand, not smap.clamp
    bus = make_bus("sim", robot=ROBOT)
    bus.open()
    try:
        start = smap.from_positions(bus.read_positions(smap.ids))
        states: list[str] = []
        cmds: list[list[float]] = []

        def watch(tel: Telemetry) -> None:
            if tel.state == "pose":
                states.append(tel.state)
                cmds.append(list(tel.q_cmd))
        move = PoseMove(ROBOT, np.full(len(lo), 0.2), max_speed=0.5)
        stats = Streamer(smap, bus, move, rate_hz=rate, hold_at_end=True,
                         observer=watch).run()
    finally:
        bus.close(torque_off=True)
    # Minimum jerk peaks at 15/8 of the mean speed: T = max(0.3 s, 1.875 |dq| / v).
    speed = np.minimum(0.5, [j.max_speed_rad_s for j in ROBOT.joints])
    duration = max(0.3, float(np.max(1.875 * np.abs(want_goal - start) / speed)))
    steps = math.ceil(duration * rate - 1e-9)
    assert stats.ticks == steps == len(cmds)          # no entry ramp, no ramp to rest
    assert stats.holding and stats.stop_reason == "completed"
    assert np.allclose(cmds[-1], want_goal, atol=1e-12)
    assert set(states) == {"pose"}


def test_a_stop_ends_a_pose_move_where_it_is() -> None:
    bus = make_bus("sim", robot=ROBOT)
    bus.open()
    try:
        smap = ServoMap(ROBOT)
        streamer: Streamer[PoseMove] = Streamer(
            smap, bus, PoseMove(ROBOT, np.full(len(ROBOT.joints), 0.2), max_speed=0.2),
            rate_hz=50.0, hold_at_end=True,
            observer=lambda tel: tel.tick == 5 and streamer.request_stop("enough"))
        stats = streamer.run()
    finally:
        bus.close(torque_off=True)
    assert stats.ticks == 5 and stats.holding and stats.stop_reason == "enough"
    with pytest.raises(Exception, match="no parameters"):
        streamer.set_params({"speed": 0.5})


def test_the_tuners_objective_walks_in_process(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
        tmp_path: Path) -> None:
    monkeypatch.chdir(tmp_path)
    skip = ("slope", "cross slope", "bumps", "push*", "latency", "imu noise")
    ev = evaluate(Setup(DEFAULT_ROBOT_NAME, "quick", SECONDS, skip=skip), PARAMS)
    assert [o.condition.name for o in ev.outcomes] == ["flat"]
    flat = ev.outcomes[0]
    want = cli_json(["--seconds", f"{SECONDS:g}", "--stop-on-fall"], capsys, monkeypatch)
    got = json.loads(json.dumps(flat.summary))
    assert got["gait"] == "candidate" and want["gait"] == "walk"
    same = set(want) - {"gait", "realtime_factor"}
    assert {k: got[k] for k in same} == {k: want[k] for k in same}
    assert flat.fell is False and flat.distance_m == want["distance_m"]
    # score = walks x (runs + 1) + survived + 0.9 quality (walks: the flat, bumps skipped);
    # with no references it walks
    # when it stays up, and speed and energy count 1.
    drift = abs(want["lateral_drift_m"]) / max(want["distance_m"], 0.1)
    straight = max(0.0, 1 - abs(want["heading_change_deg"]) / 20 - drift / 0.2)
    knee = 1 - want["knee_load_pct"] / 100
    assert ev.walking
    assert ev.score == pytest.approx(2 + 1 + 0.9 * (0.4 + 0.3 * straight + 0.15 * knee + 0.15))
    assert list(tmp_path.iterdir()) == []           # no candidate TOML, no files at all


def test_the_tuner_and_the_run_import_neither_the_cli_nor_sim() -> None:
    code = ("import sys, robot.tuning.objective, robot.tuning.robustness, robot.run.run\n"
            "print(sorted(m for m in sys.modules if m == 'robot.cli' or m == 'sim'"
            " or m.startswith(('sim.', 'robot.commands'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "[]"
