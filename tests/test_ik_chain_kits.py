"""The leg IK on the real kits' published models (../shared/robots/: ROBOTIS OP3, Open
Duck Mini v2): the legs measured by the importer (robot.body.measure), solved by
robot.gait.ik_chain, checked by MuJoCo's forward kinematics of the vendor's own file (its
meshes left out: they move nothing) at the model angles the roles give (robot.body.roles):
each sole point and foot rotation where the IK aimed, within 1e-6 m and 1e-6 rad; the Duck
also with its knees bent backward, as it walks (LegChain.knee_back: the other branch)."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest
from kit_models import DUCK, OP3, without_meshes

from robot.body.measure import measure
from robot.body.mjcf_read import read_mjcf
from robot.body.roles import find_roles
from robot.gait.ik_chain import chain_leg_ik, check_layout

KITS = {"op3": OP3, "open-duck-mini-v2": DUCK}
JOINTS = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")


@pytest.mark.parametrize(("kit", "back"), [("op3", False), ("open-duck-mini-v2", False),
                                           ("open-duck-mini-v2", True)])
def test_mujoco_puts_the_kits_soles_where_the_ik_aimed(kit: str, back: bool) -> None:
    tree, _ = read_mjcf(KITS[kit], missing_mesh="box")
    roles = find_roles(tree)
    legs = tuple(dataclasses.replace(leg, knee_back=back)
                 for leg in measure(tree, roles).legs)
    origin = measure(tree, roles).origin
    model = without_meshes(KITS[kit])
    data = mujoco.MjData(model)
    axes = np.asarray(roles.axes, float)
    root = model.body(tree.links[0].name).id
    names = {j.name for j in roles.joints}

    def foot(side: str, q: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
        """The foot body's origin [m] and rotation in the pelvis frame at leg angles q."""
        data.qpos[:] = model.qpos0
        angles = {f"{side}_{n}": v for n, v in zip(JOINTS, q, strict=True)
                  if f"{side}_{n}" in names}
        for name, a in roles.model_angles(angles).items():
            data.qpos[model.joint(name).qposadr[0]] = a
        mujoco.mj_kinematics(model, data)
        r_root, p_root = data.xmat[root].reshape(3, 3), data.xpos[root]
        b = model.body(tree.links[roles.legs[0 if side == "r" else 1].last].name).id
        return (axes @ (r_root.T @ (data.xpos[b] - p_root)) - origin,
                axes @ r_root.T @ data.xmat[b].reshape(3, 3))

    rng = np.random.default_rng(31)
    for side, leg in zip("rl", legs, strict=True):
        check_layout(leg)
        at0, rot0 = foot(side, (0.0,) * 6)
        offset = rot0.T @ (np.array(leg.zero_sole()) - at0)   # the sole in the foot's frame
        worst = [0.0, 0.0]
        for _ in range(200):
            knee = rng.uniform(0.1, 1.4) * (-1.0 if back else 1.0)
            lean = math.atan2(leg.thigh * math.sin(knee), leg.shin + leg.thigh * math.cos(knee))
            q = (rng.uniform(-0.4, 0.4) if leg.has_yaw else 0.0, rng.uniform(-0.3, 0.3),
                 rng.uniform(-0.8, 0.4) * (-1.0 if back else 1.0), knee,
                 rng.uniform(-0.6, 0.6) - lean,
                 rng.uniform(-0.3, 0.3) if leg.has_ankle_roll else 0.0)
            at, rot = foot(side, q)
            sole, want = at + rot @ offset, rot @ rot0.T
            sol = chain_leg_ik(leg, tuple(sole), tuple(want.ravel()))  # type: ignore[arg-type]
            assert sol.reachable and (sol.q[3] < 0.0) == back
            at, rot = foot(side, sol.q)
            worst = [max(worst[0], float(np.abs(at + rot @ offset - sole).max())),
                     max(worst[1], float(np.abs(rot @ rot0.T - want).max()))]
        assert worst[0] < 1e-6 and worst[1] < 1e-6, (kit, back, side, worst)
