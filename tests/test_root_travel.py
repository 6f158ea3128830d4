"""Root motion becomes the gait's travel: a character that stands, walks and stands again
(tests/walk_anim.py: bvhio, hand-chosen foot plants and root speed, independent of
robot/previs) imports into a take whose timeline has the gait walk where the character
walks, at the root's speed and turn; in MuJoCo the show walks the root's distance and
stays up, and the standing spans play the authored legs."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from walk_anim import RIG_LEG, WalkShape, root_end, write_walk_bvh

import robot.cli as cli
from robot.config.gait_file import load_gait
from robot.config.joint_names import LEG_NAMES
from robot.config.robot_file import load_robot
from robot.gait.blend import PRESET_BLEND_S
from robot.motion.show import stream_sequence
from robot.motion.show_walk import ShowEngine, Travel
from robot.motion.takes import Take, read_take
from robot.panel.runs import ShowTake, build
from robot.previs.travel import MEASURED, Efficiency

#: The speed, turn and side step asked of the gait match the root's within this share.
PARAM_TOL = 0.05
#: The robot walks the root's distance within this share (MuJoCo, no balance: the gait's
#: realized share of its stride, Efficiency, was measured on other speeds and presets).
DISTANCE_TOL = 0.2
#: The robot turns by the root's yaw within this share (the turn's Efficiency, likewise).
TURN_TOL = 0.15


def _import(tmp_path: Path, shape: WalkShape, *extra: str) -> Take:
    src, out = tmp_path / "walk.bvh", tmp_path / "walk.take.jsonl"
    write_walk_bvh(str(src), shape)
    assert cli.main(["import", str(src), "--out", str(out), *extra]) == 0
    return read_take(out)


def _steps_per_s_and_stride(take: Take) -> tuple[float, float]:
    """The gait's steps per second and stance travel per step per unit of speed [m]: two
    steps a cycle; the stance foot sweeps twice the stride amplitude, Slgt scaled from
    the gait's reference leg to this robot's (docs/gait.md)."""
    robot = load_robot(take.header.robot)
    p = take.header.params
    n = 2.0 / p.cycle_s
    amplitude = robot.geometry.leg_length / p.rig_leg * (p.Slgt_R + p.Slgt_L) / 2
    return n, 2.0 * amplitude


def _scale(take: Take) -> float:
    """Robot metres per character metre: the two legs' ratio (hip to sole)."""
    g = load_robot(take.header.robot).geometry
    return (g.thigh + g.shin + g.ankle_height) / RIG_LEG


@pytest.mark.parametrize("turn", [0.0, 0.2])
def test_the_gait_walks_at_the_root_s_speed_and_turn(tmp_path: Path, turn: float) -> None:
    shape = WalkShape(turn=turn)
    take = _import(tmp_path, shape)
    assert len(take.starts) == 1 and len(take.stops) == 1
    rate = take.header.rate_hz
    start, stop = take.starts[0] / rate, take.stops[0] / rate
    ramp = take.header.params.ramp_cycles * take.header.params.cycle_s
    # The gait reaches half amplitude as the first foot lifts and leaves it as the last
    # lands (the swing detection may lag a frame or two): its walk is the character's.
    walk_start, walk_end = shape.stand_s, shape.stand_s + shape.walk_s
    assert start + ramp / 2 == pytest.approx(walk_start, abs=0.15)
    assert stop + ramp / 2 == pytest.approx(walk_end, abs=0.4)
    n, stride = _steps_per_s_and_stride(take)
    v = shape.speed * _scale(take)                     # the root's speed on the robot [m/s]
    first = take.changes[min(take.changes)]
    assert first["speed"] * stride * n * Efficiency().forward == pytest.approx(
        v, rel=PARAM_TOL)
    assert first["turn"] * n == pytest.approx(turn, abs=PARAM_TOL * 0.2)
    assert first["side_step"] == pytest.approx(0.0, abs=1e-4)


