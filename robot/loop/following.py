"""Whether each servo follows its goal, judged relative to how the goal moves (the
watchdog's jam detection, robot.loop.watchdog).

A fixed "goal - present > 0.6 rad" misses a jam: a knee jammed mid-walk sat at most
0.36 rad from goals that swung around it, and got 3739 more goals (issue 19). What a
jammed or blocked servo shows instead is a position that stays put while its goal keeps
moving. Over the last ``WINDOW_S`` of read-backs, per joint:

  goal range     R_g = max(goal) - min(goal)      [rad]
  present range  R_p = max(present) - min(present)
  not following  R_g >= travel  and  R_p <= FROZEN_SHARE * R_g

``travel`` is how far the goal must have moved for the command to count as a move: the
distance the joint may travel in one read-back period at its ``max_speed_rad_s`` (the
slew limit the loop holds it to; 5 rad/s x 50 ms = 0.25 rad for the bundled robots at
200 Hz reading every 10th tick), and never less than ``NOISE_STEPS`` position steps, so a
jam whose reading jitters by a step or two still reads as one. A servo, however soft,
that keeps a fraction of its goal's motion is following; only one that stays within
``FROZEN_SHARE`` of it is not.

Why these numbers (sim bus, every bundled robot and gait preset, 10 s walks; the servos
as bundled and 4x and 10x softer, kp / 4 and kp / 10, critically damped): the smallest
R_p / R_g over any 1 s window with R_g >= 0.25 rad was 0.43 as bundled, 0.27 at 4x and
0.13 at 10x (0.095 after a fall). Shorter windows are not safe with soft servos: a stance
leg in double support is held by the ground, and at 10x a hip pitch moved 0.003 rad while
its goal swept 0.26 rad in 0.25 s. A jam reads 0 (the emulator's stuck servo) or a step
or two of jitter: 0.012 of 0.25 rad.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from robot.bus.servo_map import ServoMap

#: The span of read-backs judged [s] (at least ``MIN_READS`` of them).
WINDOW_S = 1.0
MIN_READS = 5
#: At most this share of the goal's range moved: not following.
FROZEN_SHARE = 0.05
#: The goal range that counts as a move is at least this many position steps.
NOISE_STEPS = 20

Floats = npt.NDArray[np.float64]


class FollowCheck:
    """The last ``WINDOW_S`` of (goal, present) read-backs of every joint of ``servo_map``,
    ``read_period_s`` [s] apart; ``add`` says which joint, if any, stopped following."""

    def __init__(self, servo_map: ServoMap, *, read_period_s: float) -> None:
        n = len(servo_map.ids)
        self.reads = max(MIN_READS, math.ceil(WINDOW_S / read_period_s - 1e-9))
        self.window_s = self.reads * read_period_s
        self.travel: Floats = np.maximum(servo_map.max_speed * read_period_s,
                                         NOISE_STEPS / servo_map.ticks_per_rad)
        self._goal = np.zeros((self.reads, n))
        self._present = np.zeros((self.reads, n))
        self._count = 0

    def add(self, goal: Floats, present: Floats) -> tuple[int, float, float] | None:
        """One read-back: the goal just written and the present read [rad], joint order.
        None while every joint follows (or the window is not full yet); else the first
        joint that does not: (index, goal range, present range [rad])."""
        k = self._count % self.reads
        self._goal[k], self._present[k] = goal, present
        self._count += 1
        if self._count < self.reads:
            return None
        # np.ptp's reductions, called directly (this runs at every read-back)
        r_goal = np.maximum.reduce(self._goal, axis=0) - np.minimum.reduce(self._goal, axis=0)
        r_present = (np.maximum.reduce(self._present, axis=0)
                     - np.minimum.reduce(self._present, axis=0))
        stuck = (r_goal >= self.travel) & (r_present <= FROZEN_SHARE * r_goal)
        if not np.logical_or.reduce(stuck):
            return None
        i = int(np.argmax(stuck))
        return i, float(r_goal[i]), float(r_present[i])
