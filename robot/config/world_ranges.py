"""Valid ranges of the simulated world's perturbations (slope, bumps, pushes, latency,
friction, mass, stairs), in the `biped walk` options' units. One table for the CLI
(robot.commands.world_args, at parse time) and for ``sim.mujoco.world.World`` (its fields), kept
in robot/ so the CLI checks them without importing sim."""

from __future__ import annotations

from robot.config.toml_io import Range

RANGES: dict[str, Range] = {
    "slope": Range(-20.0, 20.0, "deg"),
    "cross_slope": Range(-20.0, 20.0, "deg"),
    "bumps": Range(0.0, 50.0, "mm"),
    "terrain_seed": Range(0, 2**31 - 1),
    "push_time": Range(0.0, 1e6, "s"),
    "push_impulse": Range(-10.0, 10.0, "N*s"),
    "latency": Range(0.0, 100.0, "ms"),
    "friction": Range(0.2, 3.0),
    "mass_scale": Range(0.5, 2.0),
    "stairs_height": Range(0.0, 0.05, "m"),
    "stairs_count": Range(0, 10),
    "stairs_tread": Range(0.05, 1.0, "m"),
}