def test_a_share_by_speed_asks_the_speed_that_walks_the_root_s_speed() -> None:
    """Where a robot's share changes with the speed (biped18-feetech without balance), the
    speed asked is the measured one whose share times speed is the root's no-slip speed:
    at each measured point, and between them (interpolated) with share x speed rising."""
    eff = MEASURED["biped18-feetech"]
    for speed, share in eff.forward_by_speed:
        assert eff.speed_for(speed * share) == pytest.approx(speed, abs=0.006)
        assert eff.speed_for(-speed * share) == pytest.approx(-speed, abs=0.006)
    asked = [eff.speed_for(x) for x in np.linspace(0.25, 0.74, 20)]
    assert all(b > a for a, b in zip(asked, asked[1:], strict=False))
    assert Efficiency(forward=0.5).speed_for(0.3) == pytest.approx(0.6)


def test_a_walk_s_ramps_are_counted_at_their_smaller_share() -> None:
    """The speed asked for a walk with ramps walks the root's distance when each instant
    of the gait's envelope walks at the share of its own stride (a time loop through the
    gait's start, full amplitude and stop, as robot/gait/engine.py ramps it: the linear
    ramp variable r over ``ramp_s``, amplitude smoothstep(r))."""
    eff = MEASURED["biped18-feetech"]
    pts = np.asarray(eff.forward_by_speed)
    walk_s, ramp_s, dt = 6.26, 2.6, 1e-3
    for target in (0.3, 0.5, 0.6):
        speed = eff.speed_for(target, walk_s=walk_s, ramp_s=ramp_s)
        walked, t = 0.0, 0.0
        while t < walk_s + ramp_s:      # started at 0, told to stop at walk_s
            r = min(t / ramp_s, 1.0) if t < walk_s else max(0.0, 1.0 - (t - walk_s) / ramp_s)
            a = r * r * (3.0 - 2.0 * r)
            walked += speed * a * float(np.interp(speed * a, pts[:, 0], pts[:, 1])) * dt
            t += dt
        assert walked / walk_s == pytest.approx(target, rel=0.01)
        assert speed > eff.speed_for(target)       # more than without ramps
    assert Efficiency(forward=0.5).speed_for(0.3, walk_s=5.0, ramp_s=2.0) == \
        pytest.approx(0.6)


def test_stepping_in_place_is_not_a_walk(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    """Feet lift in turn but the root stays: the legs play as authored (no timeline)."""
    take = _import(tmp_path, WalkShape(speed=0.0, steps=6))
    assert take.starts == () and take.changes == {}
    assert "0 walks by the gait" in capsys.readouterr().out


def test_no_root_travel_writes_no_timeline(tmp_path: Path) -> None:
    take = _import(tmp_path, WalkShape(steps=4), "--no-root-travel")
    assert take.starts == () and take.stops == () and take.changes == {}


def test_the_show_walks_the_root_s_distance_in_the_sim(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]
                                                       ) -> None:
    shape = WalkShape()
    take = _import(tmp_path, shape)
    capsys.readouterr()
    record = tmp_path / "run.csv"
    code = cli.main(["play", str(tmp_path / "walk.take.jsonl"), "--json",
                     "--record", str(record)])
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == 0 and result["physics"]["fell_at_s"] is None, result["physics"]
    root = shape.speed * shape.walk_s * _scale(take)
    assert result["walked"]["distance_m"] == pytest.approx(root, rel=DISTANCE_TOL)
    assert abs(result["walked"]["lateral_drift_m"]) < DISTANCE_TOL * root
    # Where the character stands, the legs are the authored ones: before the gait starts
    # and after its ramp out has handed the legs back (tick i of the show is take tick
    # i + 1, tests/test_import.py).
    rows = np.genfromtxt(record, delimiter=",", names=True, dtype=None, encoding="utf-8")
    show = rows[rows["state"] == "walking"]
    names = take.header.joints
    legs = [names.index(j) for j in names if j in LEG_NAMES]
    cmd = np.column_stack([show[f"cmd_{j}"] for j in names])[:, legs]
    authored = take.q[1:len(cmd) + 1][:, legs]
    rate = take.header.rate_hz
    t = np.arange(1, len(cmd) + 1) / rate
    ramp = take.header.params.ramp_cycles * take.header.params.cycle_s
    before = t < take.starts[0] / rate
    after = t > take.stops[0] / rate + ramp + 0.05
    assert before.sum() > 0.5 * rate and after.sum() > 0.5 * rate
    assert np.abs(cmd[before] - authored[before]).max() < 1e-6
    assert np.abs(cmd[after] - authored[after]).max() < 1e-6
    # In the walk, the gait's legs: not the authored ones (which walk open loop).
    middle = (t > shape.stand_s + 1.0) & (t < shape.stand_s + shape.walk_s - 1.0)
    assert np.abs(cmd[middle] - authored[middle]).max() > 0.05
    assert math.isfinite(result["walked"]["heading_change_deg"])


