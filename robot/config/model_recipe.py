"""``biped robots import --map``: the recipe of an import
(robot/config/model_import.py): what it may say of each model joint, of the bus and its
gains, of the robot's balance gains and gait, which way the knees bend, and where the model
comes from. Every fault is one line naming the file and the key."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robot.errors import ConfigError

#: What ``--map`` may say of a model joint: its name (an extra joint's), its servo's id,
#: limits in the project's convention (min_rad, max_rad) or the model's (model_range,
#: [rad]: where a vendor documents them so) and where they come from, a slew limit, the
#: angle an extra joint is held at, weld (true: no servo drives it; welded at the model's
#: zero), gains (its servo's gain registers: ``[joints.NAME.gains]`` of the robot file).
MAP_KEYS = {"name", "servo_id", "min_rad", "max_rad", "model_range", "max_speed_rad_s",
            "limits_source", "fixed_rad", "weld", "gains"}
#: A map's ``knee``: the knee bends backward (True) or forward.
KNEES = {"forward": False, "back": True}


@dataclass(frozen=True)
class Recipe:
    """An import's ``--map`` file: per model joint what MAP_KEYS allow; the bus (kind,
    model, baud), the gain registers, balance gains and gait parameters the robot file
    gets (``[bus.gains]``, ``[balance]``, ``[gait]``); which way the knees bend
    (``KNEES``; None: from the limits); where the model comes from, its licence, and
    notes for the file's opening comment."""

    joints: dict[str, dict[str, object]] = field(default_factory=dict)
    bus: dict[str, object] = field(default_factory=dict)
    gains: dict[str, int] = field(default_factory=dict)
    balance: dict[str, float] = field(default_factory=dict)
    source: str = ""
    licence: str = ""
    notes: tuple[str, ...] = ()
    knee: str | None = None
    gait: dict[str, float] = field(default_factory=dict)


RECIPE_KEYS = ("joints", "bus", "balance", "gait", "knee", "source", "licence", "notes")


def read_map(path: str | None) -> Recipe:
    """The ``--map`` file at ``path`` (None: an empty one); one-line ConfigError."""
    if path is None:
        return Recipe()
    from robot.config.robot_file import parse_gait_table
    from robot.config.toml_io import read_toml, show

    data = read_toml(Path(path))
    where = f"--map {path}"
    bad = sorted(set(data) - set(RECIPE_KEYS))
    if bad:
        raise ConfigError(f"{where}: {bad[0]}: unknown key; valid: {', '.join(RECIPE_KEYS)}")
    joints = data.get("joints", {})
    if not isinstance(joints, dict):
        raise ConfigError(f"{where}: joints: expected [joints.MODEL_JOINT] tables")
    out: dict[str, dict[str, object]] = {}
    for name, tab in joints.items():
        if not isinstance(tab, dict):
            raise ConfigError(f"{where}: joints.{name}: expected a table")
        unknown = sorted(set(tab) - MAP_KEYS)
        if unknown:
            raise ConfigError(f"{where}: joints.{name}.{unknown[0]}: unknown key; valid: "
                              f"{', '.join(sorted(MAP_KEYS))}")
        if not isinstance(tab.get("gains", {}), dict):
            raise ConfigError(f"{where}: joints.{name}.gains: expected a table of register values")
        out[name] = dict(tab)
    bus = data.get("bus", {})
    balance = data.get("balance", {})
    notes = data.get("notes", [])
    if not isinstance(bus, dict) or not isinstance(balance, dict) or not isinstance(notes, list):
        raise ConfigError(f"{where}: bus and balance must be tables, notes a list of strings")
    gains = bus.pop("gains", {}) if isinstance(bus.get("gains", {}), dict) else None
    if gains is None:
        raise ConfigError(f"{where}: bus.gains: expected a table of register values")
    unknown = sorted(set(bus) - {"kind", "model", "baud"})
    if unknown:
        raise ConfigError(f"{where}: bus.{unknown[0]}: unknown key; valid: kind, model, baud, gains")
    knee = data.get("knee")
    if knee is not None and knee not in KNEES:
        raise ConfigError(f"{where}: knee: {show(knee)}; valid: {', '.join(KNEES)}")
    gait = parse_gait_table(where, data.get("gait", {}))
    return Recipe(out, dict(bus), dict(gains), dict(balance),  # type: ignore[arg-type]
                  str(data.get("source", "")), str(data.get("licence", "")),
                  tuple(str(n) for n in notes), None if knee is None else str(knee), gait)
