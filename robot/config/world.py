"""The perturbations of a simulated world (pure configuration; the simulation applies
them: sim.mujoco.world, sim.mujoco.world_scene) for robustness runs: a tilted floor, bumps, pushes
on the torso, goal latency, friction and mass. ``World()`` (all defaults) is the plain
scene: the bus then builds exactly the model it builds without a world.

Sign conventions (REP-103, the robot starts at the origin facing +x):

- ``slope_deg`` > 0: the ground rises along +x (walking uphill); ``cross_slope_deg`` > 0:
  the ground falls to the robot's right (-y lower). The floor plane through the origin is
  ``z = x tan(slope) + y tan(cross_slope)``; the robot starts rigidly rotated with it
  (minimal rotation taking +z to the floor normal), soles flat on it. Gravity stays -z, so
  the IMU's accelerometer sees the slope as a real robot would.
- ``bumps_mm``: flat boxes of that height on the floor over 0.1..5.1 m ahead of the origin
  and +-0.5 m sideways (floor frame): one box in about 83 % of the 10 cm x 10 cm cells, sides
  3..8 cm, so about 25 % of the area is covered; the layout depends only on
  ``terrain_seed``.
- ``pushes``: impulses [N*s] on the torso at gait times [s], forward (``jx``) and left
  (``jy``) in the robot's heading frame (its yaw only), applied by the simulation
  (``sim.mujoco.world.PushScheduler``) as a constant force at the torso's centre of mass
  for a short window.
- ``latency_s``: goals written to the bus take effect that much sim time later.
- ``stairs_height_m``, ``stairs_count``: a flight of that many steps up, each that high,
  a landing, and a flight as many steps down, straight ahead (sim.mujoco.world_stairs has
  the landing and where the first riser stands); 0, 0: none. ``stairs_tread_m``: the depth
  of each tread (``STAIRS_TREAD_M`` by default: why, there).
- ``friction_scale``: scales the sliding friction of every geom (floor, bumps, feet,
  body), hence of every contact; ``mass_scale``: scales every robot body's mass and
  inertia.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from robot.config.toml_io import Range
from robot.config.world_ranges import RANGES
from robot.errors import ConfigError

#: Default tread depth of the stairs [m]. The issue fixes the rise (1.5 cm) and the count
#: (3), not the tread: 25 cm lets a robot with 13 cm soles put a footstep wholly on every
#: tread with room for its dead reckoning's error (a sole may not rest on a nosing ahead of
#: or behind its ankle; the tread must hold the ankle 2 cm past the riser and the toe
#: short of the next one, 10 cm, plus a stride's worth of footsteps: docs/gait.md,
#: "climb"). Real stairs have 25-30 cm treads for 25 cm human feet.
STAIRS_TREAD_M = 0.25

MS = 1e-3  # [s/ms]
#: Push impulse of the robustness suite [N*s] (issue 10's goal) and the gait time of its
#: first push [s]: well after the ramp-in (robot.tuning.robustness, sim.mujoco.capture_study).
PUSH_NS = 1.0
PUSH_AT_S = 8.0
#: Phases of the step at which the suite's pushes land (fractions of a gait cycle).
PUSH_PHASES = (0.0, 0.25, 0.5, 0.75)


@dataclass(frozen=True)
class Push:
    """An impulse on the torso. at_s: gait time [s] (since the streamer's first "walking"
    tick); jx, jy: impulse forward and to the left in the heading frame [N*s]."""

    at_s: float
    jx: float = 0.0
    jy: float = 0.0

    def __post_init__(self) -> None:
        _check("Push.at_s", self.at_s, RANGES["push_time"])
        _check("Push.jx", self.jx, RANGES["push_impulse"])
        _check("Push.jy", self.jy, RANGES["push_impulse"])


@dataclass(frozen=True)
class World:
    """The perturbations of one simulated run (module docstring: units and signs).

    slope_deg, cross_slope_deg [deg]; bumps_mm: bump height [mm] (0: none); terrain_seed:
    the bump layout; pushes; latency_s: goal latency [s]; friction_scale, mass_scale [1];
    stairs_height_m [m], stairs_count: steps up, then as many down (0, 0: none);
    stairs_tread_m [m]: each tread's depth.
    """

    slope_deg: float = 0.0
    cross_slope_deg: float = 0.0
    bumps_mm: float = 0.0
    terrain_seed: int = 0
    pushes: tuple[Push, ...] = ()
    latency_s: float = 0.0
    friction_scale: float = 1.0
    mass_scale: float = 1.0
    stairs_height_m: float = 0.0
    stairs_count: int = 0
    stairs_tread_m: float = STAIRS_TREAD_M

    def __post_init__(self) -> None:
        for name, key in (("slope_deg", "slope"), ("cross_slope_deg", "cross_slope"),
                          ("bumps_mm", "bumps"), ("friction_scale", "friction"),
                          ("mass_scale", "mass_scale")):
            _check(f"World.{name}", getattr(self, name), RANGES[key])
        seed = RANGES["terrain_seed"]
        if not (isinstance(self.terrain_seed, int) and seed.lo <= self.terrain_seed <= seed.hi):
            raise ConfigError(f"World.terrain_seed: {self.terrain_seed!r} is not an integer "
                              f"in {seed}")
        _check_stairs(self.stairs_height_m, self.stairs_count)
        _check("World.stairs_tread_m", self.stairs_tread_m, RANGES["stairs_tread"])
        ms = RANGES["latency"]
        _check("World.latency_s", self.latency_s, Range(ms.lo * MS, ms.hi * MS, "s"))
        if not all(isinstance(p, Push) for p in self.pushes):
            raise ConfigError("World.pushes: expected a tuple of robot.config.world.Push")
        object.__setattr__(self, "pushes", tuple(sorted(self.pushes, key=lambda p: p.at_s)))

    @property
    def tilted(self) -> bool:
        return self.slope_deg != 0.0 or self.cross_slope_deg != 0.0

    def floor_normal(self) -> tuple[float, float, float]:
        """Unit normal of the floor plane (module docstring)."""
        gx = math.tan(math.radians(self.slope_deg))
        gy = math.tan(math.radians(self.cross_slope_deg))
        norm = math.sqrt(gx * gx + gy * gy + 1.0)
        return (-gx / norm, -gy / norm, 1.0 / norm)

    def floor_quat(self) -> tuple[float, float, float, float]:
        """(w, x, y, z): the minimal rotation taking +z to ``floor_normal()``."""
        nx, ny, nz = self.floor_normal()
        s = math.hypot(nx, ny)  # sin of the tilt
        if s == 0.0:
            return (1.0, 0.0, 0.0, 0.0)
        half = math.atan2(s, nz) / 2
        # axis = z x n / |z x n| = (-ny, nx, 0) / s
        return (math.cos(half), -ny / s * math.sin(half), nx / s * math.sin(half), 0.0)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: every field (pushes as objects)."""
        return dataclasses.asdict(self)


def _check_stairs(height: float, count: int) -> None:
    """ConfigError unless the stairs are none (0, 0) or a height in range above 0 and a
    count in range above 0."""
    _check("World.stairs_height_m", height, RANGES["stairs_height"])
    n = RANGES["stairs_count"]
    if not (isinstance(count, int) and not isinstance(count, bool) and n.lo <= count <= n.hi):
        raise ConfigError(f"World.stairs_count: {count!r} is not an integer in {n}")
    if (height > 0.0) != (count > 0):
        raise ConfigError(f"World.stairs_height_m, stairs_count: {height!r}, {count!r}: give "
                          "both above 0 (stairs) or both 0 (none)")


def _check(where: str, value: Any, valid: Range) -> None:
    """ConfigError naming ``where``, the value and the range ``valid`` unless inside it."""
    if not (isinstance(value, (int, float)) and not isinstance(value, bool)
            and valid.lo <= value <= valid.hi):            # false for nan
        raise ConfigError(f"{where}: {value!r} is outside {valid}")
