"""robot.gait.tick: the fused float tick is the general functions' arithmetic, bit for bit.

``TickKernel.pose`` must give exactly what ``expressions.channels`` → ``targets.body_targets``
→ ``engine.solve`` give on Python floats, for any parameters, phase, envelope and trim
(including unreachable targets, turning and the 5-DoF legs), and for legs with real
offsets (robot.gait.ik_chain: 6-DoF, without hip yaw, without ankle roll in both hip
orders, with and without Newton steps). Compared as the bits of each float (``struct``),
so -0.0 and 0.0 differ.
"""

from __future__ import annotations

import dataclasses
import math
import struct

import pytest
from five_dof import five_dof_robot, no_ankle_roll_robot
from hypothesis import given, settings
from hypothesis import strategies as st

from robot.body.legs import LegChain
from robot.config.bundled import ROBOTS_DIR
from robot.config.params import SPECS, GaitParams
from robot.config.robot import RobotConfig
from robot.config.robot_file import load_robot
from robot.gait import expressions as gait
from robot.gait.targets import BodyTrim, body_targets
from robot.gait.tick import TickKernel
from robot.gait.vectorised import solve

ROBOTS = {p.stem: load_robot(p) for p in sorted(ROBOTS_DIR.glob("*.toml"))}
ROBOTS["five-dof"] = five_dof_robot()      # no hip yaw: turn steers by step length


def chains(robot: RobotConfig, yaw_off: tuple[float, float]) -> RobotConfig:
    """``robot`` with real legs' offsets (robot.gait.ik_chain's closed form): the yaw axis
    ``yaw_off`` (x, inward) [m] off the hip, the roll axis 12 mm above the pitch axis, 6 mm
    sideways, the ankle roll 10 mm below the ankle pitch, the sole 10 mm ahead."""
    g = robot.geometry

    def leg(side: str, out: float) -> LegChain:
        hip = (0.002, out * g.hip_width / 2, 0.01)
        return LegChain(side, hip, g.thigh, g.shin, (0.01, out * 0.002, -g.ankle_height),
                        yaw_axis=((hip[0] + yaw_off[0], hip[1] - out * yaw_off[1])
                                  if robot.has_hip_yaw else None),
                        roll_drop=0.012, lateral=out * 0.006,
                        ankle_drop=0.01 if robot.has_ankle_roll else 0.0,
                        has_ankle_roll=robot.has_ankle_roll,
                        order="roll_yaw" if yaw_off[1] < 0 else "yaw_roll")
    return dataclasses.replace(robot, leg_chains=(leg("r", -1.0), leg("l", 1.0)))


_DYN = ROBOTS["biped18-dynamixel"]
ROBOTS["chain-6dof"] = chains(_DYN, (0.016, 0.0))            # closed form
ROBOTS["chain-6dof-newton"] = chains(_DYN, (0.016, 0.01))    # yaw axis off sideways too
ROBOTS["chain-no-yaw"] = chains(ROBOTS["five-dof"], (0.0, 0.0))
ROBOTS["no-ankle-roll"] = no_ankle_roll_robot()             # the box legs, 5-DoF
ROBOTS["chain-no-ankle-roll"] = chains(ROBOTS["no-ankle-roll"], (-0.016, 0.01))
ROBOTS["chain-no-ankle-roll-roll-yaw"] = chains(ROBOTS["no-ankle-roll"], (0.01, -0.01))
KERNELS = {name: TickKernel(r) for name, r in ROBOTS.items()}


def bits(values: list[float]) -> list[bytes]:
    return [struct.pack("<d", v) for v in values]


def general(robot: RobotConfig, ph: gait.Phase, p: GaitParams, a: float,
            trim: BodyTrim) -> tuple[list[float], float, float, bool]:
    ch = gait.channels(ph, p, amplitude=a)
    t = body_targets(ch, p, robot.geometry, amplitude=a, leg_yaw=robot.has_hip_yaw,
                     trim=trim)
    q, ok = solve(t, robot)
    return q, t.lift_r, t.lift_l, bool(ok)


def zero_or(s: st.SearchStrategy[float]) -> st.SearchStrategy[float]:
    """Often exactly 0.0 (or -0.0): the code has branches for zero trims and turns."""
    return st.one_of(st.just(0.0), st.just(-0.0), s)


params_st = st.fixed_dictionaries({
    name: zero_or(st.floats(spec.lo, spec.hi)) if spec.lo <= 0.0 <= spec.hi
    else st.floats(spec.lo, spec.hi) for name, spec in SPECS.items()})
phase_st = st.builds(gait.Phase, *[st.floats(-1e5, 1e5) for _ in range(5)])
amp_st = st.one_of(st.just(1.0), st.just(0.0), st.floats(0.0, 1.0))
trim_st = st.builds(BodyTrim, *[zero_or(st.floats(-lim, lim)) for lim in
                                (0.3, 0.3, 0.05, 0.05, 0.05, 0.05, 0.5, 1.0, 1.0,
                                 0.3, 0.3, 0.3, 0.3)])


@pytest.mark.parametrize("name", ROBOTS)
# The profile's examples: 100 per robot in `make test` (300 took 25-30 s per robot on a
# loaded 2-core machine, the suite's costliest property), 2000 in `make fuzz`.
@settings(deadline=None)
@given(values=params_st, ph=phase_st, a=amp_st, trim=trim_st)
def test_kernel_equals_the_general_functions_bit_for_bit(
        name: str, values: dict[str, float], ph: gait.Phase, a: float,
        trim: BodyTrim) -> None:
    p = GaitParams(**values)
    want_q, want_r, want_l, want_ok = general(ROBOTS[name], ph, p, a, trim)
    got_q, got_r, got_l, got_ok = KERNELS[name].pose(ph, p, a, trim)
    assert len(got_q) == len(ROBOTS[name].joints)
    assert bits(got_q) == bits(want_q), (got_q, want_q)
    assert bits([got_r, got_l]) == bits([want_r, want_l])
    assert got_ok is want_ok


def test_a_new_parameter_set_is_used_at_once() -> None:
    """The per-parameter constants follow a new GaitParams object (even an equal-valued
    one built anew), never a stale one."""
    robot = ROBOTS["biped18-dynamixel"]
    kernel = TickKernel(robot)
    ph = gait.Phase(1.0, 2.0, 1.0, 0.5, 0.5)
    wide = GaitParams(foot_spread=0.03, sway=0.05, sway_phase=1.0)
    kernel.pose(ph, GaitParams(), 1.0, BodyTrim())
    got = kernel.pose(ph, wide, 1.0, BodyTrim())
    assert bits(got[0]) == bits(general(robot, ph, wide, 1.0, BodyTrim())[0])
    assert not math.isclose(got[0][1], kernel.pose(ph, GaitParams(), 1.0, BodyTrim())[0][1])
