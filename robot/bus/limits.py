"""The bus's last line of defence: goal ticks outside a joint's limits are refused."""

from __future__ import annotations

from robot.bus.servo_map import ServoMap
from robot.config.robot import RobotConfig
from robot.errors import BusError
from robot.servo import ticks as tick_math


class TickLimits:
    """Allowed goal range [ticks] per servo id, from the joint limits (``ServoMap``) and the
    servo's resolution. Without a robot config nothing is allowed."""

    def __init__(self, robot: RobotConfig | None) -> None:
        self.robot = robot
        self.by_id: dict[int, tuple[int, int]] = {}
        if robot is not None:
            sm = ServoMap(robot)
            lo, hi = tick_math.accepted_range(sm.tick_min, sm.tick_max, sm.resolution)
            for sid, a, b in zip(sm.ids, lo.tolist(), hi.tolist(), strict=True):
                self.by_id[sid] = (int(a), int(b))

    def check(self, sid: int, ticks: int) -> int:
        """``ticks`` as an int if allowed for servo ``sid``, else BusError. Hot path: runs
        for every servo on every control tick, so messages are built only on failure."""
        t = int(ticks)
        limits = self.by_id.get(sid)
        if limits is not None and limits[0] <= t <= limits[1] and t == ticks:
            return t
        joint = self.robot.joint_by_id(sid) if self.robot else None
        who = f"id {sid} ({joint.name})" if joint else f"id {sid}"
        if t != ticks:
            raise BusError(f"write_goals: goal for {who} must be whole ticks, got {ticks!r}")
        if sid not in self.by_id:
            if self.robot is None:
                raise BusError("write_goals: this bus has no robot config, so it cannot check "
                               "joint limits; construct it with robot=...")
            raise BusError(f"write_goals: id {sid} is not a servo of robot {self.robot.name}; "
                           f"valid ids: {', '.join(map(str, sorted(self.by_id)))}")
        lo, hi = self.by_id[sid]
        raise BusError(f"write_goals: goal {t} ticks for {who} is outside its limits "
                       f"[{lo}, {hi}] ticks; refusing to move it (clamp first, e.g. "
                       "ServoMap.goals)")
