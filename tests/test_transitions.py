"""Live preset switches (robot.gait.blend, GaitEngine.blend_to, robot.run.switching): the
blend's law by hand, the slew rule at the joints (no joint asked to move faster than its
servo's max speed at a switch), and a scripted run walk -> jog -> crouch -> walk in the sim
that does not fall and whose goals on the wire never reach the slew limit."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np  # noqa: E402
import numpy.typing as npt  # noqa: E402
import pytest  # noqa: E402
from waiting import wait_for  # noqa: E402

import robot.cli as cli  # noqa: E402
from robot.bus.factory import make_bus  # noqa: E402
from robot.config.gait_file import load_gait  # noqa: E402
from robot.config.robot import RobotConfig  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from robot.gait.blend import PRESET_BLEND_S, Blend, min_jerk  # noqa: E402
from robot.gait.engine import GaitEngine  # noqa: E402
from robot.loop.telemetry import Telemetry  # noqa: E402
from robot.motion.takes import read_take  # noqa: E402
from robot.panel.controller import BusSpec, LoopOptions, make_controller  # noqa: E402
from robot.panel.studio import Studio  # noqa: E402
from robot.run.run import execute  # noqa: E402
from robot.run.spec import RunOptions  # noqa: E402
from robot.run.switching import PresetSwitch, PresetSwitcher  # noqa: E402
from robot.run.walk import walk_imu, walk_spec, walk_summary  # noqa: E402

RATE = 200.0
DT = 1.0 / RATE
ROBOTS = ("biped18-dynamixel", "biped18-feetech")
#: The issue's sequence: gait time [s] of each switch and the preset switched to.
SEQUENCE = ((4.0, "jog"), (7.0, "crouch"), (10.0, "walk"))


def test_min_jerk_by_hand() -> None:
    """10 x^3 - 15 x^4 + 6 x^5: 0, 1/2, 1 at 0, 1/2, 1; 0.104 at 1/4 (10/64 - 15/256 +
    6/1024 = 0.103515625); its fastest rate 15/8 at 1/2; clipped outside [0, 1]."""
    assert (min_jerk(0.0), min_jerk(0.5), min_jerk(1.0)) == (0.0, 0.5, 1.0)
    assert min_jerk(0.25) == pytest.approx(0.103515625, abs=1e-15)
    assert (min_jerk(-1.0), min_jerk(2.0)) == (0.0, 1.0)
    x = np.linspace(0.0, 1.0, 100001)
    rate = np.diff([min_jerk(v) for v in x]) / np.diff(x)
    assert rate.max() == pytest.approx(1.875, abs=1e-4)
    assert abs(rate[0]) < 1e-6 and abs(rate[-1]) < 1e-6


def test_a_blend_goes_from_the_live_values_to_the_preset() -> None:
    walk, jog = load_gait("walk").params, load_gait("jog").params
    b = Blend(walk, jog, seconds=1.2)
    assert b.value("stance", 0.0) == walk.stance
    mid = (walk.stance + jog.stance) / 2
    assert b.value("stance", 0.6) == pytest.approx(mid, abs=1e-12)
    assert b.value("stance", 1.2) == jog.stance and b.value("vM", 5.0) == jog.vM
    with pytest.raises(ValueError, match="positive time"):
        Blend(walk, jog, seconds=0.0)


def steps(robot: RobotConfig, switch: str) -> npt.NDArray[np.float64]:
    """Per tick, each joint's move / (its max speed x the tick) through the sequence, with
    the switches made by ``switch``: "blend_to" or "set_params" (a slider's follow)."""
    presets = {n: load_gait(n).for_robot(robot) for n in ("walk", "jog", "crouch")}
    e = GaitEngine(robot, presets["walk"])
    e.start()
    at = {round(t * RATE): name for t, name in SEQUENCE}
    q = [e.start_pose()]
    for i in range(round(13.0 * RATE)):
        if i in at:
            p = presets[at[i]]
            e.blend_to(p) if switch == "blend_to" else e.set_params(p.as_dict())
        q.append(e.tick(DT))
    limit = np.array([j.max_speed_rad_s for j in robot.joints]) * DT
    return np.abs(np.diff(np.array(q), axis=0)) / limit


@pytest.mark.parametrize("name", ROBOTS)
def test_no_joint_is_asked_past_the_slew_limit_at_a_switch(name: str) -> None:
    """The blended switches stay inside every joint's max speed; the same switches as a
    slider's first-order follow would not (the streamer would clip them: a silent jump)."""
    robot = load_robot(name)
    blended = steps(robot, "blend_to")
    assert blended.max() < 1.0, robot.joint_names[int(blended.max(axis=0).argmax())]
    followed = steps(robot, "set_params")
    assert followed.max() > 1.2


def test_a_blend_reaches_the_preset_exactly_and_a_slider_ends_it() -> None:
    robot = load_robot(ROBOTS[0])
    walk, jog = load_gait("walk").for_robot(robot), load_gait("jog").for_robot(robot)
    e = GaitEngine(robot, walk)
    e.start()
    for _ in range(100):
        e.tick(DT)
    e.blend_to(jog)
    e.tick(DT)
    assert walk.stance > e.live_params.stance > jog.stance
    for _ in range(round(PRESET_BLEND_S * RATE)):
        e.tick(DT)
    assert e.live_params == e.params == jog
    e.blend_to(walk)
    for _ in range(10):
        e.tick(DT)
    e.set_params({"Slgt_R": 0.5})            # a slider mid-blend: followed as a slider
    for _ in range(round(3.0 * RATE)):
        e.tick(DT)
    assert e.live_params == e.params and e.params.Slgt_R == 0.5 and e.params.vM == walk.vM


@pytest.mark.parametrize(("name", "balance"), [("biped18-feetech", False),
                                               ("biped18-dynamixel", True)])
def test_walk_jog_crouch_walk_in_the_sim(name: str, balance: bool) -> None:
    """The issue's sequence in MuJoCo: no fall; open loop the goals on the wire (after the
    streamer's clamp and slew limit) never reach the slew limit, so nothing was clipped."""
    robot = load_robot(name)
    bus = make_bus("sim", robot=robot, realtime=False, view=False)
    switches = tuple(PresetSwitch(t, n, load_gait(n).for_robot(robot)) for t, n in SEQUENCE)
    spec = walk_spec(robot, load_gait("walk").for_robot(robot), bus, gait="walk",
                     imu=walk_imu(robot, bus, balance=balance),
                     options=RunOptions(seconds=13.0, stop_on_fall=True), switches=switches)
    limit = np.array([j.max_speed_rad_s for j in robot.joints]) * DT
    worst = [0.0]
    last: list[npt.NDArray[np.float64]] = []
    switcher = spec.observer
    assert isinstance(switcher, PresetSwitcher)

    def watch(tel: Telemetry) -> None:
        switcher(tel)
        q = np.array(tel.q_cmd)
        if last and tel.state == "walking":
            worst[0] = max(worst[0], float((np.abs(q - last[0]) / limit).max()))
        last[:] = [q]

    watched = dataclasses.replace(spec, observer=watch)
    r = walk_summary(watched, execute(watched), gait="walk")
    assert [s["preset"] for s in switcher.as_list()] == ["jog", "crouch", "walk"]
    assert not r["fell"] and r["stop_reason"] == "completed"
    if not balance:
        assert worst[0] < 0.999


def test_a_switch_is_recorded_in_a_take_and_replays_exactly(tmp_path: Path) -> None:
    """`biped walk --switch` records the switch as a blend line; `biped play` replays it
    to the same joint stream."""
    take, replay = tmp_path / "switch.take.jsonl", tmp_path / "replay.take.jsonl"
    assert cli.main(["walk", "--seconds", "4", "--switch", "3:crouch", "--record",
                     str(take)]) == 0
    assert cli.main(["play", str(take), "--record", str(replay)]) == 0
    a, b = read_take(take), read_take(replay)
    # seen after the tick at gait time 3 s was written: it shapes the next one
    assert list(a.blends) == [round(3.0 * RATE) + 1] == list(b.blends)
    assert a.blends[601]["Hhgt"] == load_gait("crouch").params.Hhgt
    assert a.q.shape == b.q.shape and np.max(np.abs(a.q - b.q)) <= 1e-6


def test_the_panels_preset_picker_blends_while_walking(tmp_path: Path) -> None:
    """The panel's preset switch goes to the loop as a blend (the take says "blend"), and
    the walk goes on."""
    robot = load_robot("biped18-dynamixel")
    controller = make_controller(robot, BusSpec("sim"), load_gait("walk").params,
                                 options=LoopOptions(rate_hz=100.0, read_every=5),
                                 preset="walk")
    studio = Studio(controller, takes_dir=tmp_path / "takes", keys_dir=tmp_path / "keys")
    try:
        name = studio.record("switch")
        wait_for(lambda: int(controller.state()["tick"]) >= 300)
        assert controller.load_preset("crouch").Hhgt == load_gait("crouch").params.Hhgt
        at = int(controller.state()["tick"])
        wait_for(lambda: int(controller.state()["tick"]) >= at + 200)
        assert controller.running, controller.state()
        controller.stop()
        assert controller.wait(30) and not controller.last_stats.fault  # type: ignore[union-attr]
    finally:
        controller.shutdown(timeout=5)
    take = read_take(tmp_path / "takes" / f"{name}.take.jsonl")
    assert len(take.blends) == 1 and not take.changes
