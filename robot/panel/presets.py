"""Gait presets for the panel: list, load and save (validated TOML via gait_to_toml).

Bundled presets live in ``configs/gaits``; a panel may save into its own ``presets_dir``.
A bundled preset is never overwritten unless ``overwrite`` is set.
"""

from __future__ import annotations

import logging
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

from robot.config import GAITS_DIR, Gait, gait_names, gait_to_toml, load_gait, parse_gait
from robot.errors import ConfigError
from robot.params import GaitParams

log = logging.getLogger(__name__)

NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,47}$")


class PresetExistsError(ConfigError):
    """Saving would overwrite an existing preset and ``overwrite`` was not set."""


@dataclass(frozen=True)
class PresetStore:
    """Where presets are read and written.

    presets_dir: directory written by "save as preset" (default: the bundled gait dir),
    searched before the bundled presets.
    """

    presets_dir: Path = GAITS_DIR

    def names(self) -> list[str]:
        own = {p.stem for p in self.presets_dir.glob("*.toml")} if self.presets_dir.is_dir() \
            else set()
        return sorted(own | set(gait_names()))

    def path(self, name: object) -> Path:
        name = check_name(name)
        own = self.presets_dir / f"{name}.toml"
        if own.exists():
            return own
        bundled = GAITS_DIR / f"{name}.toml"
        if bundled.exists():
            return bundled
        raise ConfigError(f"preset {name!r} not found; valid: {', '.join(self.names())}")

    def load(self, name: object) -> Gait:
        return load_gait(self.path(name))

    def save(self, name: object, params: GaitParams, *, overwrite: bool = False) -> Path:
        """Write ``params`` as preset ``name``; returns the file written."""
        name = check_name(name)
        target = self.presets_dir / f"{name}.toml"
        bundled = name in gait_names()
        if not overwrite and (target.exists() or bundled):
            what = "bundled preset" if bundled else f"preset file {target}"
            raise PresetExistsError(f"preset {name!r}: would overwrite the {what}; "
                               "choose another name or set overwrite")
        text = gait_to_toml(Gait(name=name, params=params))
        parse_gait(tomllib.loads(text), source=str(target))  # validate what we write
        self.presets_dir.mkdir(parents=True, exist_ok=True)
        tmp = target.with_suffix(".toml.tmp")
        tmp.write_text(text)
        tmp.replace(target)
        log.info("saved preset %s to %s", name, target)
        return target


def check_name(name: object) -> str:
    """A preset name: letters, digits, '_' and '-', 1-48 characters, no path parts."""
    if not isinstance(name, str) or not NAME_RE.match(name):
        raise ConfigError(f"preset name {name!r}: use 1-48 letters, digits, '_' or '-' "
                          "(starting with a letter or digit)")
    return name
