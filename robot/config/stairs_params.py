"""The ``stairs_*`` gait parameters (robot/gait/stairs.py, robot/gait/stair_steps.py): a
staircase the user describes (0 steps: none) and how its footsteps are planned, as
(default, lo, hi, unit, meaning); robot.config.params makes them parameters of the robot
mapping."""

from __future__ import annotations

STAIRS: dict[str, tuple[float, float, float, str, str]] = {
    "stairs_rise": (0.0, 0.0, 0.05, "m", "stairs: height of each step (0: no stairs)"),
    "stairs_count": (0.0, 0.0, 10.0, "-", "stairs: steps up, then as many down (0: no "
                     "stairs)"),
    "stairs_tread": (0.25, 0.05, 1.0, "m", "stairs: depth of each tread"),
    "stairs_x0": (0.3, 0.0, 5.0, "m", "stairs: first riser ahead of the start pose's ankles"),
    "stairs_landing": (0.3, 0.0, 2.0, "m", "stairs: depth of the landing at the top"),
    "stairs_margin": (0.01, 0.0, 0.05, "m", "stairs: a planned sole stays this far from "
                      "every riser edge ahead of its ankle"),
    "stairs_margin_back": (0.01, 0.0, 0.06, "m", "stairs: ... and this far behind it (a "
                           "footstep that lands short)"),
    "stairs_odometry": (1.0, 0.5, 1.0, "-", "stairs: footstep advance per commanded "
                        "advance (measured on the flat)"),
    "stairs_learn": (0.0, 0.0, 1.0, "-", "stairs: share of the way each footstep's "
                     "read-back moves the learned reach gain (0: footsteps are sent where "
                     "they should land)"),
    "stairs_slow": (0.0, 0.0, 0.2, "m", "stairs: a footstep shifted this far swings at "
                    "half the gait's rate (0: never slowed)"),
    "stairs_close": (0.0, 0.0, 0.1, "m", "stairs: a foot behind the standing one may land "
                     "beside it when that stands this near a riser edge (0: never)"),
    "stairs_reach": (0.04, 0.0, 0.15, "m", "stairs: largest shift of a planned footstep "
                     "from the gait's own"),
}
