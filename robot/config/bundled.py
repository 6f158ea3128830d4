"""Where robot and gait files come from: the ones shipped inside the package, the user's
saved gait presets, and the name-or-path rule of ``--robot`` / ``--gait``.

The bundled files are package data (``robot/configs/{robots,gaits}/*.toml``), found with
importlib.resources, so they are there however biped was installed (wheel, editable, or a
checkout on ``sys.path``). Presets saved from the panel live in the user's config directory
(platformdirs: ``~/.config/biped/gaits`` on Linux), never in the package.

A value with no ``/`` and no ``.toml`` suffix is a name; anything else is a path.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import platformdirs

from robot.errors import ConfigError


def _bundled_root() -> Path:
    root = resources.files("robot") / "configs"
    if not isinstance(root, Path):   # a zipped install: load_* need real files
        raise ConfigError(f"bundled configs {root}: biped must be installed as files "
                          "(pip install), not imported from a zip archive")
    return root


CONFIG_DIR = _bundled_root()
ROBOTS_DIR = CONFIG_DIR / "robots"
GAITS_DIR = CONFIG_DIR / "gaits"
DEFAULT_ROBOT_NAME = "biped18-dynamixel"
DEFAULT_ROBOT = ROBOTS_DIR / f"{DEFAULT_ROBOT_NAME}.toml"
DEFAULT_GAIT = "walk"
#: Bundled presets not made for some bundled robots, with why: walked and reported by the
#: bench, but neither the bench nor the tests ask them to stay up or in reach there.
#: `jog` falls 13.7 s into a 60 s walk on the 12 cm-legged ROBOTIS MINI (docs/gait.md);
#: on the Open Duck Mini v2 (thigh and shin 79 mm, knees bending backward within +-90
#: deg) `crouch`, `jog`, `robust`, `run` and `paper` ask for soles out of its legs' reach
#: (docs/robustness.md, "open-duck-mini-v2").
NOT_MADE_FOR: dict[str, frozenset[str]] = {
    "jog": frozenset({"robotis-mini", "open-duck-mini-v2"}),
    "crouch": frozenset({"open-duck-mini-v2"}), "robust": frozenset({"open-duck-mini-v2"}),
    "run": frozenset({"open-duck-mini-v2"}), "paper": frozenset({"open-duck-mini-v2"}),
}


def made_for(robot_name: str, gait_name: str) -> bool:
    """Whether the bundled preset ``gait_name`` is made for the robot ``robot_name``."""
    return robot_name not in NOT_MADE_FOR.get(gait_name, frozenset())


def user_gaits_dir() -> Path:
    """The user's saved gait presets: ``user_config_dir("biped")/gaits`` (platformdirs;
    ``$XDG_CONFIG_HOME/biped/gaits`` or ``~/.config/biped/gaits`` on Linux)."""
    return Path(platformdirs.user_config_dir("biped", appauthor=False)) / "gaits"


def _stems(directory: Path) -> list[str]:
    return sorted(p.stem for p in directory.glob("*.toml")) if directory.is_dir() else []


def robot_names() -> list[str]:
    """Names of the bundled robots (``--robot NAME``)."""
    return _stems(ROBOTS_DIR)


def gait_names() -> list[str]:
    """Names of the bundled gait presets."""
    return _stems(GAITS_DIR)


def user_gait_names() -> list[str]:
    """Names of the user's saved presets that a bundled one does not shadow."""
    bundled = {n.lower() for n in gait_names()}
    return [n for n in _stems(user_gaits_dir()) if n.lower() not in bundled]


def is_name(text: str) -> bool:
    """``--robot`` / ``--gait`` value is a bundled name, not a path."""
    return "/" not in text and "\\" not in text and not text.endswith(".toml")


def _existing(option: str, path: Path, names: str) -> Path:
    """``path`` if it exists (read_toml reports what else is wrong with it); else a one-line
    ConfigError that also lists the bundled names (given without ``.toml``)."""
    if not path.exists():
        raise ConfigError(f"{option} {path}: file not found; give an existing .toml path or "
                          f"a name without .toml ({names})")
    return path


def resolve_robot_path(name_or_path: str | Path) -> Path:
    """A bundled robot name (``biped18-feetech``) or a path to a TOML file → a path."""
    s = str(name_or_path)
    if isinstance(name_or_path, Path) or not is_name(s):
        return _existing("--robot", Path(s), f"bundled robots: {', '.join(robot_names())}")
    p = ROBOTS_DIR / f"{s}.toml"
    if not p.is_file():
        raise ConfigError(f"--robot: unknown robot {s!r}; valid: {', '.join(robot_names())} "
                          "(bundled), or a path to a .toml file")
    return p


def resolve_gait_path(name_or_path: str | Path) -> Path:
    """A preset name (``walk``: bundled first, then the user's saved presets) or a path to a
    TOML file → a path."""
    s = str(name_or_path)
    if isinstance(name_or_path, Path) or not is_name(s):
        return _existing("--gait", Path(s), f"bundled presets: {', '.join(gait_names())}")
    bundled = GAITS_DIR / f"{s}.toml"
    if bundled.is_file():
        return bundled
    if s in user_gait_names():
        return user_gaits_dir() / f"{s}.toml"
    saved = user_gait_names()
    mine = f"; saved in {user_gaits_dir()}: {', '.join(saved)}" if saved else ""
    raise ConfigError(f"--gait: unknown preset {s!r}; valid: {', '.join(gait_names())} "
                      f"(bundled){mine}; or a path to a .toml file")
