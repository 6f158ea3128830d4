"""Gait presets for the panel: list, load and save (validated TOML via gait_to_toml).

Bundled presets ship inside the package (``robot/configs/gaits``) and are read-only here:
saving under a bundled name is refused whatever ``overwrite`` says, and a user file with a
bundled name is ignored (the bundled one wins). The panel saves into ``presets_dir``: by
default the user's config directory (``robot.config.bundled.user_gaits_dir``, platformdirs:
``~/.config/biped/gaits`` on Linux), never the package or the repository; ``biped walk
--gait NAME`` finds presets saved there too.
"""

from __future__ import annotations

import logging
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from robot.config.bundled import GAITS_DIR, gait_names, user_gaits_dir
from robot.config.gait_file import Gait, gait_to_toml, load_gait, parse_gait
from robot.config.params import GaitParams
from robot.errors import ConfigError
from robot.files.atomic import write_text

log = logging.getLogger(__name__)

NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{0,47}\Z")  # \Z: "$" lets a final newline in


class PresetExistsError(ConfigError):
    """Saving would overwrite a bundled preset, or a user preset without ``overwrite``."""


#: Where "save as preset" writes by default (the user's config directory, via platformdirs).
user_presets_dir = user_gaits_dir


@dataclass(frozen=True)
class PresetStore:
    """Where presets are read and written.

    presets_dir: directory written by "save as preset" (default ``user_presets_dir()``);
    it may not be the bundled directory.
    """

    presets_dir: Path = field(default_factory=user_presets_dir)

    def __post_init__(self) -> None:
        if self.presets_dir.resolve() == GAITS_DIR.resolve():
            raise ConfigError(f"presets directory {self.presets_dir}: that is where the "
                              "bundled presets live; save elsewhere (default "
                              f"{user_presets_dir()})")

    def names(self) -> list[str]:
        own = {p.stem for p in self.presets_dir.glob("*.toml")} if self.presets_dir.is_dir() \
            else set()
        return sorted({n for n in own if NAME_RE.fullmatch(n)} | set(gait_names()))

    def path(self, name: object) -> Path:
        name = check_name(name)
        for path in (GAITS_DIR / f"{name}.toml", self.presets_dir / f"{name}.toml"):
            if path.is_file():
                return path
        raise ConfigError(f"preset {name!r} not found; valid: {', '.join(self.names())}")

    def load(self, name: object) -> Gait:
        return load_gait(self.path(name))

    def save(self, name: object, params: GaitParams, *, overwrite: bool = False) -> Path:
        """Write ``params`` as user preset ``name``; returns the file written. A bundled
        name is refused even with ``overwrite``."""
        name = check_name(name)
        target = self.presets_dir / f"{name}.toml"
        if name.lower() in {n.lower() for n in gait_names()}:
            raise PresetExistsError(f"preset {name!r} is bundled with biped and cannot be "
                                    "replaced from the panel; save under another name")
        if not overwrite and target.exists():
            raise PresetExistsError(f"preset {name!r}: would overwrite {target}; choose "
                                    "another name or set overwrite")
        text = gait_to_toml(Gait(name=name, params=params))
        parse_gait(tomllib.loads(text), source=str(target))  # validate what we write
        try:
            self.presets_dir.mkdir(parents=True, exist_ok=True)
            write_text(target, text)
        except OSError as e:
            raise ConfigError(f"preset {name!r}: cannot write {target}: {e.strerror or e}") \
                from e
        log.info("saved preset %s to %s", name, target)
        return target


def check_name(name: object) -> str:
    """A preset name: letters, digits, '_' and '-', 1-48 characters, no path parts."""
    if not isinstance(name, str) or not NAME_RE.fullmatch(name):
        raise ConfigError(f"preset name {name!r}: use 1-48 letters, digits, '_' or '-' "
                          "(starting with a letter or digit)")
    return name
