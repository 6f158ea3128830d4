"""The robustness suite's conditions: perturbations of a flat walk (slopes, bumps, pushes,
parameter changes, latency, IMU noise, friction, mass), each as the world, parameter
changes and IMU noise of one walk (``args``: the `biped walk` options that reproduce it).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from robot.config.params import SPECS, GaitParams
from robot.config.world import MS, PUSH_AT_S, PUSH_NS, PUSH_PHASES, Push, World
from robot.errors import ConfigError

#: Parameters the +/-20 % conditions change: every non-zero parameter of the preset that
#: shapes the motion (steering and balance gains are covered by their own conditions).
PARAM_SCALE = 0.2
SKIP_PARAMS = frozenset({"speed", "turn", "side_step", "ramp_cycles", "rig_leg", "fps"})
#: The straightness goal's walk [s]: heading within STRAIGHT_DEG and lateral drift within
#: STRAIGHT_DRIFT of the distance over this long on flat ground.
STRAIGHT_S = 60.0
STRAIGHT_DEG = 5.0
STRAIGHT_DRIFT = 0.05
#: Scales of the sim IMU's datasheet noise and offsets (every run has x1, the robot
#: file's "realistic" BNO055).
IMU_NOISE = (2.0, 3.0)
#: A push needs this long after it [s] to tell a recovery from a slow fall.
AFTER_PUSH_S = 2.0
#: The harder push of the full suite's second grid [N*s] (issue 22: 12 of 16 with `walk`).
PUSH_HARD_NS = 1.5
#: A pushed walk survives only if it keeps walking: its forward speed over the run at
#: least this share of the same suite's unpushed flat walk (same robot, preset, balance
#: mode and seconds). A robot that braces and stands after the push falls under it (the
#: push grid study's line, docs/robustness.md: 0.082 of 0.096-0.098 m/s).
WALK_ON_SHARE = 0.85
#: The pushes' directions as (forward, left) unit impulses.
PUSH_DIRECTIONS = {"forward": (1, 0), "backward": (-1, 0), "left": (0, 1), "right": (0, -1)}


@dataclass(frozen=True)
class Condition:
    """One perturbation: a name, a group (one bar of the picture), the walk's world (None:
    the plain scene), its parameter changes (name, value), its IMU noise scale (None: the
    robot file's); seconds: this condition's walk [s] (None: the suite's); switches: preset
    switches (gait time [s], bundled preset) during the walk; reach_m: the distance [m]
    the walk must cover to survive (None: not falling is enough); walk_on: it must also
    keep walking, at WALK_ON_SHARE of the flat walk's speed (the pushes)."""

    group: str
    name: str
    world: World | None = None
    changes: tuple[tuple[str, float], ...] = ()
    imu_noise: float | None = None
    seconds: float | None = None
    switches: tuple[tuple[float, str], ...] = ()
    reach_m: float | None = None
    walk_on: bool = False

    @property
    def args(self) -> tuple[str, ...]:
        """The `biped walk` options that reproduce this condition."""
        out: list[str] = []
        w = self.world or World()
        if w.slope_deg:
            out += ["--slope", f"{w.slope_deg:g}"]
        if w.cross_slope_deg:
            out += ["--cross-slope", f"{w.cross_slope_deg:g}"]
        if w.bumps_mm:
            out += ["--bumps", f"{w.bumps_mm:g}", "--terrain-seed", str(w.terrain_seed)]
        for p in w.pushes:
            out += ["--push", f"{p.at_s:.3f}:{p.jx:g},{p.jy:g}"]
        if w.latency_s:
            out += ["--latency", f"{w.latency_s / MS:g}"]
        if w.friction_scale != 1.0:
            out += ["--friction", f"{w.friction_scale:g}"]
        if w.mass_scale != 1.0:
            out += ["--mass-scale", f"{w.mass_scale:g}"]
        if w.stairs_count:
            out += ["--stairs", f"{w.stairs_height_m:g},{w.stairs_count}"]
        for name, value in self.changes:
            out += ["--set", f"{name}={value!r}"]
        if self.imu_noise is not None:
            out += ["--imu-noise", f"{self.imu_noise:g}"]
        for t, preset in self.switches:
            out += ["--switch", f"{t:g}:{preset}"]
        return tuple(out)


def conditions(params: GaitParams, *, quick: bool = False) -> list[Condition]:
    """The suite for a preset with ``params`` (``quick``: a few cases for CI)."""
    cycle = params.cycle_s
    out = [Condition("flat", "flat")]
    slopes = (5.0, -5.0) if quick else (2.0, 5.0, -2.0, -5.0)
    out += [Condition("slope", f"slope {s:+g} deg", World(slope_deg=s)) for s in slopes]
    crosses = (4.0,) if quick else (4.0, -4.0)
    out += [Condition("cross slope", f"cross slope {s:+g} deg", World(cross_slope_deg=s))
            for s in crosses]
    heights, seeds = ((5.0,), (0,)) if quick else ((1.0, 3.0, 5.0), (0, 1, 2))
    out += [Condition("bumps", f"bumps {h:g} mm seed {s}", World(bumps_mm=h, terrain_seed=s))
            for h in heights for s in seeds]
    out += push_grid(cycle, PUSH_NS, phases=(0.0,) if quick else PUSH_PHASES)
    if not quick:
        out += push_grid(cycle, PUSH_HARD_NS, group=f"push {PUSH_HARD_NS:g} N*s")
    if not quick:
        out += scaled_params(params)
    for ms in ((20.0,) if quick else (10.0, 20.0)):
        out.append(Condition("latency", f"latency {ms:g} ms", World(latency_s=ms * MS)))
    for scale in (IMU_NOISE[-1:] if quick else IMU_NOISE):
        out.append(Condition("imu noise", f"imu noise x{scale:g}", imu_noise=scale))
    if not quick:
        out.append(Condition("flat 60 s", f"flat {STRAIGHT_S:g} s", seconds=STRAIGHT_S))
        out += [Condition("friction", f"friction x{f:g}", World(friction_scale=f))
                for f in (0.5, 2.0)]
        out += [Condition("mass", f"mass x{m:g}", World(mass_scale=m)) for m in (0.8, 1.2)]
        out += stairs_and_switches()
    return out


def push_grid(cycle: float, impulse: float, *, phases: Iterable[float] = PUSH_PHASES,
              group: str | None = None) -> list[Condition]:
    """Pushes of ``impulse`` [N*s] forward, backward, left and right, each at gait time
    PUSH_AT_S + each of ``phases`` x ``cycle`` [s]; grouped per direction ("push
    forward", ...) unless ``group`` names one group for them all."""
    out = []
    for direction, (ux, uy) in PUSH_DIRECTIONS.items():
        for ph in phases:
            # The gait time to the millisecond, as the `--push` option gives it.
            t = float(f"{PUSH_AT_S + ph * cycle:.3f}")
            push = Push(t, ux * impulse, uy * impulse)
            out.append(Condition(group or f"push {direction}",
                                 f"push {impulse:g} N*s {direction} at phase {ph:g}",
                                 World(pushes=(push,)), walk_on=True))
    return out


def check_seconds(conds: Iterable[Condition], seconds: float) -> None:
    """Refuse runs too short for the latest push to land and be recovered from."""
    last = max((p.at_s for c in conds if c.world is not None and c.seconds is None
                for p in c.world.pushes), default=None)
    if last is not None and seconds < last + AFTER_PUSH_S:
        raise ConfigError(f"--seconds {seconds:g}: the suite's pushes land up to "
                          f"{last:.2f} s into the gait; give at least "
                          f"{last + AFTER_PUSH_S:.1f} s (or leave the pushes out)")


def scaled_params(params: GaitParams) -> list[Condition]:
    """Every shaping parameter of ``params`` +/- PARAM_SCALE, clipped to its documented
    range (a clipped change is named; one that the range leaves at the preset's value is
    left out)."""
    out = []
    for name, v in params.as_dict().items():
        if name in SKIP_PARAMS or name.startswith("bal_") or v == 0.0:
            continue
        spec = SPECS[name]
        for sign in (1, -1):
            want = v * (1 + sign * PARAM_SCALE)
            got = min(max(want, spec.lo), spec.hi)
            if got == v:
                continue
            label = f"{name} {sign * 20:+d} %" + ("" if got == want else f" (range: {got:g})")
            out.append(Condition("params +/-20 %", label, changes=((name, got),)))
    return out


#: The stairs group: steps [m] and their number (up, a landing, as many down), the walk's
#: length [s] (room for a walk at 0.06 m/s to cross them) and how far it must get [m]: the
#: torso 5 cm past the last riser down (sim.mujoco.world_stairs.stairs_end_m: 1.60 m for
#: these with the default 0.25 m treads).
STAIRS = (0.015, 3)
STAIRS_S = 30.0
STAIRS_REACH_M = 1.65
#: The preset-transition group: the issue's walk -> jog -> crouch -> walk, each switch a
#: blend (robot.gait.blend), then 2.8 s on the last preset.
SWITCHES = ((4.0, "jog"), (7.0, "crouch"), (10.0, "walk"))
SWITCHES_S = 14.0


def stairs_and_switches() -> list[Condition]:
    """The full suite's stairs (up and down, crossed to the far side) and preset switches
    (issue 22); none in the quick suite (tests/test_transitions.py walks the switches)."""
    h, n = STAIRS
    return [Condition("stairs", f"stairs {n} x {h * 1e3:g} mm up and down",
                      World(stairs_height_m=h, stairs_count=n), seconds=STAIRS_S,
                      reach_m=STAIRS_REACH_M),
            Condition("preset switches", " -> ".join(["start"] + [p for _, p in SWITCHES]),
                      seconds=SWITCHES_S, switches=SWITCHES)]
