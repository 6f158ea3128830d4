"""`biped walk` perturbation options (sim only): slope, bumps, pushes, latency, friction,
mass, stairs. Parsed and range-checked here at parse time (one line, exit 2); turned into a
``robot.config.world.World`` by ``world_from``. Units and sign conventions:
``robot.config.world`` and docs/robustness.md."""

from __future__ import annotations

import argparse
from typing import Any

from robot.commands.common import bounded_float, bounded_int
from robot.config.world import MS, STAIRS_TREAD_M, Push, World
from robot.config.world_ranges import RANGES
from robot.errors import ConfigError

#: Option → (argparse dest, value of "not given").
DEFAULTS: dict[str, tuple[str, Any]] = {
    "--slope": ("slope", 0.0), "--cross-slope": ("cross_slope", 0.0),
    "--bumps": ("bumps", 0.0), "--terrain-seed": ("terrain_seed", 0), "--push": ("push", []),
    "--latency": ("latency", 0.0), "--friction": ("friction", 1.0),
    "--mass-scale": ("mass_scale", 1.0), "--stairs": ("stairs", (0.0, 0, STAIRS_TREAD_M)),
}

def _float(key: str, what: str) -> Any:
    r = RANGES[key]
    return bounded_float(r.lo, r.hi, r.unit, what=what)


def push_spec(text: str) -> tuple[float, float, float]:
    """An argparse type: ``T:JX,JY`` → (gait time [s], forward, left impulse [N*s])."""
    t_text, _, j_text = text.partition(":")
    jx_text, _, jy_text = j_text.partition(",")
    t, jx, jy = RANGES["push_time"], RANGES["push_impulse"], RANGES["push_impulse"]
    try:
        values = (float(t_text), float(jx_text), float(jy_text))
    except ValueError:
        values = (float("nan"),) * 3
    if not (t.lo <= values[0] <= t.hi and jx.lo <= values[1] <= jx.hi
            and jy.lo <= values[2] <= jy.hi):
        raise argparse.ArgumentTypeError(
            f"expected T:JX,JY with T in {t} and JX, JY in {jx} (e.g. 8:1.0,0), got {text!r}")
    return values


def stairs_spec(text: str) -> tuple[float, int, float]:
    """An argparse type: ``H,N[,TREAD]`` → (step height [m] above 0, number of steps up
    and then down, at least 1, tread depth [m], default ``STAIRS_TREAD_M``)."""
    parts = text.split(",")
    h, n, t = RANGES["stairs_height"], RANGES["stairs_count"], RANGES["stairs_tread"]
    try:
        if len(parts) not in (2, 3):
            raise ValueError(text)
        height, count = float(parts[0]), int(parts[1])
        tread = float(parts[2]) if len(parts) == 3 else STAIRS_TREAD_M
    except ValueError:
        height, count, tread = float("nan"), 0, float("nan")
    if not (0.0 < height <= h.hi and 1 <= count <= n.hi
            and t.lo <= tread <= t.hi):  # false for nan
        raise argparse.ArgumentTypeError(
            f"expected H,N[,TREAD] with H in (0, {h.hi:g}] m, N an integer in [1, "
            f"{n.hi:g}] and TREAD in [{t.lo:g}, {t.hi:g}] m (default {STAIRS_TREAD_M:g}; "
            f"e.g. 0.015,3), got {text!r}")
    return height, count, tread


