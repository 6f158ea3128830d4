"""The panel's simulation reset: the robot back on its feet in the ``home`` keyframe,
torque off, the simulation clock kept (robot.panel.controller.reset_sim)."""

from __future__ import annotations

from robot.bus.base import Bus
from robot.errors import BipedError


def reset_to_home(bus: Bus, ids: list[int]) -> None:
    """Torque off on ``ids``, then the ``home`` keyframe at the present sim time;
    BipedError unless ``bus`` is the simulated bus."""
    import mujoco

    from sim.mujoco.bus import MujocoBus  # only here: the panel runs on real buses too

    if not isinstance(bus, MujocoBus):
        raise BipedError("reset applies to the simulated bus only")
    model, data = bus.model, bus.data
    t = float(data.time)
    bus.set_torque(ids, enabled=False)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    data.time = t
    mujoco.mj_forward(model, data)
