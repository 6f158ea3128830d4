"""`biped import`: files written independently of `biped export` (tests/anim_files.py:
bvhio and pygltflib from hand-chosen angles, Blender's axes and habits) give back those
angles; `biped export` then `biped import` gives back the joint stream; every violation is
named with its time and joint, and --strict refuses."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from anim_files import ANGLES, KNEE_HIERARCHY, map_toml, write_blender_bvh, write_blender_gltf

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.robot_file import load_robot
from robot.gait.engine import GaitEngine
from robot.motion.takes import read_take

FPS = 24.0
FRAMES = 49
#: The take runs at the smallest multiple of 24 fps at or above 200 Hz: 216 Hz, 9 ticks a frame.
TICKS_PER_FRAME = 9


def _frames_error(take_path: Path) -> float:
    take = read_take(take_path)
    assert take.header.rate_hz == pytest.approx(FPS * TICKS_PER_FRAME)
    names = take.header.joints
    worst = 0.0
    for k in range(FRAMES):
        row = take.q[TICKS_PER_FRAME * k]
        for joint, angle in ANGLES.items():
            worst = max(worst, abs(row[names.index(joint)] - angle(k / FPS)))
    return worst


def test_blender_style_bvh_gives_the_chosen_angles(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    src, out = tmp_path / "dance.bvh", tmp_path / "dance.take.jsonl"
    write_blender_bvh(str(src), FPS, FRAMES, travel_m_s=0.3)
    assert cli.main(["import", str(src), "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "up +Z" in said and "0 violations" in said
    assert _frames_error(out) < 1e-6
    show = json.loads(out.read_text().splitlines()[0])["show"]
    assert show["stream"] is True and show["up"] == "+Z"
    forward, left, _ = show["travel_m"]
    assert forward > 0.05 and abs(left) < 1e-6   # the root walked forward (-Y in Blender)


def test_blender_style_gltf_with_a_map_gives_the_chosen_angles(tmp_path: Path) -> None:
    src, out, bones = tmp_path / "dance.glb", tmp_path / "g.take.jsonl", tmp_path / "map.toml"
    write_blender_gltf(str(src), FPS, FRAMES)
    bones.write_text(map_toml())
    assert cli.main(["import", str(src), "--map", str(bones), "--out", str(out)]) == 0
    assert _frames_error(out) < 1e-5       # float32 quaternions


def test_without_the_map_the_rig_s_names_are_refused(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "dance.glb"
    write_blender_gltf(str(src), FPS, FRAMES)
    out = tmp_path / "x.take.jsonl"
    assert cli.main(["import", str(src), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "--map" in err and "thigh.R" in err and len(err.splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("suffix", [".bvh", ".glb", ".gltf"])
def test_export_then_import_round_trips(tmp_path: Path, suffix: str) -> None:
    anim, out = tmp_path / f"walk{suffix}", tmp_path / "walk.take.jsonl"
    assert cli.main(["export", "--gait", "walk", "--seconds", "2", "--fps", "30",
                     "--out", str(anim)]) == 0
    assert cli.main(["import", str(anim), "--out", str(out)]) == 0
    robot = load_robot()
    n = 61
    _, qt = GaitEngine(robot, load_gait("walk").params).curves(np.arange(n) / 30.0,
                                                               with_channels=False)
    take = read_take(out)
    assert take.header.rate_hz == 210.0          # 7 ticks a frame
    assert np.abs(take.q[::7] - qt.T).max() < 1e-4


@pytest.mark.parametrize("suffix", [".bvh", ".glb"])
def test_what_lies_between_the_frames_comes_back(tmp_path: Path, suffix: str) -> None:
    """The gait at 30 fps, imported again, against the gait itself at every tick of 210 Hz
    (6 ticks of 7 between frames): within 0.005 rad on every joint. The monotone cubic was
    0.0183 rad off at the right knee (it flattens the peaks and rounds the kinks of the
    swing's lift), a C2 spline alone 0.0197 (it rings at the kinks): robot/motion/kinks.py."""
    anim, out = tmp_path / f"walk{suffix}", tmp_path / "walk.take.jsonl"
    assert cli.main(["export", "--gait", "walk", "--seconds", "2", "--fps", "30",
                     "--out", str(anim)]) == 0
    assert cli.main(["import", str(anim), "--out", str(out)]) == 0
    take = read_take(out)
    t = np.arange(len(take.t)) / take.header.rate_hz
    _, qt = GaitEngine(load_robot(), load_gait("walk").params).curves(t, with_channels=False)
    assert np.abs(take.q - qt.T).max(axis=0).max() < 0.005


def _knee_bvh(path: Path, knee_deg: list[float], fps: float = 30.0) -> None:
    """Our skeleton's names, only the right knee moving (Xrotation: the robot's pitch)."""
    lines = [*KNEE_HIERARCHY, f"Frames: {len(knee_deg)}", f"Frame Time: {1 / fps:.6f}"]
    lines += [f"0 25 0 0 0 0 0 0 0 0 0 {d} 0 0 0" for d in knee_deg]
    path.write_text("\n".join(lines) + "\n")


def test_violations_are_named_with_time_and_joint_then_clamped(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot()
    hi = np.degrees(robot.joint("r_knee").max_rad)
    # 1 s of 30 fps: rest, then frames 15-19 at 10 deg beyond the knee's upper limit.
    degs = [20.0] * 30
    for k in range(15, 20):
        degs[k] = hi + 10.0
    src, out = tmp_path / "kick.bvh", tmp_path / "kick.take.jsonl"
    _knee_bvh(src, degs)
    assert cli.main(["import", str(src), "--out", str(out)]) == 0
    said = capsys.readouterr().out
    limit = [ln for ln in said.splitlines() if "r_knee" in ln and " limit " in ln]
    assert len(limit) == 1
    # The frames beyond: 0.5 s .. 0.633 s (the stream crosses the limit just before).
    t0, t1 = (float(v) for v in limit[0].split("t=")[1].split(" s")[0].split("-"))
    assert 0.45 < t0 <= 0.5 and 0.633 <= t1 < 0.67
    assert any("r_knee" in ln and " speed " in ln for ln in said.splitlines())
    take = read_take(out)
    knee = take.q[:, robot.joint_names.index("r_knee")]
    assert knee.max() <= robot.joint("r_knee").max_rad + 1e-12
    assert np.abs(np.diff(knee)).max() * take.header.rate_hz <= \
        robot.joint("r_knee").max_speed_rad_s + 1e-5  # 8 decimals a tick


def test_strict_refuses_and_writes_nothing(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot()
    degs = [0.0] * 10 + [np.degrees(robot.joint("r_knee").max_rad) + 5.0] * 10
    src, out = tmp_path / "kick.bvh", tmp_path / "kick.take.jsonl"
    _knee_bvh(src, degs)
    assert cli.main(["import", str(src), "--out", str(out), "--strict"]) == 2
    err = capsys.readouterr().err.strip()
    assert "r_knee" in err and "--strict" in err and len(err.splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize(("text", "what"), [
    ('[joints.r_knee]\nbone = "shin"\naxis = "w"\n', "joints.r_knee.axis"),
    ('[joints.nose]\nbone = "shin"\naxis = "y"\n', "joints.nose"),
    ('[joints.r_knee]\nbone = "shin"\naxis = "y"\nsign = 2\n', "joints.r_knee.sign"),
    ('[joints.r_knee]\nbone = "a"\naxis = "y"\n[joints.l_knee]\nbone = "a"\naxis = "y"\n',
     "already joints.r_knee"),
])
def test_a_bad_map_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                               text: str, what: str) -> None:
    src, bones = tmp_path / "kick.bvh", tmp_path / "map.toml"
    _knee_bvh(src, [0.0, 1.0])
    bones.write_text(text)
    assert cli.main(["import", str(src), "--map", str(bones),
                     "--out", str(tmp_path / "x.take.jsonl")]) == 2
    err = capsys.readouterr().err.strip()
    assert what in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("text", ["HIERARCHY\nROOT a\n{\nOFFSET 0 0\n", "MOTION\n",
                                  "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 2 Xrotation "
                                  "Yrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0\n"])
def test_a_broken_bvh_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                  text: str) -> None:
    src = tmp_path / "bad.bvh"
    src.write_text(text)
    assert cli.main(["import", str(src), "--out", str(tmp_path / "x.take.jsonl")]) == 2
    err = capsys.readouterr().err.strip()
    assert str(src) in err and len(err.splitlines()) == 1


def test_an_imported_take_plays_its_stream_on_the_sim(tmp_path: Path) -> None:
    """The commanded joints while the show plays are the take's ticks, in order (after the
    ramp in to the first tick; within limits and speeds, so clamp and slew change nothing),
    until the physics check stops it: this dance is not balanced, it falls (exit 1)."""
    src, take_path = tmp_path / "dance.bvh", tmp_path / "dance.take.jsonl"
    write_blender_bvh(str(src), FPS, FRAMES)
    assert cli.main(["import", str(src), "--out", str(take_path)]) == 0
    record = tmp_path / "run.csv"
    assert cli.main(["play", str(take_path), "--record", str(record)]) in (0, 1)
    take = read_take(take_path)
    rows = np.genfromtxt(record, delimiter=",", names=True, dtype=None, encoding="utf-8")
    show = rows[rows["state"] == "walking"]
    cmd = np.column_stack([show[f"cmd_{n}"] for n in take.header.joints])
    assert 10 < len(cmd) <= len(take.q) - 1      # tick 0 is where the ramp in ends
    assert np.abs(cmd - take.q[1:len(cmd) + 1]).max() < 1e-6


def test_a_shoulder_raised_past_90_degrees_stays_one_pitch(tmp_path: Path) -> None:
    """Of the two Euler solutions, the one with the bone's unused axis at 0: an arm raised
    to -2.2 rad of pitch (126 deg, overhead) is that pitch, not -0.94 with roll flipped."""
    pitch = np.linspace(0.0, -2.2, 31)
    lines = ["HIERARCHY", "ROOT pelvis", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Yrotation Zrotation Xrotation",
             "JOINT chest", "{", "OFFSET 0 30 0", "CHANNELS 3 Zrotation Xrotation Yrotation",
             "JOINT r_shoulder", "{", "OFFSET -10 0 0",
             "CHANNELS 3 Zrotation Xrotation Yrotation", "End Site", "{", "OFFSET 0 -20 0",
             "}", "}", "}", "}", "MOTION", f"Frames: {len(pitch)}", "Frame Time: 0.033333"]
    lines += [f"0 45 0 0 0 0 0 0 0 0 {np.degrees(p):.6f} 0" for p in pitch]
    src, out = tmp_path / "raise.bvh", tmp_path / "raise.take.jsonl"
    src.write_text("\n".join(lines) + "\n")
    assert cli.main(["import", str(src), "--out", str(out), "--strict"]) == 0
    take = read_take(out)
    names = take.header.joints
    assert np.abs(take.q[::7, names.index("r_shoulder_pitch")] - pitch).max() < 1e-5
    assert np.abs(take.q[:, names.index("r_shoulder_roll")]).max() < 1e-5