@pytest.mark.parametrize(("robot", "turn"), [("biped18-dynamixel", 0.2),
                                           ("biped18-feetech", 0.0),
                                           ("biped18-feetech", 0.2)])
def test_the_show_walks_the_root_s_path_and_turn_in_the_sim(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], robot: str, turn: float) -> None:
    """The root walks an arc (``turn`` [rad/s], 1.2 rad over the walk) or a line: in
    MuJoCo the robot stays up, turns by the root's yaw and ends where the root ends, both
    from the character's own geometry (tests/walk_anim.py), scaled to the robot."""
    shape = WalkShape(turn=turn)
    take = _import(tmp_path, shape, "--robot", robot)
    capsys.readouterr()
    code = cli.main(["play", str(tmp_path / "walk.take.jsonl"), "--json"])
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == 0 and result["physics"]["fell_at_s"] is None, result["physics"]
    walked = result["walked"]
    end, yaw = root_end(shape)
    end = end * _scale(take)
    got = np.array([walked["distance_m"], walked["lateral_drift_m"]])
    path = shape.speed * shape.walk_s * _scale(take)
    assert np.linalg.norm(got - end) < DISTANCE_TOL * path, (got, end)
    assert math.radians(walked["heading_change_deg"]) == pytest.approx(
        yaw, abs=max(TURN_TOL * abs(yaw), math.radians(5.0))), walked


def test_the_panel_plays_a_walking_show_with_the_gait(tmp_path: Path) -> None:
    """The panel's show run (robot/panel/runs.py) walks the legs with the take's timeline:
    the engine it builds from the take is the gait's where the character walks."""
    take = _import(tmp_path, WalkShape(steps=4))
    robot = load_robot(take.header.robot)
    kind = ShowTake("walk", stream_sequence(take), Travel.of_take(take), take.header.params)
    engine = build(kind, robot, take.header.params).engine
    assert isinstance(engine, ShowEngine)
    engine.start()
    rate = take.header.rate_hz
    walk_mid = (WalkShape().stand_s + 1.0) * rate
    for _ in range(int(walk_mid)):
        engine.tick(1.0 / rate)
    assert engine.gait_share == 1.0 and engine.state == "walking"


def test_a_show_plays_a_recorded_preset_switch_as_a_blend(tmp_path: Path) -> None:
    """A take's ``blend`` line (a preset switch recorded by `biped walk --switch` or the
    panel's picker) reaches the show's engine: the live parameters are the take's until
    the switch, then move to the preset's, and equal them once the blend's time is over.
    The expected values are the preset file's own (robot/configs/gaits/crouch.toml)."""
    take = _import(tmp_path, WalkShape(steps=6))
    rate = take.header.rate_hz
    switch_s = WalkShape().stand_s + 1.0                 # a second into the walk
    crouch = load_gait("crouch").params.as_dict()
    take = dataclasses.replace(take, blends={round(switch_s * rate): crouch})
    travel = Travel.of_take(take)
    assert [line for line in travel.timeline(rate) if "blend" in line] == [
        {"gait_tick": round(switch_s * rate), "t": round(switch_s * rate) / rate,
         "blend": crouch}]
    engine = ShowEngine(load_robot(take.header.robot), take.header.params,
                        stream=stream_sequence(take), travel=travel)
    engine.start()
    hhgt: list[float] = []
    for _ in range(round((switch_s + PRESET_BLEND_S + 0.1) * rate)):
        engine.tick(1.0 / rate)
        hhgt.append(engine.live_params.Hhgt)
    before = round(switch_s * rate) - 1
    assert hhgt[before] == take.header.params.Hhgt != crouch["Hhgt"]
    assert hhgt[-1] == pytest.approx(crouch["Hhgt"], abs=1e-12)
    between = hhgt[before + round(PRESET_BLEND_S * rate / 2)]
    assert min(hhgt[before], crouch["Hhgt"]) < between < max(hhgt[before], crouch["Hhgt"])
