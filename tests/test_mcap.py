"""`--record run.mcap`: a walk in the simulation recorded as MCAP reads back with the
`mcap` reader, every channel there with its published schema, decoded by another
library's CDR decoder (mcap-ros2-support's, not the rosbags store that wrote it); its joint
stream equals the same walk's take (the simulation is deterministic) to 1e-9 rad, its
read-backs too; `biped sim-gap` and `biped plot` read it; a file that is not one is one
line, exit 2."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

import robot.cli as cli
from robot.motion.takes import read_take

TOPICS = {"/joint_commands": "sensor_msgs/msg/JointState",
          "/joint_states": "sensor_msgs/msg/JointState",
          "/servo_temperatures": "sensor_msgs/msg/Temperature",
          "/imu": "sensor_msgs/msg/Imu",
          "/torso_pose": "geometry_msgs/msg/PoseStamped",
          "/gait/params": "biped.GaitParams",
          "/events": "foxglove.Log"}


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    d = tmp_path_factory.mktemp("mcap")
    run, take = d / "run.mcap", d / "run.take.jsonl"
    for path in (run, take):
        assert cli.main(["walk", "--seconds", "1", "--record", str(path)]) == 0
    return run, take


def _messages(path: Path) -> dict[str, list[tuple[int, object]]]:
    out: dict[str, list[tuple[int, object]]] = {}
    factory = DecoderFactory()
    with path.open("rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None
        for ch in summary.channels.values():
            schema = summary.schemas[ch.schema_id]
            assert TOPICS[ch.topic] == schema.name
            assert (schema.encoding, ch.message_encoding) in (("ros2msg", "cdr"),
                                                              ("jsonschema", "json"))
        for schema, channel, message in reader.iter_messages():
            assert schema is not None
            if channel.message_encoding == "cdr":
                decode = factory.decoder_for("cdr", schema)
                assert decode is not None
                value: object = decode(message.data)
            else:
                value = json.loads(message.data)
            out.setdefault(channel.topic, []).append((message.log_time, value))
    return out


def test_every_channel_reads_back_and_the_joints_equal_the_take(
        recorded: tuple[Path, Path]) -> None:
    run, take_path = recorded
    assert not run.with_name(run.name + ".part").exists()
    got = _messages(run)
    assert set(got) == set(TOPICS)
    take = read_take(take_path)
    names = list(take.header.joints)
    cmds = got["/joint_commands"]
    assert len(cmds) == len(take.t)
    q = np.array([m.position for _, m in cmds])               # type: ignore[attr-defined]
    assert all(list(m.name) == names for _, m in cmds)        # type: ignore[attr-defined]
    assert np.abs(q - take.q).max() <= 1e-9
    # stamps: the tick's time, in order, 1/200 s apart (the simulation's clock)
    stamps = np.array([m.header.stamp.sec * 10**9 + m.header.stamp.nanosec  # type: ignore[attr-defined]
                       for _, m in cmds])
    assert (stamps == np.array([t for t, _ in cmds])).all()
    assert np.allclose(np.diff(stamps), 5e6, atol=2)
    # read-backs: at the ticks the take has them, equal; loads as effort in N m
    assert take.present is not None
    fresh = np.flatnonzero(np.isfinite(take.present).all(axis=1))
    states = got["/joint_states"]
    assert len(states) == len(fresh)
    present = np.array([m.position for _, m in states])       # type: ignore[attr-defined]
    assert np.abs(present - take.present[fresh]).max() <= 1e-9
    assert all(len(m.effort) == len(names) for _, m in states)  # type: ignore[attr-defined]
    temps = got["/servo_temperatures"]
    assert len(temps) == len(fresh) * len(names)
    assert {m.header.frame_id for _, m in temps} == set(names)   # type: ignore[attr-defined]
    assert all(20.0 < m.temperature < 70.0 for _, m in temps)    # type: ignore[attr-defined]
    imu = got["/imu"]
    assert len(imu) > len(cmds) / 2
    assert all(8.0 < m.linear_acceleration.z < 11.5 for _, m in imu[:20])  # type: ignore[attr-defined]
    pose = got["/torso_pose"]
    assert len(pose) == len(cmds) and all(0.1 < m.pose.position.z < 0.5   # type: ignore[attr-defined]
                                          for _, m in pose)
    params = got["/gait/params"]
    assert len(params) == 1 and params[0][1] == take.header.params.as_dict()
    texts = [e["message"] for _, e in got["/events"]]                      # type: ignore[index]
    assert texts[0] == "state: ramp_in" and "state: walking" in texts
    assert texts[-1] == "stopped: completed"
    assert all(set(e) == {"timestamp", "level", "message", "name", "file", "line"}  # type: ignore[arg-type]
               for _, e in got["/events"])


def test_sim_gap_and_plot_read_it(recorded: tuple[Path, Path], tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    run, take = recorded
    out = []
    for path in (run, take):
        capsys.readouterr()
        assert cli.main(["sim-gap", str(path), "--json"]) == 0
        out.append(json.loads(capsys.readouterr().out)["joints"])
    # real - command needs no replay: the same; the replay follows each record's reply
    # times, on the loop's clock (the sim's here): the sim replays its own run, gap ~0
    assert [(r["joint"], r["rms_real_cmd"], r["max_real_cmd"]) for r in out[0]] == \
        [(r["joint"], r["rms_real_cmd"], r["max_real_cmd"]) for r in out[1]]
    assert all(np.isfinite(r["rms_sim_cmd"]) and r["max_real_sim"] < 0.02 for r in out[0]), out[0]
    png = tmp_path / "run.png"
    assert cli.main(["plot", str(run), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_a_file_that_is_no_record_is_one_line(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_text("not an mcap\n")
    for argv in (["plot", str(bad), "--out", str(tmp_path / "x.png")], ["sim-gap", str(bad)]):
        capsys.readouterr()
        assert cli.main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert str(bad) in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x.png").exists()


def test_a_panel_take_with_mcap_writes_both(tmp_path: Path) -> None:
    """`biped panel --mcap`: a take recorded from the panel (a live change in it) is also
    NAME.mcap beside it, its joint stream the take's, its parameters as they changed."""
    from waiting import wait_for

    from robot.config.bundled import DEFAULT_ROBOT
    from robot.config.gait_file import load_gait
    from robot.config.robot_file import load_robot
    from robot.panel.controller import BusSpec, LoopOptions, make_controller
    from robot.panel.studio import Studio
    controller = make_controller(load_robot(DEFAULT_ROBOT), BusSpec("sim"),
                                 load_gait("walk").params, preset="walk",
                                 options=LoopOptions(rate_hz=100.0, read_every=5, mcap=True))
    studio = Studio(controller, takes_dir=tmp_path / "takes", keys_dir=tmp_path / "keys")
    try:
        name = studio.record("live")
        assert wait_for(lambda: int(controller.state()["tick"]) >= 60)
        controller.set_params({"speed": 0.7})
        at = int(controller.state()["tick"])
        assert wait_for(lambda: int(controller.state()["tick"]) >= at + 60)
        controller.stop()
        assert controller.wait(30) and studio.recording is None
    finally:
        controller.shutdown(timeout=5)
    take = read_take(tmp_path / "takes" / f"{name}.take.jsonl")
    got = _messages(tmp_path / "takes" / f"{name}.mcap")
    q = np.array([m.position for _, m in got["/joint_commands"]])   # type: ignore[attr-defined]
    assert q.shape == take.q.shape and np.abs(q - take.q).max() <= 1e-9
    speeds = [p["speed"] for _, p in got["/gait/params"]]           # type: ignore[index]
    assert speeds[0] == take.header.params.speed and speeds[-1] == 0.7
