"""The `jog` preset (issue 22): at least twice the `walk` speed with no flight phase, in
MuJoCo with the servo model, on the Dynamixel 18-joint robot (balance on, as `biped walk`
runs it). The speed is the torso's over the gait time, the feet on the ground are counted
per control tick from the simulation's contacts (sim/mujoco/foot_contact.py), both as
`biped walk --json` reports them; docs/gait.md has the 60 s figures of both robots."""

from __future__ import annotations

import json

import pytest

import robot.cli as cli

ROBOT = "biped18-dynamixel"
# 20 s: the speed is over the gait time, the stop's ramp-out included, and the stop that
# finishes its step (issue 32, bal_stop_close) ends the jog's long strides sooner than the
# walk's: over 12 s jog was 1.96 x walk, over 20 s 2.01 x, over 60 s 2.04 x (0.234 / 0.1145).
SECONDS = "20"


def walk_json(gait: str, capsys: pytest.CaptureFixture[str],
              monkeypatch: pytest.MonkeyPatch) -> dict:
    monkeypatch.setattr(cli, "COMMANDS", ("walk",))
    code = cli.main(["walk", "--robot", ROBOT, "--gait", gait, "--seconds", SECONDS, "--json"])
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == 0 and not out["fell"], out
    return out


def test_jog_is_twice_the_walk_with_a_foot_always_down(
        capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    walk = walk_json("walk", capsys, monkeypatch)
    jog = walk_json("jog", capsys, monkeypatch)
    assert jog["speed_m_s"] >= 2.0 * walk["speed_m_s"] > 0.0, (jog["speed_m_s"],
                                                                walk["speed_m_s"])
    feet = jog["feet"]
    assert feet["fewest_feet_down"] >= 1 and feet["flight_s"] == 0.0
    assert jog["flight_s_per_cycle"] == 0.0
    assert feet["single_support_s"] > 0.0          # it does lift its feet: a gait, not a slide
