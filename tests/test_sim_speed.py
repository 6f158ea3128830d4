"""The sim bus batches physics steps for speed; it must stay the simulation its docstring
describes: before every physics step each setpoint moves toward its goal by at most
max_speed * step, the actuator tracks the setpoint, and a tick ends exactly on its
deadline with one shorter step. A plain step-by-step reference must match bit for bit."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robot.bus.servo_map import ServoMap  # noqa: E402
from robot.config.robot_file import load_robot  # noqa: E402
from sim.mujoco.bus import MujocoBus  # noqa: E402

ROBOT = load_robot()
SM = ServoMap(ROBOT)


def _goal_sequence(ticks: int) -> list[dict[int, int]]:
    """Small walk-like wiggles, and a big shoulder move (slewing for many steps)."""
    rest = SM.vector(ROBOT.rest)
    out = []
    for k in range(ticks):
        q = rest + 0.02 * np.sin(0.07 * k + np.arange(len(rest)))
        if k >= 10:
            q[SM.index("r_shoulder_pitch")] = -1.2
        out.append(SM.goals(SM.clamp(q).tolist()))
    return out


class _Reference:
    """The documented servo model stepped one physics step at a time on a bus's
    model/data (never advanced by the bus itself)."""

    def __init__(self, bus: MujocoBus) -> None:
        self.m, self.d = bus.model, bus.data
        self.act = np.array([self.m.actuator(n).id for n in ROBOT.joint_names])
        qadr = [self.m.jnt_qposadr[self.m.joint(n).id] for n in ROBOT.joint_names]
        self.setpoint = self.d.qpos[qadr].copy()   # torque on: from the present position
        self.goal = self.setpoint.copy()
        self.dt = self.m.opt.timestep

    def write(self, goals: dict[int, int]) -> None:
        ticks = np.array([goals[i] for i in SM.ids], float)
        self.goal = np.clip((ticks - SM.zero) * SM.sign / SM.ticks_per_rad, SM.q_min, SM.q_max)

    def step(self, dt: float) -> None:
        vmax = SM.max_speed * dt
        error = self.goal - self.setpoint
        self.setpoint = np.where(np.abs(error) <= vmax, self.goal,
                                 self.setpoint + np.sign(error) * vmax)
        self.d.ctrl[self.act] = self.setpoint
        self.m.opt.timestep = dt
        mujoco.mj_step(self.m, self.d)
        self.m.opt.timestep = self.dt

    def advance(self, deadline: float) -> None:
        while (remaining := deadline - self.d.time) > 1e-9:
            self.step(min(self.dt, remaining))
        self.d.time = deadline


@pytest.mark.parametrize("rate_hz", [200.0, 30.0, 500.0])
def test_batched_stepping_is_the_step_by_step_simulation(rate_hz: float) -> None:
    goals = _goal_sequence(round(0.4 * rate_hz))
    with MujocoBus(ROBOT) as bus, MujocoBus(ROBOT) as ref_bus:
        assert isinstance(bus, MujocoBus) and isinstance(ref_bus, MujocoBus)
        for b in (bus, ref_bus):
            b.write_goals(goals[0])
            b.set_torque(ROBOT.ids, enabled=True)
        ref = _Reference(ref_bus)
        for k, g in enumerate(goals, start=1):
            bus.write_goals(g)
            ref.write(g)
            bus.clock.sleep_until(k / rate_hz)
            ref.advance(k / rate_hz)
            assert bus.data.time == ref.d.time
            np.testing.assert_array_equal(bus.data.qpos, ref.d.qpos, err_msg=f"tick {k}")
        np.testing.assert_array_equal(bus.data.ctrl, ref.d.ctrl)
