"""``biped robots import --map``: the recipe of an import (robot/config/model_import.py
reads its joints' entries; the command its bus, gains, balance gains, source and notes)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robot.config.model_import import MAP_KEYS
from robot.config.toml_io import read_toml
from robot.errors import ConfigError


@dataclass(frozen=True)
class Recipe:
    """An import's ``--map`` file: per model joint what MAP_KEYS allow; the bus (kind,
    model, baud), the gain registers and balance gains the robot file gets; where the
    model comes from, its licence, and notes for the file's opening comment."""

    joints: dict[str, dict[str, object]] = field(default_factory=dict)
    bus: dict[str, object] = field(default_factory=dict)
    gains: dict[str, int] = field(default_factory=dict)
    balance: dict[str, float] = field(default_factory=dict)
    source: str = ""
    licence: str = ""
    notes: tuple[str, ...] = ()


RECIPE_KEYS = ("joints", "bus", "balance", "source", "licence", "notes")


def read_map(path: str | None) -> Recipe:
    """The ``--map`` file at ``path`` (None: an empty one); one-line ConfigError."""
    if path is None:
        return Recipe()
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
    return Recipe(out, dict(bus), dict(gains), dict(balance),  # type: ignore[arg-type]
                  str(data.get("source", "")), str(data.get("licence", "")),
                  tuple(str(n) for n in notes))
