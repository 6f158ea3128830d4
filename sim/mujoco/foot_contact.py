"""Which feet touch the ground, tick by tick: the gait's flight phase and double support.

A foot is on the ground when one of its sole geoms (``r_foot`` / ``l_foot``, sim.mujoco.geoms)
has a contact with a geom outside the robot (the floor, a bump, a stair step). Sampled once
per control tick while the gait walks, until a fall (the gait's ramp in and out included,
the ramps to and from the start pose not), so times are multiples of the tick; the time with no foot on the
ground is the flight phase (a jog has none, a run has one per step).
"""

from __future__ import annotations

import mujoco
import numpy as np

from sim.mujoco.geoms import foot_geoms


class FootContacts:
    """``update(t)`` once per walking tick at sim time ``t`` [s]: the time since the last
    one counts for the number of feet on the ground now. ``summary``: seconds with none
    (flight), one and two, the fewest feet down, the longest flight and its share."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self.data = data
        right, left = foot_geoms(model)
        self.feet = set(right) | set(left)
        #: per geom: which foot's sole (0 none, 1 right, 2 left), and a part of the robot
        #: (anything not on the world body)
        self._foot = np.zeros(model.ngeom, dtype=np.int8)
        self._foot[list(right)] = 1
        self._foot[list(left)] = 2
        self._sole = self._foot > 0
        self._robot = np.asarray(model.geom_bodyid) != 0
        self.seconds = [0.0, 0.0, 0.0]     # with 0, 1, 2 feet down [s]
        self.fewest = 2
        self.longest_flight_s = 0.0
        self._last_t: float | None = None
        self._flight_s = 0.0               # the flight in progress [s]
        self.right_down = False            # at the last update

    def down(self) -> np.ndarray:
        """The feet (1 right, 2 left) that touch something that is not the robot, now."""
        # The contact list's columns as arrays (a Python loop over the contacts cost as
        # much as the physics step).
        g1, g2 = self.data.contact.geom1, self.data.contact.geom2
        soles = np.concatenate((self._foot[g1[self._sole[g1] & ~self._robot[g2]]],
                                self._foot[g2[self._sole[g2] & ~self._robot[g1]]]))
        return np.unique(soles)

    def feet_down(self) -> int:
        """How many feet touch something that is not the robot, now."""
        return len(self.down())

    def update(self, t: float) -> None:
        """Count the tick at ``t`` [s]; ``right_down``: the right sole on the ground now."""
        feet = self.down()
        n = len(feet)
        self.right_down = bool(n) and int(feet[0]) == 1
        if self._last_t is not None:
            dt = t - self._last_t
            self.seconds[n] += dt
            self.fewest = min(self.fewest, n)
            self._flight_s = self._flight_s + dt if n == 0 else 0.0
            self.longest_flight_s = max(self.longest_flight_s, self._flight_s)
        self._last_t = t

    def summary(self) -> dict[str, float]:
        """JSON-ready: seconds with 0, 1, 2 feet down, the fewest, the longest flight [s]
        and the flight's share of the walking time."""
        total = sum(self.seconds)
        return {"flight_s": self.seconds[0], "single_support_s": self.seconds[1],
                "double_support_s": self.seconds[2], "fewest_feet_down": self.fewest,
                "longest_flight_s": self.longest_flight_s,
                "flight_share": self.seconds[0] / total if total > 0 else 0.0}
