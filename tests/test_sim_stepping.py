"""The sim bus's physics steps skip the sensors except in the last step of each tick
(sim.mujoco.stepping): after every ``advance`` the sensors and the state are bit for bit
those of MuJoCo stepping with its sensors on in every step, whether the tick ends on a
whole step (the last step inside a batched ``mj_step`` call) or on a short one; the
model's flags and timestep are as they were."""

from __future__ import annotations

import copy
import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robot.config.robot_file import load_robot  # noqa: E402
from sim.mujoco.bus import MujocoBus  # noqa: E402


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.array_equal(np.asarray(a).view(np.uint64), np.asarray(b).view(np.uint64)))


@pytest.mark.parametrize(("timestep", "tick"), [(0.0025, 0.005), (0.002, 0.005),
                                                (0.001, 0.001), (0.002, 0.05)])
@pytest.mark.parametrize("robot", ["biped18-dynamixel", "robotis-op3"])
def test_each_tick_ends_with_the_sensors_of_every_step_on(robot: str, timestep: float,
                                                          tick: float) -> None:
    bus = MujocoBus(load_robot(robot), timestep=timestep)
    with bus:
        bus.set_torque(bus.robot.ids, enabled=True)
        bus.advance(bus.data.time + tick)       # the setpoints settle: a tick's ctrl is constant
        m, d = bus.model, bus.data
        flags, dt = m.opt.disableflags, m.opt.timestep
        ref = copy.copy(d)    # MuJoCo alone, one step at a time, sensors on in every step
        for k in range(1, 8):
            deadline = ref.time + tick
            bus.advance(deadline)
            ref.ctrl[:] = d.ctrl   # the tick's ctrl (the firmware's I term sets it per tick)
            for _ in range(int((deadline - ref.time) / dt + 1e-6)):   # the bus's whole steps
                mujoco.mj_step(m, ref)
            if deadline - ref.time > 1e-9:                            # and its short one
                m.opt.timestep = deadline - ref.time
                mujoco.mj_step(m, ref)
                m.opt.timestep = dt
            ref.time = deadline
            assert _same(d.sensordata, ref.sensordata), (k, d.sensordata - ref.sensordata)
            assert _same(d.qpos, ref.qpos) and _same(d.qvel, ref.qvel), k
            assert m.opt.disableflags == flags and m.opt.timestep == dt
        assert np.any(d.sensordata != 0.0)