def add_world_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("perturbations (--bus sim only; docs/robustness.md)")
    g.add_argument("--slope", type=_float("slope", "a slope"), default=0.0, metavar="DEG",
                   help=f"floor slope along the walk, + = uphill {RANGES['slope']}")
    g.add_argument("--cross-slope", type=_float("cross_slope", "a slope"), default=0.0,
                   metavar="DEG", help="floor slope across the walk, + = the ground falls to "
                   f"the robot's right {RANGES['cross_slope']}")
    g.add_argument("--bumps", type=_float("bumps", "a height"), default=0.0, metavar="MM",
                   help=f"height of random flat boxes over the first 5 m {RANGES['bumps']} "
                   "(0: none)")
    seed = RANGES["terrain_seed"]
    g.add_argument("--terrain-seed", type=bounded_int(int(seed.lo), int(seed.hi),
                                                      what="a seed"),
                   default=0, metavar="N", help="bump layout (default: %(default)s)")
    g.add_argument("--push", type=push_spec, action="append", default=[], metavar="T:JX,JY",
                   help="impulse on the torso at gait time T [s], JX forward / JY left "
                   f"[N*s] in the heading frame, each in {RANGES['push_impulse']} (repeatable)")
    g.add_argument("--latency", type=_float("latency", "a latency"), default=0.0,
                   metavar="MS", help=f"goals take effect this much later {RANGES['latency']}")
    g.add_argument("--friction", type=_float("friction", "a friction scale"), default=1.0,
                   metavar="SCALE", help=f"scale sliding friction {RANGES['friction']}")
    g.add_argument("--mass-scale", type=_float("mass_scale", "a mass scale"), default=1.0,
                   metavar="SCALE", help=f"scale every body's mass and inertia "
                   f"{RANGES['mass_scale']}")
    g.add_argument("--stairs", type=stairs_spec, default=(0.0, 0, STAIRS_TREAD_M),
                   metavar="H,N[,TREAD]",
                   help="N steps of height H [m] up ahead of the robot, a landing, N steps "
                   f"down, treads TREAD [m] deep (default {STAIRS_TREAD_M:g}; e.g. 0.015,3)")


def given(args: argparse.Namespace) -> list[str]:
    """The perturbation options given with a non-default value."""
    return [opt for opt, (dest, default) in DEFAULTS.items()
            if getattr(args, dest, default) != default]


def world_from(args: argparse.Namespace, kind: str) -> World | None:
    """The ``robot.config.world.World`` of the options, None if none is given; ConfigError (nothing
    opened) if one is given for a bus other than sim."""
    options = given(args)
    if not options:
        return None
    if kind != "sim":
        raise ConfigError(f"{options[0]} applies to --bus sim only, not --bus {kind}")
    return World(slope_deg=args.slope, cross_slope_deg=args.cross_slope,
                 bumps_mm=args.bumps, terrain_seed=args.terrain_seed,
                 pushes=tuple(Push(t, jx, jy) for t, jx, jy in args.push),
                 latency_s=args.latency * MS, friction_scale=args.friction,
                 mass_scale=args.mass_scale, stairs_height_m=args.stairs[0],
                 stairs_count=args.stairs[1], stairs_tread_m=args.stairs[2])


def describe_world(w: dict[str, Any] | None) -> str | None:
    """One line for the text summary from the JSON "world" object (None: plain world)."""
    if not w:
        return None
    parts = []
    if w["slope_deg"] or w["cross_slope_deg"]:
        parts.append(f"slope {w['slope_deg']:+g} deg, cross slope {w['cross_slope_deg']:+g} deg")
    if w["bumps_mm"]:
        parts.append(f"bumps {w['bumps_mm']:g} mm (seed {w['terrain_seed']})")
    if w["pushes"]:
        parts.append(f"{len(w['pushes_applied'])} of {len(w['pushes'])} pushes applied")
    if w["latency_s"]:
        parts.append(f"latency {w['latency_s'] / MS:g} ms")
    if w["friction_scale"] != 1.0:
        parts.append(f"friction x{w['friction_scale']:g}")
    if w["mass_scale"] != 1.0:
        parts.append(f"mass x{w['mass_scale']:g}")
    if w.get("stairs_count"):
        parts.append(f"stairs {w['stairs_count']} x {w['stairs_height_m'] * 1e3:g} mm up "
                     f"and down, treads {w.get('stairs_tread_m', STAIRS_TREAD_M) * 1e2:g} cm")
    return ", ".join(parts) or None
