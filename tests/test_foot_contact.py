"""Feet on the ground, counted from MuJoCo's contact list: a sole counts when it touches
something on the world body (floor, a step), never another part of the robot. Expected
counts are set by where the bodies are put, by hand."""

from __future__ import annotations

import mujoco
import pytest

from sim.mujoco.foot_contact import FootContacts

SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <geom name="step" type="box" size="0.1 0.1 0.05" pos="1 0 0.05"/>
    <body name="right" pos="{r}"><freejoint/>
      <geom name="r_foot" type="box" size="0.05 0.03 0.01"/></body>
    <body name="left" pos="{l}"><freejoint/>
      <geom name="l_foot" type="box" size="0.05 0.03 0.01"/></body>
    <body name="crate" pos="{c}"><freejoint/>
      <geom name="crate" type="box" size="0.05 0.05 0.05"/></body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize(("right", "left", "crate", "down"), [
    ("0 0 0.009", "0 0.5 0.009", "-1 0 1", 2),       # both on the floor
    ("0 0 0.5", "0 0.5 0.009", "-1 0 1", 1),         # right lifted
    ("0 0 0.5", "0 0.5 0.6", "-1 0 1", 0),           # flight
    ("1 0 0.109", "0 0.5 0.6", "-1 0 1", 1),         # right on the step (world body)
    ("0 0 0.109", "0 0.5 0.6", "0 0 0.05", 0),       # right stands on the robot's own part
])
def test_feet_down_counts_soles_on_the_world_only(right: str, left: str, crate: str,
                                                  down: int) -> None:
    model = mujoco.MjModel.from_xml_string(SCENE.format(r=right, l=left, c=crate))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.ncon > 0 or down == 0
    assert FootContacts(model, data).feet_down() == down
